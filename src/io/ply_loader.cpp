// io/ply_loader.cpp: PLY files (ASCII, binary little and big endian) into meshes.
//
// Debian has no small, maintained PLY library (assimp reads PLY among forty formats and is some
// 20 MB installed), so this is a strict parser of the format as Greg Turk defined it: a text
// header of elements and their properties, then the elements in that order. Read: the vertex
// element's x, y, z (required), nx, ny, nz, and u, v / s, t / texture_u, texture_v /
// texture_s, texture_t; red, green, blue (and alpha; also r, g, b, a and diffuse_red, ...) as
// vertex colours, integers scaled by their type's largest value (255 for uchar), floats as they
// are, both clamped to [0, 1]; any other property is read and dropped. The face element's
// vertex_indices (or vertex_index) list, of any integer types, cut into triangles as
// geometry/polygon.hpp says (the fan of a convex face, ear clipping of a concave one). Other
// elements (edges, materials, ...) are read past. A file of vertices without faces is a point
// cloud: every vertex a point (Mesh::point_indices).
//
// Robustness: every element count is checked against the bytes left before anything is reserved
// (a binary element has a known minimum size; an ASCII value takes at least two bytes), list
// lengths are capped and checked the same way, numbers must fit their declared type, positions
// and normals must be finite, and vertex indices must name a vertex.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <glm/geometric.hpp>

#include "geometry/polygon.hpp"
#include "io/model_formats.hpp"

namespace softrast::detail {
namespace {

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeName {
  const char* name;
  Type type;
};
constexpr std::array<TypeName, 16> kTypeNames = {{
    {"char", Type::kInt8},
    {"int8", Type::kInt8},
    {"uchar", Type::kUint8},
    {"uint8", Type::kUint8},
    {"short", Type::kInt16},
    {"int16", Type::kInt16},
    {"ushort", Type::kUint16},
    {"uint16", Type::kUint16},
    {"int", Type::kInt32},
    {"int32", Type::kInt32},
    {"uint", Type::kUint32},
    {"uint32", Type::kUint32},
    {"float", Type::kFloat32},
    {"float32", Type::kFloat32},
    {"double", Type::kFloat64},
    {"float64", Type::kFloat64},
}};

size_t type_size(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 8;
}

bool is_integer(Type t) {
  return t != Type::kFloat32 && t != Type::kFloat64;
}

std::optional<Type> type_named(std::string_view name) {
  for (const TypeName& t : kTypeNames) {
    if (name == t.name) return t.type;
  }
  return std::nullopt;
}

enum class Encoding { kAscii, kLittle, kBig };

// A colour channel in [0, 1]: an integer over its type's largest value (uchar 255, ushort 65535),
// a float as it is; clamped.
double colour_channel(Type type, double value) {
  switch (type) {
    case Type::kInt8:
      value /= 127.0;
      break;
    case Type::kUint8:
      value /= 255.0;
      break;
    case Type::kInt16:
      value /= 32767.0;
      break;
    case Type::kUint16:
      value /= 65535.0;
      break;
    case Type::kInt32:
      value /= 2147483647.0;
      break;
    case Type::kUint32:
      value /= 4294967295.0;
      break;
    default:
      break;
  }
  return std::clamp(value, 0.0, 1.0);
}

// What a property is used for.
enum class Role { kSkip, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kRed, kGreen, kBlue, kAlpha, kIndices };

struct Property {
  std::string name;
  Type type = Type::kFloat32;
  bool list = false;
  Type count_type = Type::kUint8;
  Role role = Role::kSkip;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

// Largest list (a face's corners): far above any real polygon, small enough that a corrupt
// count cannot ask for much memory.
constexpr uint64_t kMaxListLength = 1 << 16;
constexpr size_t kMaxHeaderBytes = size_t(1) << 20;
constexpr size_t kMaxElements = 256;
constexpr size_t kMaxProperties = 1024;

// 'word', appended rather than "'" + ...: GCC 12 warns falsely (-Wrestrict) about the latter.
std::string quoted(std::string_view word) {
  std::string text(1, '\'');
  text.append(word);
  return text += '\'';
}

Status fail(const std::string& name, const std::string& reason) {
  return Status::error(name + ": " + reason);
}

Status fail_line(const std::string& name, size_t line, const std::string& reason) {
  return Status::error(name + ":" + std::to_string(line) + ": " + reason);
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && (line[at] == ' ' || line[at] == '\t' || line[at] == '\r')) ++at;
    size_t start = at;
    while (at < line.size() && line[at] != ' ' && line[at] != '\t' && line[at] != '\r') ++at;
    if (at > start) words.push_back(line.substr(start, at - start));
  }
  return words;
}

Role vertex_role(std::string_view name) {
  if (name == "x") return Role::kX;
  if (name == "y") return Role::kY;
  if (name == "z") return Role::kZ;
  if (name == "nx") return Role::kNx;
  if (name == "ny") return Role::kNy;
  if (name == "nz") return Role::kNz;
  if (name == "u" || name == "s" || name == "texture_u" || name == "texture_s") return Role::kU;
  if (name == "v" || name == "t" || name == "texture_v" || name == "texture_t") return Role::kV;
  if (name == "red" || name == "r" || name == "diffuse_red") return Role::kRed;
  if (name == "green" || name == "g" || name == "diffuse_green") return Role::kGreen;
  if (name == "blue" || name == "b" || name == "diffuse_blue") return Role::kBlue;
  if (name == "alpha" || name == "a" || name == "diffuse_alpha") return Role::kAlpha;
  return Role::kSkip;
}

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t data_start = 0;              // byte offset of the first element
  size_t lines = 0;                   // header lines (ASCII data starts on line lines + 1)
  std::vector<std::string> warnings;  // lines read past
};

class HeaderParser {
 public:
  HeaderParser(const char* data, size_t size, const std::string& name)
      : data_(data), size_(size), name_(name) {}

  Status parse(Header& h);

 private:
  Status error(const std::string& reason) const { return fail_line(name_, line_, reason); }
  Status format_line(const std::vector<std::string_view>& w, Header& h);
  Status element_line(const std::vector<std::string_view>& w, Header& h);
  Status property_line(const std::vector<std::string_view>& w, Header& h);

  const char* data_;
  size_t size_;
  const std::string& name_;
  size_t line_ = 0;
  bool has_format_ = false;
};

Status HeaderParser::format_line(const std::vector<std::string_view>& w, Header& h) {
  if (has_format_) return error("a second 'format' line");
  if (w.size() != 3 || w[2] != "1.0")
    return error("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
  if (w[1] == "ascii") {
    h.encoding = Encoding::kAscii;
  } else if (w[1] == "binary_little_endian") {
    h.encoding = Encoding::kLittle;
  } else if (w[1] == "binary_big_endian") {
    h.encoding = Encoding::kBig;
  } else {
    return error("unknown format '" + std::string(w[1]) + "'");
  }
  has_format_ = true;
  return {};
}

Status HeaderParser::element_line(const std::vector<std::string_view>& w, Header& h) {
  if (w.size() != 3) return error("expected 'element NAME COUNT'");
  uint64_t count = 0;
  auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
  if (ec != std::errc() || end != w[2].data() + w[2].size()) {
    return error("element count '" + std::string(w[2]) + "' is not a number");
  }
  if (h.elements.size() == kMaxElements) return error("more than 256 elements");
  for (const Element& e : h.elements) {
    if (e.name == w[1]) return error("element '" + std::string(w[1]) + "' declared twice");
  }
  h.elements.push_back({std::string(w[1]), count, {}});
  return {};
}

Status HeaderParser::property_line(const std::vector<std::string_view>& w, Header& h) {
  if (h.elements.empty()) return error("property before any element");
  Element& e = h.elements.back();
  if (e.properties.size() == kMaxProperties) return error("more than 1024 properties");
  Property p;
  size_t name_at = 2;
  if (w.size() >= 2 && w[1] == "list") {
    if (w.size() != 5) return error("expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
    std::optional<Type> count = type_named(w[2]), item = type_named(w[3]);
    if (!count || !item)
      return error("unknown type in '" + std::string(w[2]) + " " + std::string(w[3]) + "'");
    if (!is_integer(*count)) return error("a list count must be an integer type");
    p.list = true;
    p.count_type = *count;
    p.type = *item;
    name_at = 4;
  } else {
    if (w.size() != 3) return error("expected 'property TYPE NAME'");
    std::optional<Type> type = type_named(w[1]);
    if (!type) return error("unknown type '" + std::string(w[1]) + "'");
    p.type = *type;
  }
  p.name = std::string(w[name_at]);
  if (e.name == "vertex" && !p.list) p.role = vertex_role(p.name);
  if (e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
    if (!is_integer(p.type)) return error("face vertex indices must be an integer type");
    p.role = Role::kIndices;
  }
  for (const Property& q : e.properties) {
    if (q.role != Role::kSkip && q.role == p.role) {
      return error("property '" + p.name + "' repeats what '" + q.name + "' gives");
    }
  }
  e.properties.push_back(std::move(p));
  return {};
}

Status HeaderParser::parse(Header& h) {
  size_t at = 0;
  for (;;) {
    const void* nl = std::memchr(data_ + at, '\n', std::min(size_, kMaxHeaderBytes) - at);
    ++line_;
    if (!nl) {
      return size_ > kMaxHeaderBytes ? error("header longer than 1 MiB")
                                     : error("the file ends in the header (no 'end_header')");
    }
    size_t end = size_t(static_cast<const char*>(nl) - data_);
    std::string_view text(data_ + at, end - at);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    at = end + 1;
    if (line_ == 1) {
      if (text != "ply") return error("not a PLY file (the first line is not 'ply')");
      continue;
    }
    if (std::memchr(text.data(), '\0', text.size())) return error("NUL byte in the header");
    std::vector<std::string_view> w = split_words(text);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    Status s;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      s = format_line(w, h);
    } else if (w[0] == "element") {
      s = element_line(w, h);
    } else if (w[0] == "property") {
      s = property_line(w, h);
    } else {
      // Not a PLY statement: read past, as a comment, with a warning. Blender 2.4x wrote its
      // "Created by Blender3D ..." line without the 'comment' keyword (assimp's Wuson.ply), and
      // the lines that matter (format, element, property) are checked as they come.
      std::string excerpt(text.substr(0, 60));
      h.warnings.push_back(name_ + ":" + std::to_string(line_) + ": header line '" + excerpt +
                           (text.size() > 60 ? "...'" : "'") +
                           " is not a PLY statement; read past as a comment");
    }
    if (!s.ok()) return s;
  }
  if (!has_format_) return error("'end_header' before any 'format' line");
  h.data_start = at;
  h.lines = line_;
  return {};
}

// Reads the values of the body, ASCII or binary, with the position for messages.
class BodyReader {
 public:
  BodyReader(const char* data, size_t size, const Header& h, const std::string& name)
      : data_(data),
        size_(size),
        at_(h.data_start),
        encoding_(h.encoding),
        line_(h.lines + 1),
        name_(name) {}

  size_t remaining() const { return size_ - at_; }
  bool ascii() const { return encoding_ == Encoding::kAscii; }

  // Reads one value of type t into `value`; false with `error_` set otherwise.
  bool read(Type t, double& value) { return ascii() ? read_text(t, value) : read_binary(t, value); }

  // For ASCII: each element is one line; anything left on it is an error.
  bool end_element() {
    if (!ascii()) return true;
    while (at_ < size_ && (data_[at_] == ' ' || data_[at_] == '\t' || data_[at_] == '\r')) ++at_;
    // Every line ends in a newline, the last one too: without it, a cut inside the last number
    // ("4 20 21 22 2" for "... 23") would pass for a whole file.
    if (at_ == size_) return fail("the file ends before the end of the line (truncated)");
    if (data_[at_] != '\n') return fail("more values than the header declares");
    ++at_;
    ++line_;
    return true;
  }

  // After the last element: only white space may follow in ASCII, nothing in binary.
  bool at_clean_end() {
    if (ascii()) {
      while (at_ < size_ && std::strchr(" \t\r\n", data_[at_]) && data_[at_] != '\0') {
        if (data_[at_] == '\n') ++line_;
        ++at_;
      }
    }
    if (at_ != size_) return fail("data after the last element");
    return true;
  }

  bool fail(const std::string& reason) {
    error_ = reason;
    return false;
  }
  // "name:LINE: where: reason" (ASCII) or "name: where, byte N: reason" (binary).
  Status error(const std::string& where) const {
    if (ascii()) return fail_line(name_, line_, where + ": " + error_);
    return Status::error(name_ + ": " + where + ", byte " + std::to_string(at_) + ": " + error_);
  }

 private:
  bool read_binary(Type t, double& value) {
    size_t n = type_size(t);
    if (remaining() < n) return fail("the file ends here (truncated)");
    uint8_t b[8];
    std::memcpy(b, data_ + at_, n);
    if (encoding_ == Encoding::kBig) std::reverse(b, b + n);
    at_ += n;
    switch (t) {
      case Type::kInt8:
        value = double(int8_t(b[0]));
        break;
      case Type::kUint8:
        value = double(b[0]);
        break;
      case Type::kInt16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        value = v;
        break;
      }
      case Type::kUint16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        value = v;
        break;
      }
      case Type::kInt32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        value = v;
        break;
      }
      case Type::kUint32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        value = v;
        break;
      }
      case Type::kFloat32: {
        float v;
        std::memcpy(&v, b, 4);
        value = v;
        break;
      }
      case Type::kFloat64: {
        std::memcpy(&value, b, 8);
        break;
      }
    }
    return true;
  }

  bool read_text(Type t, double& value) {
    while (at_ < size_ && (data_[at_] == ' ' || data_[at_] == '\t' || data_[at_] == '\r')) ++at_;
    if (at_ == size_) return fail("the file ends here (truncated)");
    if (data_[at_] == '\n') return fail("fewer values than the header declares");
    if (data_[at_] == '\0') return fail("NUL byte: not a text file");
    size_t start = at_;
    while (at_ < size_ && !std::strchr(" \t\r\n", data_[at_])) ++at_;
    std::string_view word(data_ + start, at_ - start);
    if (is_integer(t)) return parse_integer(word, t, value);
    auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (ec == std::errc::result_out_of_range)
      return fail("number " + std::string(word) + " is out of range");
    if (ec != std::errc() || end != word.data() + word.size()) {
      return fail(quoted(word) + " is not a number");
    }
    return true;
  }

  bool parse_integer(std::string_view word, Type t, double& value) {
    int64_t v = 0;
    auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() && ec != std::errc::result_out_of_range) {
      return fail(quoted(word) + " is not an integer");
    }
    if (end != word.data() + word.size()) return fail(quoted(word) + " is not an integer");
    int64_t lo = 0, hi = 0;
    switch (t) {
      case Type::kInt8:
        lo = INT8_MIN;
        hi = INT8_MAX;
        break;
      case Type::kUint8:
        hi = UINT8_MAX;
        break;
      case Type::kInt16:
        lo = INT16_MIN;
        hi = INT16_MAX;
        break;
      case Type::kUint16:
        hi = UINT16_MAX;
        break;
      case Type::kInt32:
        lo = INT32_MIN;
        hi = INT32_MAX;
        break;
      default:
        hi = UINT32_MAX;
        break;
    }
    if (ec == std::errc::result_out_of_range || v < lo || v > hi) {
      return fail("integer " + std::string(word) + " does not fit its type");
    }
    value = double(v);
    return true;
  }

  const char* data_;
  size_t size_;
  size_t at_;
  Encoding encoding_;
  size_t line_;
  const std::string& name_;
  std::string error_;
};

// Fewest bytes one element can take: binary, the fixed properties plus each list's count; ASCII,
// two per value (a digit and a separator; a list at least its count).
uint64_t min_element_bytes(const Element& e, bool ascii) {
  uint64_t bytes = 0;
  for (const Property& p : e.properties) {
    bytes += ascii ? 2 : type_size(p.list ? p.count_type : p.type);
  }
  return std::max<uint64_t>(bytes, 1);
}

class PlyBuilder {
 public:
  PlyBuilder(const Header& h, const std::string& name, BodyReader& body)
      : h_(h), name_(name), body_(body) {}

  Result<Mesh> build();

 private:
  Status read_element(const Element& e);
  bool read_vertex(const Element& e, size_t index);
  bool read_face(const Element& e, const Property& p, size_t face);
  Status where(const Element& e, uint64_t i) const {
    return body_.error(e.name + " " + std::to_string(i));
  }

  const Header& h_;
  const std::string& name_;
  BodyReader& body_;
  Mesh mesh_;
  uint64_t vertex_count_ = 0;
  bool has_normals_ = false, has_uvs_ = false, has_colors_ = false;
  std::vector<uint32_t> corners_;
  std::vector<glm::vec3> points_;               // the face's corners' positions
  std::vector<uint32_t> triangles_;             // its triangles, as corner numbers
  uint64_t ear_tests_ = detail::kFileEarTests;  // the file's allowance (geometry/polygon.hpp)
};

bool PlyBuilder::read_vertex(const Element& e, size_t index) {
  float v[int(Role::kIndices)] = {};  // by Role
  v[int(Role::kAlpha)] = 1.0f;        // opaque unless the file says otherwise
  for (const Property& p : e.properties) {
    double value = 0.0;
    if (p.list) {
      double count = 0.0;
      if (!body_.read(p.count_type, count)) return false;
      if (count < 0 || count > double(kMaxListLength))
        return body_.fail("list length out of range");
      for (int k = 0; k < int(count); ++k) {
        if (!body_.read(p.type, value)) return false;
      }
      continue;
    }
    if (!body_.read(p.type, value)) return false;
    if (p.role == Role::kSkip) continue;
    if (!(std::fabs(value) <= double(std::numeric_limits<float>::max()))) {
      return body_.fail("property '" + p.name + "' is not finite as a 32-bit float");
    }
    if (p.role >= Role::kRed && p.role <= Role::kAlpha) value = colour_channel(p.type, value);
    v[int(p.role)] = float(value);
  }
  mesh_.positions[index] = {v[int(Role::kX)], v[int(Role::kY)], v[int(Role::kZ)]};
  if (has_normals_)
    mesh_.normals[index] = {v[int(Role::kNx)], v[int(Role::kNy)], v[int(Role::kNz)]};
  if (has_uvs_) mesh_.uvs[index] = {v[int(Role::kU)], v[int(Role::kV)]};
  if (has_colors_) {
    mesh_.colors[index] = {v[int(Role::kRed)], v[int(Role::kGreen)], v[int(Role::kBlue)],
                           v[int(Role::kAlpha)]};
  }
  return true;
}

bool PlyBuilder::read_face(const Element& e, const Property& indices, size_t face) {
  (void)face;
  for (const Property& p : e.properties) {
    double count = 0.0, value = 0.0;
    if (!p.list) {
      if (!body_.read(p.type, value)) return false;
      continue;
    }
    if (!body_.read(p.count_type, count)) return false;
    if (count < 0 || count > double(kMaxListLength)) {
      return body_.fail("list of " + std::to_string(int64_t(count)) + " items (at most " +
                        std::to_string(kMaxListLength) + ")");
    }
    if (!body_.ascii() && uint64_t(count) * type_size(p.type) > body_.remaining()) {
      return body_.fail("a list of " + std::to_string(int64_t(count)) +
                        " items runs past the end of the file (truncated)");
    }
    if (&p != &indices) {
      for (int k = 0; k < int(count); ++k) {
        if (!body_.read(p.type, value)) return false;
      }
      continue;
    }
    if (count < 3) return body_.fail("a face with fewer than 3 vertices");
    corners_.clear();
    for (int k = 0; k < int(count); ++k) {
      if (!body_.read(p.type, value)) return false;
      if (value < 0 || value >= double(vertex_count_)) {
        return body_.fail("vertex index " + std::to_string(int64_t(value)) +
                          " is out of range (0.." + std::to_string(int64_t(vertex_count_) - 1) +
                          ")");
      }
      corners_.push_back(uint32_t(value));
    }
    if (mesh_.indices.size() + 3 * (corners_.size() - 2) > UINT32_MAX) {
      return body_.fail("too many faces");
    }
    // Triangles as geometry/polygon.hpp cuts the face (the fan of a convex one). A face read
    // before the vertices (an element order PLY allows) sees them all at the origin: the fan.
    points_.clear();
    for (uint32_t corner : corners_) points_.push_back(mesh_.positions[corner]);
    triangles_.clear();
    detail::triangulate_polygon(points_.data(), points_.size(), triangles_, &ear_tests_);
    for (uint32_t k : triangles_) mesh_.indices.push_back(corners_[k]);
  }
  return true;
}

Status PlyBuilder::read_element(const Element& e) {
  uint64_t need = min_element_bytes(e, body_.ascii());
  if (e.count > body_.remaining() / need) {
    return Status::error(name_ + ": " + std::to_string(e.count) + " " + e.name +
                         " elements need at least " + std::to_string(need) + " bytes each, but " +
                         std::to_string(body_.remaining()) + " bytes are left (truncated)");
  }
  const Property* indices = nullptr;
  for (const Property& p : e.properties) {
    if (p.role == Role::kIndices) indices = &p;
  }
  if (e.name == "face" && indices) mesh_.indices.reserve(size_t(e.count) * 3);
  for (uint64_t i = 0; i < e.count; ++i) {
    bool ok = e.name == "vertex"            ? read_vertex(e, size_t(i))
              : e.name == "face" && indices ? read_face(e, *indices, size_t(i))
                                            : read_face(e, Property{}, size_t(i));
    if (!ok || !body_.end_element()) return where(e, i);
  }
  return {};
}

Result<Mesh> PlyBuilder::build() {
  const Element* vertices = nullptr;
  for (const Element& e : h_.elements) {
    if (e.name == "vertex") vertices = &e;
  }
  if (!vertices) return fail(name_, "no 'vertex' element");
  int xyz = 0, normals = 0, uvs = 0, colors = 0;
  for (const Property& p : vertices->properties) {
    xyz += p.role == Role::kX || p.role == Role::kY || p.role == Role::kZ;
    normals += p.role == Role::kNx || p.role == Role::kNy || p.role == Role::kNz;
    uvs += p.role == Role::kU || p.role == Role::kV;
    colors += p.role == Role::kRed || p.role == Role::kGreen || p.role == Role::kBlue;
  }
  if (xyz != 3) return fail(name_, "the vertex element lacks x, y or z");
  if (vertices->count > UINT32_MAX) return fail(name_, "more than 2^32 - 1 vertices");
  vertex_count_ = vertices->count;
  has_normals_ = normals == 3;
  has_uvs_ = uvs == 2;
  has_colors_ = colors == 3;  // red, green and blue; alpha optional
  // The vertex arrays, once the count is known to fit in the bytes left.
  uint64_t need = min_element_bytes(*vertices, body_.ascii());
  if (vertex_count_ > (body_.remaining()) / need) {
    return Status::error(name_ + ": " + std::to_string(vertex_count_) +
                         " vertex elements need at least " + std::to_string(need) +
                         " bytes each, but " + std::to_string(body_.remaining()) +
                         " bytes are left (truncated)");
  }
  mesh_.positions.resize(size_t(vertex_count_));
  mesh_.uvs.resize(size_t(vertex_count_), glm::vec2(0.0f));
  if (has_normals_) mesh_.normals.resize(size_t(vertex_count_));
  if (has_colors_) mesh_.colors.resize(size_t(vertex_count_));
  for (const Element& e : h_.elements) {
    if (Status s = read_element(e); !s.ok()) return s;
  }
  if (!body_.at_clean_end()) return body_.error("end");
  if (vertex_count_ == 0) return fail(name_, "no faces");
  if (mesh_.indices.empty()) {  // a point cloud (a scanner's PLY): every vertex a point
    mesh_.point_indices.resize(size_t(vertex_count_));
    for (size_t i = 0; i < mesh_.point_indices.size(); ++i) mesh_.point_indices[i] = uint32_t(i);
  }
  for (glm::vec3& n : mesh_.normals) {
    float length = glm::length(n);
    n = length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  if (!has_normals_) compute_smooth_normals(mesh_);
  return std::move(mesh_);
}

}  // namespace

Result<Mesh> parse_ply(const char* data, size_t size, const std::string& name) {
  if (size == 0) data = "";  // an empty vector's data() may be null, which memchr must not get
  Header header;
  if (Status s = HeaderParser(data, size, name).parse(header); !s.ok()) return s;
  BodyReader body(data, size, header, name);
  Result<Mesh> mesh = PlyBuilder(header, name, body).build();
  if (mesh)
    mesh->warnings.insert(mesh->warnings.begin(), header.warnings.begin(), header.warnings.end());
  return mesh;
}

}  // namespace softrast::detail
