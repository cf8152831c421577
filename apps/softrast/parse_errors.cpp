// apps/softrast/parse_errors.cpp
#include "parse_errors.hpp"

#include <charconv>
#include <string_view>
#include <system_error>

namespace softrast::cli {
namespace {

const CLI::Option* find_option(std::span<const CLI::App* const> commands, const std::string& name) {
  for (const CLI::App* app : commands) {
    if (const CLI::Option* o = app->get_option_no_throw(name)) return o;
  }
  return nullptr;
}

// CLI11: "Could not convert: --NAME = VALUE".
std::string conversion_message(std::span<const CLI::App* const> commands, std::string_view rest) {
  size_t eq = rest.find(" = ");
  if (eq == std::string_view::npos) return {};
  std::string name(rest.substr(0, eq)), value(rest.substr(eq + 3));
  const CLI::Option* option = find_option(commands, name);
  if (!option) return {};
  if (option->get_expected_max() == 0) return name + ": takes no value, got '" + value + "'";
  // Every option that CLI11 converts itself is a number (the others are read as text and
  // checked by values.cpp): a value that is a number but did not convert wanted an integer.
  double number = 0.0;
  const char* end = value.data() + value.size();
  auto [stop, error] = std::from_chars(value.data(), end, number);
  if (error == std::errc() && stop == end) {
    return name + ": expected a whole number, got '" + value + "'";
  }
  return name + ": expected a number, got '" + value + "'";
}

}  // namespace

std::string parse_error_message(std::span<const CLI::App* const> commands,
                                const CLI::ParseError& e) {
  const std::string text = e.what();
  constexpr std::string_view kConvert = "Could not convert: ";
  if (text.rfind(kConvert, 0) == 0) {
    std::string m = conversion_message(commands, std::string_view(text).substr(kConvert.size()));
    if (!m.empty()) return m;
  }
  // CLI11: "NAME was given a disallowed flag override" for --flag=value (flags are defined with
  // disable_flag_override, so that --wireframe=5 is not quietly taken as true).
  constexpr std::string_view kOverride = " was given a disallowed flag override";
  if (text.size() > kOverride.size() &&
      text.compare(text.size() - kOverride.size(), kOverride.size(), kOverride) == 0) {
    std::string name = text.substr(0, text.size() - kOverride.size());
    if (name.rfind("-", 0) != 0) name = (name.size() == 1 ? "-" : "--") + name;
    return name + ": takes no value; write " + name + " alone";
  }
  return text;
}

}  // namespace softrast::cli
