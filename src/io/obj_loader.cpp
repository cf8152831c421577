// io/obj_loader.cpp: Wavefront OBJ files into indexed meshes, with their MTL libraries.
//
// The OBJ text is parsed here, not by tinyobjloader: tinyobj reads indices with atoi, so
// 99999999999999999999 or 4294967299 became some other index silently, its number parser
// overflows an int on an exponent such as 1e2147483648, and holding its per-corner arrays beside
// the whole text took 1.83 GB for an 80 MB file. MTL files still go to tinyobj's LoadMtl
// (io/mtl_materials.cpp). Also ours: the triangulation (geometry/polygon.hpp: the fan of a convex
// face, as SCENES.md's pipeline has it, where tinyobj splits quads along the shorter diagonal;
// ear clipping of a concave one).
//
// In parallel, in bounded memory: the file is read in pieces of about 1 MiB cut at line ends;
// worker threads parse pieces (io/obj_piece.cpp) while this thread reads on and merges finished
// pieces strictly in file order. What a piece cannot know alone is completed by the merge: the
// element counts before it (negative indices reaching back past its start, and the counts in
// messages), its first line number, and the materials named so far. Errors are therefore the same
// as a line-by-line reading gives, at the same line: the first in file order wins. At most
// kWindow pieces are in flight, so the text never sits in memory whole; the arrays grow in
// chunks, never by doubling; the per-piece index arrays are joined once at the end.
//
// Memory, for the benchmark's 109 MB spheres_1m.obj (551,232 vertices, 995,328 triangles; the
// final mesh is 29.6 MB): the raw elements (17.6 MB), the vertex table (8.8 MB: key, chain link
// and head per vertex) and the indices (11.9 MB) at the end of reading, plus the pieces in flight.

#include "io/obj_loader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <malloc.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "geometry/polygon.hpp"
#include "io/mtl_materials.hpp"
#include "io/obj_piece.hpp"
#include "io/text_lines.hpp"
#include "softrast/mesh.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using detail::kObjAbsent;
using detail::kObjComponents;
using detail::ObjCorner;
using detail::ObjPiece;

// Bytes read per piece (plus the end of a line carried over from the previous read). Large
// enough that the per-piece overhead vanishes, small enough that pieces in flight stay cheap.
constexpr size_t kPieceBytes = size_t(1) << 20;

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

Status fail_at(const std::string& path, size_t line, const std::string& reason) {
  return Status::error(path + ":" + std::to_string(line) + ": " + reason);
}

const char* const kPlural[3] = {"positions", "texture coordinates", "normals"};
const char* const kIndexName[3] = {"face index", "texture coordinate index", "normal index"};

std::string range_text(int attr, size_t count) {
  if (count == 0) return "(there are no " + std::string(kPlural[attr]) + ")";
  std::string n = std::to_string(count);
  return "(1.." + n + " or -" + n + "..-1)";
}

std::string out_of_range(int attr, const std::string& word, size_t count) {
  return std::string(kIndexName[attr]) + " " + word + " is out of range " + range_text(attr, count);
}

// One element array (positions, uvs or normals) in chunks of 2^16 elements: appending never
// copies what is there, and there is no doubling slack.
class ChunkedValues {
 public:
  explicit ChunkedValues(size_t components) : components_(components) {}

  void append(const std::vector<float>& values) {
    size_t elements = values.size() / components_;
    for (size_t done = 0; done < elements;) {
      if ((count_ & kMask) == 0) {
        chunks_.emplace_back();
        chunks_.back().reserve(kChunk * components_);
      }
      size_t n = std::min(elements - done, kChunk - (count_ & kMask));
      const float* from = values.data() + done * components_;
      chunks_.back().insert(chunks_.back().end(), from, from + n * components_);
      done += n;
      count_ += n;
    }
  }
  size_t count() const { return count_; }
  const float* at(size_t i) const {
    return chunks_[i >> kShift].data() + (i & kMask) * components_;
  }
  void release() { chunks_ = {}; }

 private:
  static constexpr size_t kShift = 16;
  static constexpr size_t kChunk = size_t(1) << kShift;
  static constexpr size_t kMask = kChunk - 1;
  size_t components_;
  size_t count_ = 0;
  std::vector<std::vector<float>> chunks_;
};

// One vertex per distinct (position, uv, normal) index triple, numbered in order of first use.
// A table indexed by position heads a chain of the vertices sharing that position (short: one per
// uv seam or crease), which is several times faster than a hash map over triples. Keys whose
// position has not been read yet (OBJ allows faces before their vertices) go to a hash map; it
// is searched first while it is not empty, so a key always finds the vertex made for it.
class VertexTable {
 public:
  struct Key {
    int32_t v, vt, vn;  // 0-based; -1 for an absent uv or normal
    bool operator==(const Key&) const = default;
  };

  void grow_positions(size_t count) { head_.resize(count, kNone); }

  uint32_t vertex(const Key& key) {
    if (!forward_.empty()) {
      if (auto it = forward_.find(key); it != forward_.end()) return it->second;
    }
    auto id = uint32_t(keys_.size());
    if (size_t(key.v) < head_.size()) {
      for (uint32_t at = head_[size_t(key.v)]; at != kNone; at = next_[at]) {
        if (keys_[at].vt == key.vt && keys_[at].vn == key.vn) return at;
      }
      next_.push_back(head_[size_t(key.v)]);
      head_[size_t(key.v)] = id;
    } else {
      next_.push_back(kNone);
      forward_.emplace(key, id);
    }
    keys_.push_back(key);
    return id;
  }

  const std::vector<Key>& keys() const { return keys_; }
  void release_keys() { keys_ = {}; }
  void release_lookup() {
    head_ = {};
    next_ = {};
    forward_ = {};
  }

 private:
  static constexpr uint32_t kNone = UINT32_MAX;
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
      h ^= (uint64_t(uint32_t(k.vt)) + (h << 6) + (h >> 2)) * 0xC2B2AE3D27D4EB4Full;
      h ^= (uint64_t(uint32_t(k.vn)) + (h << 6) + (h >> 2)) * 0x165667B19E3779F9ull;
      return size_t(h ^ (h >> 29));
    }
  };
  std::vector<uint32_t> head_;  // per position
  std::vector<uint32_t> next_;  // per vertex
  std::vector<Key> keys_;       // per vertex
  std::unordered_map<Key, uint32_t, KeyHash> forward_;
};

// Sums of area-weighted face normals per group of vertices. The cross product of two edges is
// the unit normal times twice the area, so plain sums weight faces by area. Doubles keep the
// products of large float coordinates from overflowing.
std::vector<glm::dvec3> group_normal_sums(const Mesh& mesh, const std::vector<uint32_t>& group,
                                          size_t groups) {
  std::vector<glm::dvec3> sums(groups, glm::dvec3(0.0));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t* v = &mesh.indices[t];
    glm::dvec3 p0(mesh.positions[v[0]]), p1(mesh.positions[v[1]]), p2(mesh.positions[v[2]]);
    glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    for (int k = 0; k < 3; ++k) sums[group[v[k]]] += n;
  }
  return sums;
}

glm::vec3 unit_or_z(const glm::dvec3& n) {
  double length = glm::length(n);
  if (!(length > 0.0 && std::isfinite(length))) return {0.0f, 0.0f, 1.0f};
  return glm::vec3(n / length);
}

// Pieces are allocated by the worker threads (in their malloc arenas) and freed here, and the raw
// arrays are freed before the final ones grow: glibc keeps such memory mapped, counted in the
// resident size, until told to give back its free pages (malloc_trim returns whole free pages
// from every arena, not only from the top of the heap). Every few pieces and once before the
// indices are joined; each call takes well under a millisecond.
constexpr size_t kTrimEvery = 8;

void return_free_memory() {
  malloc_trim(0);
}

// Merges parsed pieces in file order into the mesh, then finishes it.
class ObjMerge {
 public:
  ObjMerge(const std::string& path, int64_t max_mtl_bytes)
      : path_(path), materials_(fs::path(path).parent_path(), max_mtl_bytes) {}

  // Lines merged so far (for errors found by the reader after them).
  size_t lines() const { return lines_; }

  Status merge(ObjPiece& piece);
  Result<Mesh> finish();

 private:
  Status piece_error(const ObjPiece& piece) const;
  Status first_fixup_error(ObjPiece& piece, const size_t offset[3], size_t& line) const;
  // mtllib's words are the libraries' names; a name with spaces (Blender writes
  // "mtllib my model.mtl") is the whole line, when a file of that name is there.
  Status load_libraries(const detail::ObjEvent& event) {
    if (event.names.size() > 1) {
      std::string whole = event.names[0];
      for (size_t k = 1; k < event.names.size(); ++k) whole += " " + event.names[k];
      if (materials_.library_exists(whole)) {
        return materials_.load_library(whole, path_, lines_ + event.line);
      }
    }
    for (const std::string& name : event.names) {
      if (Status s = materials_.load_library(name, path_, lines_ + event.line); !s.ok()) return s;
    }
    return {};
  }
  void add_faces(const ObjPiece& piece, const size_t offset[3], size_t end_face,
                 std::vector<uint32_t>& indices);
  template <class KeyOf>
  void add_polygon(const ObjCorner* c, size_t n, const KeyOf& key_of,
                   std::vector<uint32_t>& indices);
  void continue_run(std::vector<SubMesh>& runs, size_t first) const;
  template <class KeyOf>
  void add_line_or_points(const ObjCorner* c, size_t n, bool points, const KeyOf& key_of);
  Mesh build_mesh();

  const std::string& path_;
  detail::ObjMaterials materials_;
  size_t lines_ = 0;
  ChunkedValues values_[3] = {ChunkedValues(3), ChunkedValues(2), ChunkedValues(3)};
  std::vector<float> colors_;  // 3 per position when any has a colour (ObjPiece::colors)
  detail::ObjLargest largest_[3];
  VertexTable table_;
  std::vector<std::vector<uint32_t>> index_pieces_;
  size_t index_count_ = 0;
  std::vector<SubMesh> submeshes_;
  int material_ = -1;
  size_t face_ = 0, corner_ = 0, other_ = 0;  // cursor in the piece being merged
  // The l and p elements, as Mesh::line_indices and point_indices with their runs.
  std::vector<uint32_t> line_indices_, point_indices_;
  std::vector<SubMesh> line_submeshes_, point_submeshes_;
  // add_polygon's scratch: a face's vertices, positions and triangles (as corner numbers).
  std::vector<uint32_t> polygon_vertices_, polygon_triangles_;
  std::vector<glm::vec3> polygon_points_;
  uint64_t ear_tests_ = detail::kFileEarTests;  // the file's allowance (geometry/polygon.hpp)
  size_t pieces_ = 0;
};

Status ObjMerge::piece_error(const ObjPiece& piece) const {
  const detail::ObjPieceError& e = *piece.error;
  if (e.range_attr < 0) return fail_at(path_, lines_ + e.line, e.message);
  size_t count = values_[e.range_attr].count() + e.local_count;
  return fail_at(path_, lines_ + e.line, out_of_range(e.range_attr, e.word, count));
}

// Resolves the negative indices that reach back before the piece; the first out of range is an
// error at its line (`line`, else SIZE_MAX).
Status ObjMerge::first_fixup_error(ObjPiece& piece, const size_t offset[3], size_t& line) const {
  line = SIZE_MAX;
  for (const detail::ObjFixup& f : piece.fixups) {
    int64_t global = int64_t(offset[f.attr]) + f.back;
    if (global < 0) {
      line = f.line;
      return fail_at(path_, lines_ + f.line,
                     out_of_range(f.attr, f.word, offset[f.attr] + f.local_count));
    }
    piece.corners[f.corner].index[f.attr] = int32_t(global);
  }
  return {};
}

// Starts a run of the current material at index `first` of its kind unless the last one has it.
void ObjMerge::continue_run(std::vector<SubMesh>& runs, size_t first) const {
  if (runs.empty() || runs.back().material != material_) {
    runs.push_back({uint32_t(first), 0, material_});
  }
}

// A face of n > 3 corners: its vertices in corner order (so numbered as they are met), its
// triangles from triangulate_polygon (the fan of a convex face; a concave one clipped into ears).
// A face naming a position not read yet (OBJ allows it) is fanned.
template <class KeyOf>
void ObjMerge::add_polygon(const ObjCorner* c, size_t n, const KeyOf& key_of,
                           std::vector<uint32_t>& indices) {
  polygon_vertices_.clear();
  polygon_points_.clear();
  bool positioned = true;
  for (size_t k = 0; k < n; ++k) {
    VertexTable::Key key = key_of(c[k]);
    polygon_vertices_.push_back(table_.vertex(key));
    positioned = positioned && size_t(key.v) < values_[0].count();
    if (positioned) {
      const float* p = values_[0].at(size_t(key.v));
      polygon_points_.emplace_back(p[0], p[1], p[2]);
    }
  }
  polygon_triangles_.clear();
  if (positioned) {
    detail::triangulate_polygon(polygon_points_.data(), n, polygon_triangles_, &ear_tests_);
  } else {
    detail::append_fan(n, polygon_triangles_);
  }
  for (uint32_t corner : polygon_triangles_) indices.push_back(polygon_vertices_[corner]);
}

// An l element's segments (each corner to the next) or a p element's points, in runs of the
// current material as the faces' submeshes are.
template <class KeyOf>
void ObjMerge::add_line_or_points(const ObjCorner* c, size_t n, bool points, const KeyOf& key_of) {
  std::vector<uint32_t>& out = points ? point_indices_ : line_indices_;
  std::vector<SubMesh>& runs = points ? point_submeshes_ : line_submeshes_;
  continue_run(runs, out.size());
  uint32_t previous = table_.vertex(key_of(c[0]));
  if (points) out.push_back(previous);
  for (size_t k = 1; k < n; ++k) {
    uint32_t current = table_.vertex(key_of(c[k]));
    if (points) {
      out.push_back(current);
    } else {
      out.insert(out.end(), {previous, current});
    }
    previous = current;
  }
  runs.back().index_count = uint32_t(out.size() - runs.back().first_index);
}

// Adds faces [face_, end_face) of the piece: a triangle as it is, a polygon by add_polygon, and
// the l and p elements among them by add_line_or_points.
void ObjMerge::add_faces(const ObjPiece& piece, const size_t offset[3], size_t end_face,
                         std::vector<uint32_t>& indices) {
  auto key_of = [&](const ObjCorner& c) {
    int32_t k[3];
    for (int a = 0; a < 3; ++a) {
      int32_t i = c.index[a];
      k[a] = i == kObjAbsent ? -1 : i >= 0 ? i : int32_t(offset[a]) + (-1 - i);
    }
    return VertexTable::Key{k[0], k[1], k[2]};
  };
  for (; face_ < end_face; ++face_) {
    size_t n = piece.face_sizes[face_];
    if (other_ < piece.others.size() && piece.others[other_].face == face_) {
      add_line_or_points(&piece.corners[corner_], n, piece.others[other_++].points, key_of);
      corner_ += n;
      continue;
    }
    continue_run(submeshes_, index_count_ + indices.size());
    const ObjCorner* c = &piece.corners[corner_];
    if (n == 3) {
      indices.insert(indices.end(), {table_.vertex(key_of(c[0])), table_.vertex(key_of(c[1])),
                                     table_.vertex(key_of(c[2]))});
    } else {
      add_polygon(c, n, key_of, indices);
    }
    submeshes_.back().index_count += uint32_t(3 * (n - 2));
    corner_ += n;
  }
}

Status ObjMerge::merge(ObjPiece& piece) {
  if (piece.bad_alloc) throw std::bad_alloc();
  size_t offset[3] = {values_[0].count(), values_[1].count(), values_[2].count()};
  size_t fixup_line = SIZE_MAX;
  Status fixup = first_fixup_error(piece, offset, fixup_line);
  if (!fixup.ok() || piece.error) {
    // Libraries named before the first error are still read: their errors come first.
    size_t stop = std::min(fixup_line, piece.error ? piece.error->line : SIZE_MAX);
    for (const detail::ObjEvent& event : piece.events) {
      if (event.line >= stop) break;
      if (event.mtllib) {
        if (Status s = load_libraries(event); !s.ok()) return s;
      }
    }
    return fixup.ok() ? piece_error(piece) : fixup;
  }
  // Fanning gives 3(n - 2) indices; first_index and index_count are 32-bit. (A file within
  // kMaxObjFileBytes cannot get there: each corner costs at least 2 bytes for 3 indices.)
  if (index_count_ + 3 * piece.triangles > UINT32_MAX) {
    return fail_at(path_, lines_ + piece.lines, "too many faces");
  }
  for (int a = 0; a < 3; ++a) {
    if (a == 0 && !piece.colors.empty()) {  // colours line up with the positions
      colors_.resize(3 * values_[0].count(), 1.0f);
      colors_.insert(colors_.end(), piece.colors.begin(), piece.colors.end());
      piece.colors = {};
    }
    values_[a].append(piece.values[a]);
    piece.values[a] = {};
    if (piece.largest[a].value > largest_[a].value) {
      largest_[a] = {piece.largest[a].value, lines_ + piece.largest[a].line};
    }
  }
  table_.grow_positions(values_[0].count());
  std::vector<uint32_t> indices;
  indices.reserve(3 * piece.triangles);
  face_ = corner_ = other_ = 0;
  for (const detail::ObjEvent& event : piece.events) {
    add_faces(piece, offset, event.face, indices);
    if (!event.mtllib) {
      material_ = materials_.use(event.names[0], path_, lines_ + event.line);
    } else if (Status s = load_libraries(event); !s.ok()) {
      return s;
    }
  }
  add_faces(piece, offset, piece.face_sizes.size(), indices);
  index_count_ += indices.size();
  if (!indices.empty()) index_pieces_.push_back(std::move(indices));
  lines_ += piece.lines;
  if (++pieces_ % kTrimEvery == 0) return_free_memory();
  return {};
}

// The final arrays, built one at a time while the raw ones are released: the vertex arrays
// first (each raw array freed once its final one is built), then the lookup table and keys, and
// only then are the per-piece indices joined, so that at most one array exists twice.
Mesh ObjMerge::build_mesh() {
  Mesh mesh;
  mesh.submeshes = std::move(submeshes_);
  mesh.line_indices = std::move(line_indices_);
  mesh.line_submeshes = std::move(line_submeshes_);
  mesh.point_indices = std::move(point_indices_);
  mesh.point_submeshes = std::move(point_submeshes_);
  table_.release_lookup();
  const std::vector<VertexTable::Key>& keys = table_.keys();
  mesh.positions.resize(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    const float* p = values_[0].at(size_t(keys[i].v));
    mesh.positions[i] = {p[0], p[1], p[2]};
  }
  size_t position_count = values_[0].count();
  values_[0].release();
  if (!colors_.empty()) {  // white for the positions after the last coloured one
    colors_.resize(3 * position_count, 1.0f);
    mesh.colors.resize(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) {
      const float* c = &colors_[3 * size_t(keys[i].v)];
      mesh.colors[i] = {c[0], c[1], c[2], 1.0f};
    }
    colors_ = {};
  }
  return_free_memory();
  mesh.uvs.resize(keys.size(), glm::vec2(0.0f));
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i].vt < 0) continue;
    const float* t = values_[1].at(size_t(keys[i].vt));
    mesh.uvs[i] = {t[0], t[1]};
  }
  values_[1].release();
  return_free_memory();
  mesh.normals.resize(keys.size(), glm::vec3(0.0f));
  bool needs_smoothing = false;
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i].vn < 0) {
      needs_smoothing = true;
      continue;
    }
    const float* n = values_[2].at(size_t(keys[i].vn));
    mesh.normals[i] = {n[0], n[1], n[2]};
  }
  values_[2].release();
  std::vector<uint32_t> position_index;
  if (needs_smoothing) {
    position_index.resize(keys.size());
    for (size_t v = 0; v < keys.size(); ++v) position_index[v] = uint32_t(keys[v].v);
  }
  std::vector<bool> smooth;
  if (needs_smoothing) {
    smooth.resize(keys.size());
    for (size_t v = 0; v < keys.size(); ++v) smooth[v] = keys[v].vn < 0;
  }
  table_.release_keys();
  return_free_memory();
  mesh.indices.reserve(index_count_);
  for (std::vector<uint32_t>& piece : index_pieces_) {
    mesh.indices.insert(mesh.indices.end(), piece.begin(), piece.end());
    piece = {};
  }
  index_pieces_ = {};
  // Missing normals become smooth normals per OBJ position index, so vertices that share a
  // position but not a uv still get the same normal.
  if (needs_smoothing) {
    auto sums = group_normal_sums(mesh, position_index, position_count);
    for (size_t v = 0; v < smooth.size(); ++v) {
      if (smooth[v]) mesh.normals[v] = unit_or_z(sums[position_index[v]]);
    }
  }
  return mesh;
}

Result<Mesh> ObjMerge::finish() {
  if (index_count_ == 0 && line_indices_.empty() && point_indices_.empty()) {
    size_t vertices = values_[0].count();
    if (vertices == 0) return fail(path_, "no faces");
    // Vertices alone: say so, rather than only what is missing.
    return fail(path_, "no faces: " + std::to_string(vertices) +
                           (vertices == 1 ? " vertex" : " vertices") +
                           " but no face (f), line (l) or points (p) to draw");
  }
  // Positive indices may name elements defined further down: checked against the final counts.
  for (int a = 0; a < 3; ++a) {
    if (largest_[a].value > int64_t(values_[a].count())) {
      return fail_at(path_, largest_[a].line,
                     out_of_range(a, std::to_string(largest_[a].value), values_[a].count()));
    }
  }
  std::vector<std::string> warnings = materials_.take_warnings();
  Result<std::vector<Material>> materials = materials_.convert(path_, warnings);
  if (!materials.ok()) return materials.status();
  Mesh mesh = build_mesh();
  mesh.materials = std::move(*materials);
  if (mesh.materials.empty()) {
    // No MTL materials: the tutorial models' maps beside the file, drawn on every face.
    if (std::optional<Material> m = detail::tutorial_material(path_, warnings)) {
      mesh.materials.push_back(std::move(*m));
      for (SubMesh& run : mesh.submeshes) run.material = 0;
      for (SubMesh& run : mesh.line_submeshes) run.material = 0;
      for (SubMesh& run : mesh.point_submeshes) run.material = 0;
    }
  }
  mesh.warnings = std::move(warnings);
  bool tangent_maps = std::any_of(mesh.materials.begin(), mesh.materials.end(), [](const auto& m) {
    return m.normal_map && m.normal_space == NormalSpace::kTangent;
  });
  if (tangent_maps) compute_tangents(mesh);
  return mesh;
}

// Reads the file in pieces of whole lines. Errors of its own (the byte limit of a pipe, a read
// error, a NUL byte or an over-long line while looking for a line's end) are kept until every
// piece before them is merged, which may fail first, as a line-by-line reading would.
class PieceReader {
 public:
  PieceReader(std::FILE* f, const std::string& path, detail::TextLimit limit)
      : f_(f), path_(path), limit_(limit) {}

  // The next piece into `text`; false at the end of the file or on an error (error_at then says
  // what, given the lines merged).
  bool next(std::vector<char>& text);
  bool at_end() const { return eof_ && carry_.empty(); }
  bool failed() const { return failed_; }
  Status error_at(size_t lines_before) const {
    if (!line_error_) return Status::error(error_);
    return fail_at(path_, lines_before + 1, error_);
  }

 private:
  bool stop(std::string reason, bool at_line) {
    failed_ = true;
    line_error_ = at_line;
    error_ = std::move(reason);
    return false;
  }

  std::FILE* f_;
  const std::string& path_;
  detail::TextLimit limit_;
  std::vector<char> carry_;  // the start of a line whose end is not read yet
  int64_t total_ = 0;
  bool eof_ = false;
  bool failed_ = false;
  bool line_error_ = false;
  std::string error_;
};

bool PieceReader::next(std::vector<char>& text) {
  while (!eof_) {
    size_t old = carry_.size();
    carry_.resize(old + kPieceBytes);
    size_t n = std::fread(carry_.data() + old, 1, kPieceBytes, f_);
    carry_.resize(old + n);
    total_ += int64_t(n);
    // Checked per read, so a pipe or device costs at most one piece past the limit.
    if (total_ > limit_.max_bytes) {
      return stop(detail::text_too_large(path_, limit_).message(), false);
    }
    if (n < kPieceBytes) {
      if (std::ferror(f_)) {
        return stop(path_ + ": cannot read: " + std::strerror(errno), false);
      }
      eof_ = true;
    }
    const char* fresh = carry_.data() + old;
    const void* newline = n > 0 ? memrchr(fresh, '\n', n) : nullptr;
    if (newline) {
      size_t cut = size_t(static_cast<const char*>(newline) - carry_.data()) + 1;
      text = std::move(carry_);
      carry_.assign(text.begin() + std::ptrdiff_t(cut), text.end());
      text.resize(cut);
      return true;
    }
    if (eof_) break;
    // No line ends in what was just read: the line goes on, unless it cannot be one.
    if (std::memchr(fresh, '\0', n)) return stop("NUL byte: not a text file", true);
    if (carry_.size() > detail::kMaxTextLineBytes) {
      return stop("line longer than " + detail::byte_limit_text(int64_t(detail::kMaxTextLineBytes)),
                  true);
    }
  }
  if (carry_.empty()) return false;
  text = std::move(carry_);  // the last line, without its "\n"
  carry_ = {};
  return true;
}

// Worker threads that parse the pieces they are given, in any order.
class PieceWorkers {
 public:
  explicit PieceWorkers(int count) {
    try {
      for (int i = 0; i < count; ++i) threads_.emplace_back([this] { work(); });
    } catch (...) {  // no thread to be had: stop those that started, then report
      stop();
      throw;
    }
  }
  ~PieceWorkers() { stop(); }
  PieceWorkers(const PieceWorkers&) = delete;
  PieceWorkers& operator=(const PieceWorkers&) = delete;

  void submit(ObjPiece* piece) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(piece);
    }
    work_ready_.notify_one();
  }

  void wait_parsed(const ObjPiece* piece) {
    std::unique_lock<std::mutex> lock(mutex_);
    piece_done_.wait(lock, [&] { return piece->parsed; });
  }

 private:
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      queue_.clear();
    }
    work_ready_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
  }

  void work() {
    for (;;) {
      ObjPiece* piece = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        work_ready_.wait(lock, [&] { return stop_ || !queue_.empty(); });
        if (stop_) return;
        piece = queue_.front();
        queue_.pop_front();
      }
      detail::parse_obj_piece(*piece);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        piece->parsed = true;
      }
      piece_done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable work_ready_, piece_done_;
  std::deque<ObjPiece*> queue_;
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

int parse_threads() {
  unsigned n = std::thread::hardware_concurrency();
  return int(std::clamp(n, 1u, 16u));
}

// Pieces read, parsed by the workers and merged in order, at most kWindow at a time.
Status parse_in_parallel(PieceReader& reader, std::vector<char> first, ObjMerge& merge) {
  int threads = parse_threads();
  const size_t window_limit = size_t(threads) + 1;
  std::deque<std::unique_ptr<ObjPiece>> window;  // declared first: outlives the workers
  PieceWorkers workers(threads);
  auto submit = [&](std::vector<char>&& text) {
    window.push_back(std::make_unique<ObjPiece>());
    window.back()->text = std::move(text);
    workers.submit(window.back().get());
  };
  submit(std::move(first));
  for (;;) {
    while (window.size() < window_limit) {
      std::vector<char> text;
      if (!reader.next(text)) break;
      submit(std::move(text));
    }
    if (window.empty()) return {};
    workers.wait_parsed(window.front().get());
    Status s = merge.merge(*window.front());
    window.pop_front();
    if (!s.ok()) return s;
  }
}

}  // namespace

namespace detail {

Result<Mesh> load_obj(const std::string& path, int64_t max_obj_bytes, int64_t max_mtl_bytes) {
  TextLimit limit{max_obj_bytes, "OBJ files"};
  FilePtr file;
  if (Status s = open_text_file(path, limit, file); !s.ok()) return s;
  PieceReader reader(file.get(), path, limit);
  ObjMerge merge(path, max_mtl_bytes);
  std::vector<char> first;
  if (reader.next(first)) {
    if (reader.at_end()) {  // one piece: no threads
      ObjPiece piece;
      piece.text = std::move(first);
      parse_obj_piece(piece);
      if (Status s = merge.merge(piece); !s.ok()) return s;
    } else if (Status s = parse_in_parallel(reader, std::move(first), merge); !s.ok()) {
      return s;
    }
  }
  if (reader.failed()) return reader.error_at(merge.lines());
  return merge.finish();
}

}  // namespace detail

Result<Mesh> load_obj(const std::string& path) {
  return detail::load_obj(path, kMaxObjFileBytes, kMaxMtlFileBytes);
}

void compute_smooth_normals(Mesh& mesh) {
  // Group vertices by exact position (std::hash<float> hashes -0 and +0 alike, as == requires).
  struct Hash {
    size_t operator()(const glm::vec3& p) const {
      size_t h = std::hash<float>()(p.x);
      h = h * 31 + std::hash<float>()(p.y);
      return h * 31 + std::hash<float>()(p.z);
    }
  };
  std::unordered_map<glm::vec3, uint32_t, Hash> group_of;
  std::vector<uint32_t> group(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    group[v] = group_of.try_emplace(mesh.positions[v], uint32_t(group_of.size())).first->second;
  }
  std::vector<glm::dvec3> sums = group_normal_sums(mesh, group, group_of.size());
  mesh.normals.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.normals[v] = unit_or_z(sums[group[v]]);
}

}  // namespace softrast
