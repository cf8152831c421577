// apps/softrast/values.hpp: the text of flag values (sizes, vectors, enum names) turned into
// typed values, with a one-line error naming the flag for anything malformed or out of range.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/status.hpp"

namespace softrast::cli {

// "WxH", both in [1, kMaxImageSize], digits only.
Result<glm::ivec2> parse_size(std::string_view flag, std::string_view text);

// Exactly `count` finite numbers separated by commas, e.g. "0.5,-1,2e3" or "0, 0, 3".
Result<std::vector<float>> parse_floats(std::string_view flag, std::string_view text, size_t count);
Result<glm::vec3> parse_vec3(std::string_view flag, std::string_view text);
Result<glm::vec4> parse_vec4(std::string_view flag, std::string_view text);

// "R,G,B" (alpha 1) or, when `with_alpha`, "R,G,B,A"; every channel in [0, 1].
Result<glm::vec4> parse_color(std::string_view flag, std::string_view text, bool with_alpha);

// The edit distance (insertions, deletions, substitutions) between two words.
size_t edit_distance(std::string_view a, std::string_view b);

// The word of `candidates` closest to `word`, if it is close enough to be a likely typo: at
// most 2 edits, and fewer than half of the word's length.
std::optional<std::string> closest_word(std::string_view word,
                                        std::span<const std::string> candidates);

// One accepted spelling of an enum flag's value.
template <class E>
struct Named {
  std::string_view name;
  E value;
};

// "a, b or c": the accepted names, for error messages and help texts.
std::string name_list(std::span<const std::string_view> names);

template <class E>
std::vector<std::string_view> names_of(std::span<const Named<E>> table) {
  std::vector<std::string_view> names;
  for (const Named<E>& n : table) names.push_back(n.name);
  return names;
}

// The value spelled `text` in `table`, or an error listing the accepted names.
template <class E>
Result<E> lookup(std::string_view flag, std::span<const Named<E>> table, std::string_view text) {
  for (const Named<E>& n : table) {
    if (n.name == text) return n.value;
  }
  return Status::error(std::string(flag) + ": unknown value '" + std::string(text) +
                       "' (expected " + name_list(names_of(table)) + ")");
}

}  // namespace softrast::cli
