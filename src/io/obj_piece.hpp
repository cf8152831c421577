// io/obj_piece.hpp: one piece of an OBJ file (whole lines), parsed without knowing what came
// before it, so that pieces can be parsed in parallel and merged in file order (obj_loader.cpp).
// Everything that depends on earlier pieces (element counts for negative indices and messages,
// line numbers, materials) is recorded in a form the merge completes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace softrast::detail {

// The three element arrays a face corner indexes.
enum ObjAttr : int { kObjPositions = 0, kObjUvs = 1, kObjNormals = 2 };
inline constexpr size_t kObjComponents[3] = {3, 2, 3};  // floats stored per element

// A corner's index into one array: >= 0 is a 0-based index in the whole file; kObjAbsent means
// no uv or normal; any other negative value -(1 + i) is element i of this piece's own elements.
inline constexpr int32_t kObjAbsent = std::numeric_limits<int32_t>::min();
inline int32_t obj_local(size_t i) {
  return -1 - int32_t(i);
}

struct ObjCorner {
  int32_t index[3];  // by ObjAttr
};

// A negative index that reaches back before the piece: global index = offset + back, where offset
// is the element count before the piece; it is out of range if that is negative.
struct ObjFixup {
  size_t corner;       // into ObjPiece::corners
  int attr;            // ObjAttr
  int64_t back;        // local count at the time + the (negative) index
  size_t local_count;  // elements of the piece at the time, for the message
  size_t line;         // 1-based within the piece
  std::string word;    // the index as written
};

// usemtl and mtllib, in order, with the number of faces of the piece before them.
struct ObjEvent {
  bool mtllib;                     // else usemtl
  size_t face;                     // faces of the piece before the statement
  size_t line;                     // 1-based within the piece
  std::vector<std::string> names;  // usemtl: one name (maybe empty); mtllib: every word
};

// The first error of a piece. An index out of range names the element count at its line, known
// only at the merge: then range_attr >= 0 and `word` and `local_count` complete the message.
struct ObjPieceError {
  size_t line = 0;  // 1-based within the piece
  std::string message;
  int range_attr = -1;
  std::string word;
  size_t local_count = 0;
};

// The largest positive index of each array and the first line it appears on: if it exceeds the
// final element count, that line is reported.
struct ObjLargest {
  int64_t value = 0;
  size_t line = 0;
};

// A line (l) or points (p) element among a piece's faces: its corners are in ObjPiece::corners
// and its size in face_sizes, in file order with the faces; this says which it is.
struct ObjOther {
  size_t face;  // into face_sizes
  bool points;  // else a polyline
};

struct ObjPiece {
  std::vector<char> text;  // whole lines; freed once parsed
  bool bad_alloc = false;  // parsing ran out of memory: the merge rethrows
  bool parsed = false;     // set by the parsing thread under the workers' lock
  size_t lines = 0;        // lines parsed (up to and including an error's line)
  std::vector<float> values[3];
  // Vertex colours ("v x y z r g b"), 3 floats per position of the piece from its first, white
  // for positions without; empty when no position of the piece has one.
  std::vector<float> colors;
  std::vector<ObjCorner> corners;    // every face's corners in order
  std::vector<uint32_t> face_sizes;  // corners per face (per line or points element too)
  size_t triangles = 0;              // sum of face_sizes[i] - 2 over the faces
  std::vector<ObjOther> others;      // the l and p elements among them, in order
  std::vector<ObjFixup> fixups;      // in line order
  std::vector<ObjEvent> events;      // in line order
  ObjLargest largest[3];
  std::optional<ObjPieceError> error;
};

// Parses piece.text (lines separated by '\n', a trailing '\r' dropped; the last line may lack its
// '\n'), then frees it. Stops at the first error: a NUL byte, a line over kMaxTextLineBytes, or an
// OBJ error of the line (the same messages as the sequential loader had).
void parse_obj_piece(ObjPiece& piece);

// Parses a whole word as a finite float (through double, so 1e39 is out of float range).
enum class ObjNumber { kOk, kNotNumber, kOutOfRange };
ObjNumber parse_obj_float(std::string_view word, float& value);

// The words of a line, split at spaces, tabs, \r, \v and \f; a word starting with '#' ends the
// line.
class ObjWords {
 public:
  explicit ObjWords(std::string_view line) : at_(line.data()), end_(line.data() + line.size()) {}

  // The next word, or an empty view at the end of the line.
  std::string_view next() {
    while (at_ < end_ && is_space(*at_)) ++at_;
    if (at_ == end_ || *at_ == '#') {
      at_ = end_;
      return {};
    }
    const char* start = at_;
    while (at_ < end_ && !is_space(*at_)) ++at_;
    return {start, size_t(at_ - start)};
  }

  // The words left, one space apart (a name that may hold spaces: usemtl's, newmtl's).
  std::string joined() {
    std::string out(next());
    for (std::string_view w = next(); !w.empty(); w = next()) out.append(" ").append(w);
    return out;
  }

 private:
  static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  }
  const char* at_;
  const char* end_;
};

}  // namespace softrast::detail
