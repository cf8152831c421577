// apps/softrast/values.cpp: parsing of flag values.

#include "values.hpp"

#include <algorithm>
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

std::string_view trim_spaces(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
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

// The numbers of a comma-separated list, spaces around each allowed ("0, 0, 3"); empty on a
// malformed list.
std::vector<float> float_list(std::string_view text) {
  std::vector<float> values;
  std::string_view rest = text;
  for (;;) {
    size_t comma = rest.find(',');
    float value = 0.0f;
    if (!parse_float(trim_spaces(rest.substr(0, comma)), value)) return {};
    values.push_back(value);
    if (comma == std::string_view::npos) return values;
    rest.remove_prefix(comma + 1);
  }
}

Result<std::vector<float>> parse_floats(std::string_view flag, std::string_view text,
                                        size_t count) {
  std::vector<float> values = float_list(text);
  if (values.size() == count) return values;
  return malformed(flag, text, std::to_string(count) + " finite numbers separated by commas");
}

Result<glm::vec4> parse_color(std::string_view flag, std::string_view text, bool with_alpha) {
  std::vector<float> v = float_list(text);
  bool count_ok = v.size() == 3 || (with_alpha && v.size() == 4);
  if (!count_ok) {
    return malformed(flag, text, with_alpha ? "R,G,B or R,G,B,A" : "R,G,B");
  }
  for (float c : v) {
    if (!(c >= 0.0f && c <= 1.0f)) {
      return Status::error(std::string(flag) + ": every channel must be in [0, 1], got '" +
                           std::string(text) + "'");
    }
  }
  return glm::vec4(v[0], v[1], v[2], v.size() == 4 ? v[3] : 1.0f);
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

size_t edit_distance(std::string_view a, std::string_view b) {
  // One row of the Levenshtein table at a time.
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
    }
  }
  return row[b.size()];
}

std::optional<std::string> closest_word(std::string_view word,
                                        std::span<const std::string> candidates) {
  if (word.empty()) return std::nullopt;
  std::optional<std::string> best;
  size_t best_distance = std::min<size_t>(2, (word.size() - 1) / 2) + 1;
  for (const std::string& candidate : candidates) {
    size_t d = edit_distance(word, candidate);
    if (d < best_distance) best = candidate, best_distance = d;
  }
  return best;
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
