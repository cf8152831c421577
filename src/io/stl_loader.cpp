// io/stl_loader.cpp: STL files (binary and ASCII) into meshes with flat normals.
//
// No library: Debian has none for STL alone, and the format is two pages. Binary: an 80-byte
// header, a little-endian triangle count, then 50 bytes per triangle (normal, three vertices, a
// 16-bit attribute); bytes past 84 + 50 * count are ignored with a warning. ASCII: `solid NAME`,
// then `facet normal nx ny nz / outer loop / vertex x y z` (three) `/ endloop / endfacet`, then
// `endsolid NAME` (several solids may follow one another; keywords in any case). Each triangle gets
// three vertices of its own whose normal is the facet normal; a zero or non-finite facet normal
// (common in exported files) is replaced by the triangle's own, counter-clockwise. A file whose
// corners run clockwise about its normals throughout is turned (match_winding_to_normals).

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

#include <charconv>
#include <system_error>

#include <glm/geometric.hpp>

#include "io/model_formats.hpp"

namespace softrast::detail {
namespace {

// 'word', appended rather than "'" + ...: GCC 12 warns falsely (-Wrestrict) about the latter.
std::string quoted(std::string_view word) {
  std::string text(1, '\'');
  text.append(word);
  return text += '\'';
}

Status fail(const std::string& name, const std::string& reason) {
  return Status::error(name + ": " + reason);
}

uint32_t little32(const char* p) {
  const auto* b = reinterpret_cast<const uint8_t*>(p);
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

float little_float(const char* p) {
  uint32_t bits = little32(p);
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Appends one flat triangle; the normal is the facet's if usable, else the triangle's.
void add_triangle(Mesh& mesh, const glm::vec3 p[3], glm::vec3 normal) {
  float length = glm::length(normal);
  if (!(length > 0.0f) || !std::isfinite(length)) {
    normal = glm::cross(p[1] - p[0], p[2] - p[0]);
    length = glm::length(normal);
  }
  normal = length > 0.0f && std::isfinite(length) ? normal / length : glm::vec3(0.0f, 0.0f, 1.0f);
  auto first = uint32_t(mesh.positions.size());
  for (int k = 0; k < 3; ++k) {
    mesh.positions.push_back(p[k]);
    mesh.normals.push_back(normal);
    mesh.uvs.emplace_back(0.0f);
    mesh.indices.push_back(first + uint32_t(k));
  }
}

// Largest triangle count: three vertices of 32 bytes and three indices each, some 29 GB at the
// 32-bit limit of the indices. The byte limit of the file comes first in practice.
constexpr uint64_t kMaxTriangles = UINT32_MAX / 3;

Result<Mesh> parse_binary(const char* data, size_t size, const std::string& name) {
  if (size < 84) {
    return fail(name, "truncated binary STL: " + std::to_string(size) +
                          " bytes, fewer than its 84-byte header");
  }
  uint64_t count = little32(data + 80);
  uint64_t expected = 84 + 50 * count;
  if (expected > size) {
    return fail(name, "binary STL declares " + std::to_string(count) + " triangles (" +
                          std::to_string(expected) + " bytes) but has " + std::to_string(size) +
                          " bytes (truncated)");
  }
  if (count == 0) return fail(name, "no triangles");
  if (count > kMaxTriangles) return fail(name, "too many triangles");
  Mesh mesh;
  mesh.positions.reserve(size_t(count) * 3);
  mesh.normals.reserve(size_t(count) * 3);
  mesh.uvs.reserve(size_t(count) * 3);
  mesh.indices.reserve(size_t(count) * 3);
  for (uint64_t t = 0; t < count; ++t) {
    const char* at = data + 84 + 50 * t;
    glm::vec3 normal(little_float(at), little_float(at + 4), little_float(at + 8));
    glm::vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      const char* v = at + 12 + 12 * k;
      p[k] = {little_float(v), little_float(v + 4), little_float(v + 8)};
      if (!finite(p[k])) {
        return fail(name, "triangle " + std::to_string(t) + " (byte " +
                              std::to_string(84 + 50 * t) + "): a vertex is not finite");
      }
    }
    add_triangle(mesh, p, normal);
  }
  if (expected < size) {  // some writers pad the file or append their own data
    mesh.warnings.push_back(name + ": " + std::to_string(size - expected) + " bytes after the " +
                            std::to_string(count) +
                            " triangles the binary STL declares are ignored");
  }
  return mesh;
}

// The words of an ASCII STL with their line numbers.
class Words {
 public:
  Words(const char* data, size_t size) : data_(data), size_(size) {}

  std::string_view next() {
    while (at_ < size_ && std::strchr(" \t\r\n\v\f", data_[at_]) && data_[at_] != '\0') {
      if (data_[at_] == '\n') ++line_;
      ++at_;
    }
    size_t start = at_;
    while (at_ < size_ && !std::strchr(" \t\r\n\v\f", data_[at_])) ++at_;
    if (at_ < size_ && data_[at_] == '\0' && at_ == start) ++at_;  // a NUL is a word of its own
    return {data_ + start, at_ - start};
  }
  // Skips the rest of the line (a solid's name).
  void skip_line() {
    while (at_ < size_ && data_[at_] != '\n') ++at_;
  }
  size_t line() const { return line_; }

 private:
  const char* data_;
  size_t size_;
  size_t at_ = 0;
  size_t line_ = 1;
};

// Keywords are compared without regard to case: the format's are lower case, but some writers
// use upper case ("SOLID", "FACET NORMAL").
bool same_word(std::string_view word, std::string_view keyword) {
  if (word.size() != keyword.size()) return false;
  for (size_t i = 0; i < word.size(); ++i) {
    char c = word[i];
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    if (c != keyword[i]) return false;
  }
  return true;
}

class AsciiStl {
 public:
  AsciiStl(const char* data, size_t size, const std::string& name)
      : words_(data, size), name_(name) {}

  Result<Mesh> parse();

 private:
  Status error(const std::string& reason) const {
    return Status::error(name_ + ":" + std::to_string(words_.line()) + ": " + reason);
  }
  Status expect(std::string_view keyword) {
    std::string_view w = words_.next();
    if (same_word(w, keyword)) return {};
    if (w.empty())
      return error("the file ends where '" + std::string(keyword) + "' should be (truncated)");
    return error("expected '" + std::string(keyword) + "', found '" + printable(w) + "'");
  }
  static std::string printable(std::string_view w) {
    std::string s(w.substr(0, 40));
    for (char& c : s) {
      if (c == '\0') c = '?';
    }
    return s;
  }
  Status vec3(glm::vec3& v) {
    for (int k = 0; k < 3; ++k) {
      std::string_view w = words_.next();
      if (w.empty()) return error("the file ends inside a facet (truncated)");
      if (w.size() > 1 && w[0] == '+' && w[1] != '-') w.remove_prefix(1);
      double d = 0.0;
      auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), d);
      if (ec == std::errc() && end == w.data() + w.size() &&
          std::fabs(d) <= double(std::numeric_limits<float>::max())) {
        v[k] = float(d);
        continue;
      }
      if (ec == std::errc::invalid_argument || end != w.data() + w.size()) {
        return error(quoted(printable(w)) + " is not a number");
      }
      return error("number " + printable(w) + " is not finite as a 32-bit float");
    }
    return {};
  }
  Status facet();

  Words words_;
  const std::string& name_;
  Mesh mesh_;
};

Status AsciiStl::facet() {
  if (Status s = expect("normal"); !s.ok()) return s;
  glm::vec3 normal, p[3];
  if (Status s = vec3(normal); !s.ok()) return s;
  if (Status s = expect("outer"); !s.ok()) return s;
  if (Status s = expect("loop"); !s.ok()) return s;
  for (glm::vec3& v : p) {
    if (Status s = expect("vertex"); !s.ok()) return s;
    if (Status s = vec3(v); !s.ok()) return s;
  }
  if (Status s = expect("endloop"); !s.ok()) return s;
  if (Status s = expect("endfacet"); !s.ok()) return s;
  if (mesh_.triangle_count() >= kMaxTriangles) return error("too many triangles");
  add_triangle(mesh_, p, normal);
  return {};
}

Result<Mesh> AsciiStl::parse() {
  if (Status s = expect("solid"); !s.ok()) return s;
  words_.skip_line();
  for (;;) {
    std::string_view w = words_.next();
    if (same_word(w, "facet")) {
      if (Status s = facet(); !s.ok()) return s;
    } else if (same_word(w, "endsolid")) {
      words_.skip_line();
      std::string_view after = words_.next();
      if (after.empty()) break;
      if (!same_word(after, "solid"))
        return error("expected 'solid' or the end, found '" + printable(after) + "'");
      words_.skip_line();
    } else if (w.empty()) {
      return error("the file ends before 'endsolid' (truncated)");
    } else {
      return error("expected 'facet' or 'endsolid', found '" + printable(w) + "'");
    }
  }
  if (mesh_.indices.empty()) return fail(name_, "no triangles");
  return std::move(mesh_);
}

// STL says each facet's normal points out of the solid and its corners run counter-clockwise seen
// from outside. Files that keep the normals but list every corner the other way round (assimp's
// Spider_binary.stl: all 1368 facets) drew dark: the faces the camera sees are back faces by
// their winding, and two-sided lighting turned their normals away. Where most facets whose normal
// was given disagree with their winding, the file's winding is taken to be the reversed one and
// every triangle is turned (a few facets with stray normals are left as they are, and a file of
// zero normals has nothing to compare).
void match_winding_to_normals(Mesh& mesh, const std::string& name) {
  size_t against = 0, with = 0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const glm::vec3* p = &mesh.positions[mesh.indices[t]];  // three vertices of its own
    float side = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), mesh.normals[mesh.indices[t]]);
    against += side < 0.0f;
    with += side > 0.0f;
  }
  if (against <= with) return;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  }
  mesh.warnings.push_back(name + ": " + std::to_string(against) + " of " +
                          std::to_string(mesh.indices.size() / 3) +
                          " facets list their corners clockwise about their normals; every "
                          "facet's corners are taken in the reverse order");
}

Result<Mesh> parse(const char* data, size_t size, bool binary, const std::string& name) {
  if (binary) return parse_binary(data, size, name);
  Result<Mesh> mesh = AsciiStl(data, size, name).parse();
  if (!mesh.ok() && size >= 84 && 84 + 50 * uint64_t(little32(data + 80)) < size) {
    // A binary file whose header begins with "solid" (some writers put it there) and that has
    // bytes after its triangles, so that its size did not tell: binary after all if it reads so.
    if (Result<Mesh> as_binary = parse_binary(data, size, name); as_binary.ok()) return as_binary;
  }
  return mesh;
}

}  // namespace

bool is_binary_stl(const char* data, size_t size) {
  return size >= 84 && 84 + 50 * uint64_t(little32(data + 80)) == size;
}

Result<Mesh> parse_stl(const char* data, size_t size, bool binary, const std::string& name) {
  if (size == 0) data = "";  // an empty vector's data() may be null, which memchr must not get
  Result<Mesh> mesh = parse(data, size, binary, name);
  if (mesh) match_winding_to_normals(*mesh, name);
  return mesh;
}

}  // namespace softrast::detail
