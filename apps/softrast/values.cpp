// apps/softrast/values.cpp: parsing of flag values.

#include "values.hpp"

#include <charconv>
#include <cmath>

#include "softrast/image.hpp"

namespace softrast::cli {
namespace {

Status malformed(std::string_view flag, std::string_view text, std::string_view expected) {
  return Status::error(std::string(flag) + ": expected " + std::string(expected) + ", got '" +
                       std::string(text) + "'");
}

// A whole decimal number in [1, kMaxImageSize]; no sign, no spaces. 0 stands for "invalid".
int parse_dimension(std::string_view text) {
  int value = 0;
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) return 0;
  return value >= 1 && value <= kMaxImageSize ? value : 0;
}

// A finite float filling all of `text`; from_chars also takes "inf" and "nan", refused here.
bool parse_float(std::string_view text, float& value) {
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return !text.empty() && ec == std::errc() && ptr == end && std::isfinite(value);
}

}  // namespace

Result<glm::ivec2> parse_size(std::string_view flag, std::string_view text) {
  size_t x = text.find('x');
  if (x == std::string_view::npos) return malformed(flag, text, "WIDTHxHEIGHT such as 800x600");
  int width = parse_dimension(text.substr(0, x));
  int height = parse_dimension(text.substr(x + 1));
  if (width == 0 || height == 0) {
    return malformed(flag, text, "WIDTHxHEIGHT with both in 1.." + std::to_string(kMaxImageSize));
  }
  return glm::ivec2(width, height);
}

Result<std::vector<float>> parse_floats(std::string_view flag, std::string_view text,
                                        size_t count) {
  std::vector<float> values;
  std::string_view rest = text;
  for (;;) {
    size_t comma = rest.find(',');
    float value = 0.0f;
    if (!parse_float(rest.substr(0, comma), value)) break;
    values.push_back(value);
    if (comma == std::string_view::npos) {
      if (values.size() == count) return values;
      break;
    }
    rest.remove_prefix(comma + 1);
  }
  return malformed(flag, text, std::to_string(count) + " finite numbers separated by commas");
}

Result<glm::vec3> parse_vec3(std::string_view flag, std::string_view text) {
  Result<std::vector<float>> v = parse_floats(flag, text, 3);
  if (!v) return v.status();
  return glm::vec3((*v)[0], (*v)[1], (*v)[2]);
}

Result<glm::vec4> parse_vec4(std::string_view flag, std::string_view text) {
  Result<std::vector<float>> v = parse_floats(flag, text, 4);
  if (!v) return v.status();
  return glm::vec4((*v)[0], (*v)[1], (*v)[2], (*v)[3]);
}

std::string name_list(std::span<const std::string_view> names) {
  std::string list;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) list += i + 1 == names.size() ? " or " : ", ";
    list += names[i];
  }
  return list;
}

}  // namespace softrast::cli
