// io/obj_piece.cpp: parsing one piece of an OBJ file (see obj_piece.hpp). Only v, vt, vn, f, l,
// p, usemtl and mtllib are read; every other statement (o, g, s, vw, ...) is skipped unparsed.

#include "io/obj_piece.hpp"

#include <algorithm>

#include <charconv>
#include <cmath>
#include <cstring>
#include <new>
#include <system_error>

#include "io/text_lines.hpp"

namespace softrast::detail {
namespace {

const char* const kElementName[3] = {"position", "texture coordinate", "normal"};

std::string quoted(std::string_view word) {
  std::string text(1, '\'');  // appended, not "'" + ...: GCC 12 warns falsely about the latter
  text.append(word);
  return text += '\'';
}

// Exact powers of ten as doubles (10^22 is the largest that is).
constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                               1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                               1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

// The common case of an OBJ number, "-15.500000", read from p (which is advanced past it): at
// most 19 digits in all, no exponent. The digits as an integer m <= 2^53 and 10^k with k <= 22
// are both exact doubles, so m / 10^k is the correctly rounded value (Clinger's fast path), the
// same double std::from_chars gives. False for anything else, which goes to std::from_chars.
bool parse_decimal_at(const char*& p, const char* end, double& value) {
  bool negative = p < end && *p == '-';
  if (negative) ++p;
  uint64_t m = 0;
  int digits = 0, fraction = 0;
  for (; p < end && is_digit(*p); ++p, ++digits) m = m * 10 + uint64_t(*p - '0');
  if (p < end && *p == '.') {
    for (++p; p < end && is_digit(*p); ++p, ++digits, ++fraction) m = m * 10 + uint64_t(*p - '0');
  }
  if (digits == 0 || digits > 19 || m > (uint64_t(1) << 53) || fraction > 22) return false;
  value = double(m) / kPow10[fraction];
  if (negative) value = -value;
  return true;
}

bool parse_simple_decimal(std::string_view word, double& value) {
  const char* p = word.data();
  const char* end = p + word.size();
  return parse_decimal_at(p, end, value) && p == end;
}

// A word of 1 to 18 digits, optionally after '-', as an integer; false for anything else (which
// std::from_chars then classifies: not an index, or out of range).
bool parse_simple_integer(std::string_view word, int64_t& value) {
  const char* p = word.data();
  const char* end = p + word.size();
  bool negative = p < end && *p == '-';
  if (negative) ++p;
  if (p == end || end - p > 18) return false;
  int64_t v = 0;
  for (; p < end; ++p) {
    if (!is_digit(*p)) return false;
    v = v * 10 + (*p - '0');
  }
  value = negative ? -v : v;
  return true;
}

class PieceParser {
 public:
  explicit PieceParser(ObjPiece& piece) : p_(piece) {}

  // False once the line had an error (recorded in the piece).
  bool line(std::string_view text) {
    if (fast_line(text.data(), text.data() + text.size())) return true;
    ObjWords words(text);
    std::string_view keyword = words.next();
    if (keyword.size() == 1 && keyword[0] == 'v') return numbers(words, kObjPositions, 3);
    if (keyword.size() == 1 && keyword[0] == 'f') return face(words);
    if (keyword.size() == 1 && (keyword[0] == 'l' || keyword[0] == 'p')) {
      return line_or_points(words, keyword[0] == 'p');
    }
    if (keyword == "vt") return numbers(words, kObjUvs, 1);
    if (keyword == "vn") return numbers(words, kObjNormals, 3);
    if (keyword == "usemtl") {  // the name's words, one space apart (a name may hold spaces)
      p_.events.push_back({false, p_.face_sizes.size(), line_, {words.joined()}});
      return true;
    }
    if (keyword == "mtllib") {
      ObjEvent event{true, p_.face_sizes.size(), line_, {}};
      for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
        event.names.emplace_back(w);
      }
      p_.events.push_back(std::move(event));
    }
    return true;  // comments, groups, objects, smoothing, lines, points, and anything unknown
  }

  void start_line(size_t number) { line_ = number; }

  bool error(std::string message) {
    p_.error = ObjPieceError{line_, std::move(message), -1, {}, 0};
    return false;
  }

 private:
  size_t count(int attr) const { return p_.values[attr].size() / kObjComponents[attr]; }

  bool range_error(int attr, std::string_view word) {
    p_.error = ObjPieceError{line_, {}, attr, std::string(word), count(attr)};
    return false;
  }

  // Appends the stored components from at least `required` numbers; the rest must be numbers
  // too: a position's 4th (w) is dropped, and 6 numbers are a position and its colour (r g b,
  // 0 to 1, clamped), as MeshLab and other tools write them; missing optional ones are 0.
  bool numbers(ObjWords& words, int attr, size_t required) {
    std::vector<float>& out = p_.values[attr];
    size_t stored = kObjComponents[attr];
    size_t read = 0;
    float extra[3] = {};
    for (std::string_view w = words.next(); !w.empty(); w = words.next(), ++read) {
      float value = 0.0f;
      ObjNumber n = parse_obj_float(w, value);
      if (n == ObjNumber::kNotNumber) return error(quoted(w) + " is not a number");
      if (n == ObjNumber::kOutOfRange) {
        return error("number " + std::string(w) + " is not finite as a 32-bit float");
      }
      if (read < stored) out.push_back(value);
      if (read >= 3 && read < 6) extra[read - 3] = value;
    }
    if (attr == kObjPositions && read == 6) {
      std::vector<float>& colors = p_.colors;
      colors.resize(out.size() - 3, 1.0f);  // white for the positions before without one
      for (float c : extra) colors.push_back(std::clamp(c, 0.0f, 1.0f));
    }
    if (read < required) {
      out.resize(out.size() - read);
      return error(std::string(kElementName[attr]) + " with fewer than " +
                   std::to_string(required) + (required == 1 ? " number" : " numbers"));
    }
    for (; read < stored; ++read) out.push_back(0.0f);
    return true;
  }

  // One index of corner `corner`: 1-based, or negative counting back from the latest element.
  bool resolve(std::string_view word, int attr, size_t corner) {
    int64_t value = 0;
    bool overflow = false;
    if (!parse_simple_integer(word, value)) {
      auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
      overflow = ec == std::errc::result_out_of_range;
      if (!overflow && (ec != std::errc() || end != word.data() + word.size())) {
        return error("bad face corner: " + quoted(word) + " is not an index");
      }
    }
    int32_t& slot = p_.corners[corner].index[attr];
    int64_t local = int64_t(count(attr));
    if (!overflow && value < 0) {
      if (-value <= local) {
        slot = obj_local(size_t(local + value));
      } else if (value >= -int64_t(INT32_MAX)) {
        p_.fixups.push_back({corner, attr, local + value, size_t(local), line_, std::string(word)});
        slot = 0;  // set by the merge
      } else {
        return range_error(attr, word);
      }
      return true;
    }
    if (!overflow && value > 0 && value <= INT32_MAX) {
      if (value > p_.largest[attr].value) p_.largest[attr] = {value, line_};
      slot = int32_t(value - 1);
      return true;
    }
    return range_error(attr, word);
  }

  bool bad_corner(std::string_view word) {
    return error("bad face corner " + quoted(word) + " (v, v/vt, v//vn or v/vt/vn)");
  }

  // "v", "v/vt", "v//vn" or "v/vt/vn".
  bool corner(std::string_view word) {
    size_t c = p_.corners.size();
    p_.corners.push_back({{0, kObjAbsent, kObjAbsent}});
    size_t slash = word.find('/');
    std::string_view v = word.substr(0, slash);
    if (v.empty()) return bad_corner(word);
    if (!resolve(v, kObjPositions, c)) return false;
    if (slash == std::string_view::npos) return true;
    std::string_view rest = word.substr(slash + 1);
    slash = rest.find('/');
    std::string_view vt = rest.substr(0, slash);
    if (slash == std::string_view::npos) {
      return vt.empty() ? bad_corner(word) : resolve(vt, kObjUvs, c);
    }
    std::string_view vn = rest.substr(slash + 1);
    if (vn.empty()) return bad_corner(word);
    if (!vt.empty() && !resolve(vt, kObjUvs, c)) return false;
    return resolve(vn, kObjNormals, c);
  }

  // The corners of an f, l or p element into p_.corners; false at a bad one.
  bool corners(ObjWords& words, size_t& n) {
    size_t first = p_.corners.size();
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      if (!corner(w)) return false;
    }
    n = p_.corners.size() - first;
    return true;
  }

  bool face(ObjWords& words) {
    size_t n = 0;
    if (!corners(words, n)) return false;
    if (n < 3) return error("face with fewer than 3 vertices");
    p_.face_sizes.push_back(uint32_t(n));
    p_.triangles += n - 2;
    return true;
  }

  // "l v1 v2 ..." (a polyline) or "p v1 v2 ...": corners as a face's (a uv or normal is read and
  // not used), kept among the faces in file order.
  bool line_or_points(ObjWords& words, bool points) {
    size_t n = 0;
    if (!corners(words, n)) return false;
    if (points && n < 1) return error("points (p) without a vertex");
    if (!points && n < 2) return error("line (l) with fewer than 2 vertices");
    p_.others.push_back({p_.face_sizes.size(), points});
    p_.face_sizes.push_back(uint32_t(n));
    return true;
  }

  // Fast paths for the lines that make up nearly all of a large file: v, vt and vn with plain
  // decimals, and f with positive indices. Each accepts only what the general path accepts and
  // gives the same result; anything else (every error included) is left to the general path.
  static bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  }

  bool fast_line(const char* p, const char* end) {
    while (p < end && is_blank(*p)) ++p;
    if (end - p < 2) return false;
    if (p[0] == 'v' && is_blank(p[1])) return fast_numbers(p + 1, end, kObjPositions);
    if (p[0] == 'f' && is_blank(p[1])) return fast_face(p + 1, end);
    if (end - p < 3 || p[0] != 'v' || !is_blank(p[2])) return false;
    if (p[1] == 't') return fast_numbers(p + 2, end, kObjUvs);
    if (p[1] == 'n') return fast_numbers(p + 2, end, kObjNormals);
    return false;
  }

  // Exactly as many plain decimals as the array stores, then the end or a comment.
  bool fast_numbers(const char* p, const char* end, int attr) {
    float v[3];
    size_t count = kObjComponents[attr];
    for (size_t k = 0; k < count; ++k) {
      if (p == end || !is_blank(*p)) return false;
      while (p < end && is_blank(*p)) ++p;
      double d = 0.0;
      if (!parse_decimal_at(p, end, d) || (p != end && !is_blank(*p))) return false;
      if (!(std::fabs(d) <= double(std::numeric_limits<float>::max()))) return false;
      v[k] = float(d);
    }
    while (p < end && is_blank(*p)) ++p;
    if (p != end && *p != '#') return false;
    p_.values[attr].insert(p_.values[attr].end(), v, v + count);
    return true;
  }

  // 1 to 9 digits, not 0: a positive index that needs no range check beyond the final count.
  bool fast_index(const char*& p, const char* end, int attr, int32_t& slot) {
    const char* start = p;
    int64_t value = 0;
    while (p < end && is_digit(*p) && p - start < 10) value = value * 10 + (*p++ - '0');
    if (p == start || p - start > 9 || value == 0) return false;
    if (value > p_.largest[attr].value) p_.largest[attr] = {value, line_};
    slot = int32_t(value - 1);
    return true;
  }

  bool fast_corner(const char*& p, const char* end, ObjCorner& c) {
    if (!fast_index(p, end, kObjPositions, c.index[0])) return false;
    if (p < end && *p == '/') {
      ++p;
      if (p < end && *p == '/') {
        ++p;
        if (!fast_index(p, end, kObjNormals, c.index[2])) return false;
      } else {
        if (!fast_index(p, end, kObjUvs, c.index[1])) return false;
        if (p < end && *p == '/') {
          ++p;
          if (!fast_index(p, end, kObjNormals, c.index[2])) return false;
        }
      }
    }
    return p == end || is_blank(*p);
  }

  bool fast_face(const char* p, const char* end) {
    size_t first = p_.corners.size();
    for (;;) {
      while (p < end && is_blank(*p)) ++p;
      if (p == end || *p == '#') break;
      ObjCorner c{{0, kObjAbsent, kObjAbsent}};
      if (!fast_corner(p, end, c)) {
        p_.corners.resize(first);
        return false;
      }
      p_.corners.push_back(c);
    }
    size_t n = p_.corners.size() - first;
    if (n < 3) {
      p_.corners.resize(first);
      return false;
    }
    p_.face_sizes.push_back(uint32_t(n));
    p_.triangles += n - 2;
    return true;
  }

  ObjPiece& p_;
  size_t line_ = 0;
};

void parse_lines(ObjPiece& piece) {
  const char* at = piece.text.data();
  const char* end = at + piece.text.size();
  const char* nul = static_cast<const char*>(std::memchr(at, '\0', piece.text.size()));
  PieceParser parser(piece);
  size_t number = 0;
  while (at < end) {
    const char* newline = static_cast<const char*>(std::memchr(at, '\n', size_t(end - at)));
    const char* line_end = newline ? newline : end;
    piece.lines = ++number;
    parser.start_line(number);
    if (nul && nul < line_end) {
      parser.error("NUL byte: not a text file");
      return;
    }
    if (size_t(line_end - at) > kMaxTextLineBytes) {
      parser.error("line longer than " + byte_limit_text(int64_t(kMaxTextLineBytes)));
      return;
    }
    std::string_view text(at, size_t(line_end - at));
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    if (!parser.line(text)) return;
    at = newline ? newline + 1 : end;
  }
}

}  // namespace

ObjNumber parse_obj_float(std::string_view word, float& value) {
  if (word.size() > 1 && word[0] == '+' && word[1] != '-') word.remove_prefix(1);
  double d = 0.0;
  if (!parse_simple_decimal(word, d)) {
    auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), d);
    if (ec == std::errc::result_out_of_range) return ObjNumber::kOutOfRange;
    if (ec != std::errc() || end != word.data() + word.size()) return ObjNumber::kNotNumber;
  }
  if (!(std::fabs(d) <= double(std::numeric_limits<float>::max()))) return ObjNumber::kOutOfRange;
  value = float(d);
  return ObjNumber::kOk;
}

void parse_obj_piece(ObjPiece& piece) {
  try {
    parse_lines(piece);
    if (!piece.colors.empty()) piece.colors.resize(piece.values[kObjPositions].size(), 1.0f);
    for (std::vector<float>& v : piece.values) v.shrink_to_fit();
    piece.corners.shrink_to_fit();
    piece.face_sizes.shrink_to_fit();
  } catch (const std::bad_alloc&) {
    piece.bad_alloc = true;
  }
  piece.text = {};
}

}  // namespace softrast::detail
