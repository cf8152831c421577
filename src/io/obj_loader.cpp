// io/obj_loader.cpp: Wavefront OBJ files into indexed meshes, with their MTL libraries.
//
// The OBJ text is parsed here, line by line as it is read, not by tinyobjloader: tinyobj reads
// indices with atoi, so 99999999999999999999 or 4294967299 became some other index silently, its
// number parser overflows an int on an exponent such as 1e2147483648, its skin-weight extension
// casts 1e39 to int, and holding its per-corner arrays beside the whole text took 1.83 GB for an
// 80 MB file. Only v, vt, vn, f, usemtl and mtllib matter for rendering; every other statement
// (o, g, s, l, p, vw, ...) is skipped without being parsed. MTL files still go to tinyobj's
// LoadMtl, after their numbers have been checked for the exponents it would overflow on.
//
// Also ours: the fan triangulation (tinyobj splits quads along the shorter diagonal) and knowing
// which materials had a Kd (tinyobj cannot tell a missing Kd from Kd 0 0 0).

#include "io/obj_loader.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <tiny_obj_loader.h>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "io/text_lines.hpp"
#include "softrast/image.hpp"
#include "softrast/mesh.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

Status fail_at(const std::string& path, size_t line, const std::string& reason) {
  return Status::error(path + ":" + std::to_string(line) + ": " + reason);
}

// The words of a line, split at spaces and tabs; a word starting with '#' ends the line.
class Words {
 public:
  explicit Words(std::string_view line) : rest_(line) {}

  // The next word, or an empty view at the end of the line.
  std::string_view next() {
    size_t start = rest_.find_first_not_of(kSpace);
    if (start == std::string_view::npos || rest_[start] == '#') {
      rest_ = {};
      return {};
    }
    rest_.remove_prefix(start);
    std::string_view word = rest_.substr(0, rest_.find_first_of(kSpace));
    rest_.remove_prefix(word.size());
    return word;
  }

 private:
  static constexpr const char* kSpace = " \t\r\v\f";
  std::string_view rest_;
};

enum class Number { kOk, kNotNumber, kOutOfRange };

// Parses a whole word as a finite float: "1", "-0.5", "+.5e3". Doubles first, so 1e39 is seen to
// be out of float range instead of being cast (undefined behaviour) or becoming infinity.
Number parse_float(std::string_view word, float& value) {
  if (word.size() > 1 && word[0] == '+' && word[1] != '-') word.remove_prefix(1);
  double d = 0.0;
  auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), d);
  if (ec == std::errc::result_out_of_range) return Number::kOutOfRange;
  if (ec != std::errc() || end != word.data() + word.size()) return Number::kNotNumber;
  if (!(std::fabs(d) <= double(std::numeric_limits<float>::max()))) return Number::kOutOfRange;
  value = float(d);
  return Number::kOk;
}

std::string quoted(std::string_view word) {
  std::string text(1, '\'');  // appended, not "'" + ...: GCC 12 warns falsely about the latter
  text.append(word);
  return text += '\'';
}

// An attribute array (positions, texture coordinates or normals) and what faces ask of it.
struct Attribute {
  const char* name;        // for messages: "position"
  const char* plural;      // "positions"
  const char* index_name;  // "face index"
  size_t components;
  std::vector<float> values;
  // Positive indices may name elements defined further down; the largest one past the elements
  // read so far is checked against the final count, and reported with its line.
  int64_t forward_max = 0;
  size_t forward_line = 0;

  size_t count() const { return values.size() / components; }
};

std::string range_text(const Attribute& a, size_t count) {
  if (count == 0) return "(there are no " + std::string(a.plural) + ")";
  std::string n = std::to_string(count);
  return "(1.." + n + " or -" + n + "..-1)";
}

// Builds the indexed mesh: one vertex per distinct (position, uv, normal) index triple. Vertices
// keep their indices until finish(), so faces may name elements defined after them.
class MeshBuilder {
 public:
  struct Key {
    int v, vt, vn;  // 0-based; -1 for an absent uv or normal
    bool operator==(const Key&) const = default;
  };

  // Fans around the first corner: (0, 1, 2), (0, 2, 3), ...
  void add_face(const std::vector<Key>& corners, int material) {
    if (mesh_.submeshes.empty() || mesh_.submeshes.back().material != material) {
      mesh_.submeshes.push_back({uint32_t(mesh_.indices.size()), 0, material});
    }
    uint32_t first = vertex(corners[0]);
    uint32_t previous = vertex(corners[1]);
    for (size_t k = 2; k < corners.size(); ++k) {
      uint32_t current = vertex(corners[k]);
      mesh_.indices.insert(mesh_.indices.end(), {first, previous, current});
      previous = current;
    }
    mesh_.submeshes.back().index_count += uint32_t(3 * (corners.size() - 2));
  }

  size_t index_count() const { return mesh_.indices.size(); }

  // Looks up each vertex's attributes; missing normals become smooth normals per OBJ position
  // index, so vertices that share a position but not a uv still get the same normal.
  Mesh finish(const Attribute& positions, const Attribute& uvs, const Attribute& normals);

 private:
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
      h ^= (uint64_t(uint32_t(k.vt)) + (h << 6) + (h >> 2)) * 0xC2B2AE3D27D4EB4Full;
      h ^= (uint64_t(uint32_t(k.vn)) + (h << 6) + (h >> 2)) * 0x165667B19E3779F9ull;
      return size_t(h ^ (h >> 29));
    }
  };

  uint32_t vertex(const Key& key) {
    auto [it, inserted] = vertices_.try_emplace(key, uint32_t(keys_.size()));
    if (inserted) keys_.push_back(key);
    return it->second;
  }

  Mesh mesh_;
  std::unordered_map<Key, uint32_t, KeyHash> vertices_;
  std::vector<Key> keys_;  // per vertex
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

Mesh MeshBuilder::finish(const Attribute& positions, const Attribute& uvs,
                         const Attribute& normals) {
  vertices_ = {};  // free the table before the arrays grow
  const float *p = positions.values.data(), *t = uvs.values.data(), *n = normals.values.data();
  mesh_.positions.reserve(keys_.size());
  mesh_.uvs.reserve(keys_.size());
  mesh_.normals.reserve(keys_.size());
  bool needs_smoothing = false;
  for (const Key& k : keys_) {
    size_t v = size_t(k.v), vt = size_t(k.vt), vn = size_t(k.vn);
    mesh_.positions.emplace_back(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    mesh_.uvs.push_back(k.vt >= 0 ? glm::vec2(t[2 * vt], t[2 * vt + 1]) : glm::vec2(0.0f));
    mesh_.normals.push_back(k.vn >= 0 ? glm::vec3(n[3 * vn], n[3 * vn + 1], n[3 * vn + 2])
                                      : glm::vec3(0.0f));
    needs_smoothing = needs_smoothing || k.vn < 0;
  }
  if (needs_smoothing) {
    std::vector<uint32_t> position_index(keys_.size());
    for (size_t v = 0; v < keys_.size(); ++v) position_index[v] = uint32_t(keys_[v].v);
    auto sums = group_normal_sums(mesh_, position_index, positions.count());
    for (size_t v = 0; v < keys_.size(); ++v) {
      if (keys_[v].vn < 0) mesh_.normals[v] = unit_or_z(sums[position_index[v]]);
    }
  }
  return std::move(mesh_);
}

// Whether tinyobj's number parser would overflow on `word`, or cast it to a float out of range
// (both undefined behaviour). It adds exponent digits to an int, checking only before
// multiplying, so more than 9 significant exponent digits are refused even at the start of a word
// (it parses prefixes); nine stay below 2^31 / 10, and a sane file never has more than three.
bool mtl_number_out_of_range(std::string_view word) {
  float ignored = 0.0f;
  if (parse_float(word, ignored) == Number::kOutOfRange && word.find_first_of("nN") == word.npos) {
    return true;  // inf and nan are words tinyobj does not parse as numbers
  }
  size_t e = word.find_first_of("eE");
  if (e == std::string_view::npos) return false;
  size_t start = word.find_first_not_of("+-0", e + 1);
  if (start == std::string_view::npos) return false;
  size_t digits = 0;
  while (start + digits < word.size() && word[start + digits] >= '0' &&
         word[start + digits] <= '9') {
    ++digits;
  }
  return digits > 9;
}

// For each material that tinyobj::LoadMtl will produce from `text`, in its order, whether the
// MTL gave it a Kd. Mirrors LoadMtl: one material per `newmtl` line (names are never empty
// after its trimming), or a single unnamed one if there is no `newmtl` at all.
std::vector<bool> scan_kd(const std::string& text) {
  std::vector<bool> has_kd;
  bool unnamed_kd = false;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line, '\n')) {
    const char* token = line.c_str() + std::strspn(line.c_str(), " \t");
    bool is_newmtl = std::strncmp(token, "newmtl", 6) == 0 && (token[6] == ' ' || token[6] == '\t');
    bool is_kd = token[0] == 'K' && token[1] == 'd' && (token[2] == ' ' || token[2] == '\t');
    if (is_newmtl) has_kd.push_back(false);
    if (is_kd && has_kd.empty()) unnamed_kd = true;
    if (is_kd && !has_kd.empty()) has_kd.back() = true;
  }
  if (has_kd.empty()) has_kd.push_back(unnamed_kd);
  return has_kd;
}

// The materials of every MTL library the OBJ names, relative to the OBJ's folder, each with its
// MTL's folder (texture paths are relative to it) and whether it had a Kd. A missing MTL is not an
// error: the OBJ then has no materials from it, as with other loaders.
class Materials {
 public:
  Materials(fs::path obj_dir, int64_t max_mtl_bytes)
      : obj_dir_(std::move(obj_dir)), max_bytes_(max_mtl_bytes) {}

  Status load_library(const std::string& name) {
    if (!loaded_.insert(name).second) return {};
    fs::path path = obj_dir_ / name;
    std::error_code ignored;
    if (!fs::exists(path, ignored)) return {};
    std::string text;
    Status read = detail::read_lines(
        path.string(), {max_bytes_, "MTL files"}, [&](std::string_view line, size_t number) {
          Words words(line);
          for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
            if (mtl_number_out_of_range(w)) {
              return fail_at(path.string(), number,
                             "number " + std::string(w) + " is out of range");
            }
          }
          text.append(line);
          text += '\n';
          return Status();
        });
    if (!read.ok()) return read;
    size_t first = all_.size();
    std::istringstream in(text);
    std::string warn;
    tinyobj::LoadMtl(&ids_, &all_, &in, &warn, nullptr);
    std::vector<bool> kd = scan_kd(text);
    // Should the scan ever disagree with tinyobj, trust tinyobj's Kd values.
    kd.resize(all_.size() - first, true);
    has_kd_.insert(has_kd_.end(), kd.begin(), kd.end());
    dirs_.resize(all_.size(), path.parent_path());
    return {};
  }

  // The material's index, or -1 (the default material) for a name no library defined.
  int id(const std::string& name) const {
    auto it = ids_.find(name);
    return it == ids_.end() ? -1 : it->second;
  }

  Result<std::vector<Material>> convert(const std::string& path) const;

 private:
  fs::path obj_dir_;
  int64_t max_bytes_;
  std::set<std::string> loaded_;
  std::map<std::string, int> ids_;
  std::vector<tinyobj::material_t> all_;
  std::vector<fs::path> dirs_;
  std::vector<bool> has_kd_;
};

// Returns the texture at `file`, loading it on first use so that materials share it.
using TextureCache = std::map<std::string, std::shared_ptr<const Texture>>;

Result<std::shared_ptr<const Texture>> texture_at(const fs::path& file, TextureCache& cache) {
  std::string key = file.lexically_normal().string();
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  Result<Image> image = load_image(key);
  if (!image.ok()) return image.status();
  auto texture = std::make_shared<const Texture>(Texture::from_image(*image));
  cache.emplace(key, texture);
  return std::shared_ptr<const Texture>(texture);
}

Result<std::vector<Material>> Materials::convert(const std::string& path) const {
  std::vector<Material> materials;
  TextureCache cache;
  for (size_t i = 0; i < all_.size(); ++i) {
    const tinyobj::material_t& source = all_[i];
    Material material;
    material.name = source.name;
    if (has_kd_[i]) {
      material.diffuse = {source.diffuse[0], source.diffuse[1], source.diffuse[2]};
      if (!std::isfinite(material.diffuse.x + material.diffuse.y + material.diffuse.z)) {
        return fail(path, "Kd of material '" + source.name + "' is not finite");
      }
    }
    if (!source.diffuse_texname.empty()) {
      auto texture = texture_at(dirs_[i] / source.diffuse_texname, cache);
      if (!texture.ok()) {
        return fail(path,
                    "map_Kd of material '" + source.name + "': " + texture.status().message());
      }
      material.diffuse_map = *texture;
    }
    materials.push_back(std::move(material));
  }
  return materials;
}

// Parses the OBJ statements that matter, one line at a time.
class ObjParser {
 public:
  ObjParser(const std::string& path, int64_t max_mtl_bytes)
      : path_(path), materials_(fs::path(path).parent_path(), max_mtl_bytes) {}

  Status line(std::string_view text, size_t number) {
    line_ = number;
    Words words(text);
    std::string_view keyword = words.next();
    if (keyword == "v") return numbers(words, positions_, 3, 3);
    if (keyword == "vt") return numbers(words, uvs_, 1, 2);
    if (keyword == "vn") return numbers(words, normals_, 3, 3);
    if (keyword == "f") return face(words);
    if (keyword == "usemtl") {
      material_ = materials_.id(std::string(words.next()));
      return {};
    }
    if (keyword == "mtllib") return libraries(words);
    return {};  // comments, groups, objects, smoothing, lines, points, and anything unknown
  }

  Result<Mesh> finish();

 private:
  Status error(const std::string& reason) const { return fail_at(path_, line_, reason); }

  // Appends `stored` components from at least `required` numbers; the rest (w, vertex colours)
  // must be numbers too and are dropped; missing optional ones are 0.
  Status numbers(Words& words, Attribute& a, size_t required, size_t stored) {
    size_t read = 0;
    for (std::string_view w = words.next(); !w.empty(); w = words.next(), ++read) {
      float value = 0.0f;
      Number n = parse_float(w, value);
      if (n == Number::kNotNumber) return error(quoted(w) + " is not a number");
      if (n == Number::kOutOfRange) {
        return error("number " + std::string(w) + " is not finite as a 32-bit float");
      }
      if (read < stored) a.values.push_back(value);
    }
    if (read < required) {
      return error(std::string(a.name) + " with fewer than " + std::to_string(required) +
                   (required == 1 ? " number" : " numbers"));
    }
    for (; read < stored; ++read) a.values.push_back(0.0f);
    return {};
  }

  // Resolves one index of a corner: 1-based, or negative counting back from the latest element.
  Status resolve(std::string_view word, Attribute& a, int& index) {
    int64_t value = 0;
    auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    bool overflow = ec == std::errc::result_out_of_range;
    if (!overflow && (ec != std::errc() || end != word.data() + word.size())) {
      return error("bad face corner: " + quoted(word) + " is not an index");
    }
    int64_t count = int64_t(a.count());
    if (!overflow && value < 0 && -value <= count) {
      index = int(count + value);
      return {};
    }
    if (!overflow && value > 0 && value <= std::numeric_limits<int>::max()) {
      if (value > count && value > a.forward_max) {
        a.forward_max = value;
        a.forward_line = line_;
      }
      index = int(value - 1);
      return {};
    }
    return error(std::string(a.index_name) + " " + std::string(word) + " is out of range " +
                 range_text(a, a.count()));
  }

  Status bad_corner(std::string_view word) const {
    return error("bad face corner " + quoted(word) + " (v, v/vt, v//vn or v/vt/vn)");
  }

  // "v", "v/vt", "v//vn" or "v/vt/vn".
  Status corner(std::string_view word, MeshBuilder::Key& key) {
    key = {0, -1, -1};
    size_t slash = word.find('/');
    std::string_view v = word.substr(0, slash);
    if (v.empty()) return bad_corner(word);
    if (Status s = resolve(v, positions_, key.v); !s.ok()) return s;
    if (slash == std::string_view::npos) return {};
    std::string_view rest = word.substr(slash + 1);
    slash = rest.find('/');
    std::string_view vt = rest.substr(0, slash);
    if (slash == std::string_view::npos) {
      return vt.empty() ? bad_corner(word) : resolve(vt, uvs_, key.vt);
    }
    std::string_view vn = rest.substr(slash + 1);
    if (vn.empty()) return bad_corner(word);
    if (!vt.empty()) {
      if (Status s = resolve(vt, uvs_, key.vt); !s.ok()) return s;
    }
    return resolve(vn, normals_, key.vn);
  }

  Status face(Words& words) {
    corners_.clear();
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      corners_.emplace_back();
      if (Status s = corner(w, corners_.back()); !s.ok()) return s;
    }
    if (corners_.size() < 3) return error("face with fewer than 3 vertices");
    // Fanning gives 3(n - 2) indices; first_index and index_count are 32-bit.
    if (builder_.index_count() + 3 * corners_.size() > UINT32_MAX) return error("too many faces");
    builder_.add_face(corners_, material_);
    return {};
  }

  Status libraries(Words& words) {
    for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
      if (Status s = materials_.load_library(std::string(w)); !s.ok()) return s;
    }
    return {};
  }

  Status check_forward(const Attribute& a) const {
    if (a.forward_max <= int64_t(a.count())) return {};
    return fail_at(path_, a.forward_line,
                   std::string(a.index_name) + " " + std::to_string(a.forward_max) +
                       " is out of range " + range_text(a, a.count()));
  }

  const std::string& path_;
  size_t line_ = 0;
  Attribute positions_{"position", "positions", "face index", 3, {}};
  Attribute uvs_{"texture coordinate", "texture coordinates", "texture coordinate index", 2, {}};
  Attribute normals_{"normal", "normals", "normal index", 3, {}};
  Materials materials_;
  int material_ = -1;
  std::vector<MeshBuilder::Key> corners_;
  MeshBuilder builder_;
};

Result<Mesh> ObjParser::finish() {
  if (builder_.index_count() == 0) return fail(path_, "no faces");
  for (const Attribute* a : {&positions_, &uvs_, &normals_}) {
    if (Status s = check_forward(*a); !s.ok()) return s;
  }
  Result<std::vector<Material>> materials = materials_.convert(path_);
  if (!materials.ok()) return materials.status();
  Mesh mesh = builder_.finish(positions_, uvs_, normals_);
  mesh.materials = std::move(*materials);
  return mesh;
}

}  // namespace

namespace detail {

Result<Mesh> load_obj(const std::string& path, int64_t max_obj_bytes, int64_t max_mtl_bytes) {
  ObjParser parser(path, max_mtl_bytes);
  Status read =
      read_lines(path, {max_obj_bytes, "OBJ files"},
                 [&](std::string_view line, size_t number) { return parser.line(line, number); });
  if (!read.ok()) return read;
  return parser.finish();
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
