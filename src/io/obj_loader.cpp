// io/obj_loader.cpp: Wavefront OBJ/MTL files into indexed meshes, parsed by tinyobjloader.
// tinyobj only tokenizes; the checks, the fan triangulation and the vertex de-duplication are ours.
//
// Deliberately not used from tinyobj: its triangulation (quads are split along the shorter
// diagonal rather than fanned, and faces with bad indices are silently dropped) and its MTL file
// lookup (it cannot tell a material without Kd from Kd 0 0 0, nor which MTL a material came from).

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <tiny_obj_loader.h>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "softrast/image.hpp"
#include "softrast/mesh.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

// Reads a whole text file; false, with the reason, if it cannot be opened or read.
bool read_text(const fs::path& path, std::string& text, std::string& reason) {
  std::error_code ignored;
  if (fs::is_directory(path, ignored)) {
    reason = "is a directory";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    reason = std::string("cannot open: ") + std::strerror(errno);
    return false;
  }
  std::ostringstream buffer;
  if (in.peek() != std::ifstream::traits_type::eof()) buffer << in.rdbuf();
  if (in.bad() || buffer.fail()) {
    reason = "cannot read file";
    return false;
  }
  text = buffer.str();
  return true;
}

// tinyobj's messages end every line with '\n'; ours are one line.
std::string one_line(std::string message) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  for (char& c : message) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return message;
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

// Finds MTL files relative to the OBJ's folder and remembers, per material, its MTL's folder
// (texture paths are relative to it) and whether it had a Kd. A missing MTL is a warning for
// tinyobj, which then uses no materials.
class MtlReader : public tinyobj::MaterialReader {
 public:
  explicit MtlReader(fs::path obj_dir) : obj_dir_(std::move(obj_dir)) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* ids, std::string* warn, std::string*) override {
    fs::path path = obj_dir_ / name;
    std::string text, reason;
    if (!read_text(path, text, reason)) {
      if (warn) *warn += path.string() + ": " + reason + "\n";
      return false;
    }
    size_t first = materials->size();
    std::istringstream in(text);
    std::string mtl_warn;
    tinyobj::LoadMtl(ids, materials, &in, &mtl_warn, nullptr);
    std::vector<bool> kd = scan_kd(text);
    // Should the scan ever disagree with tinyobj, trust tinyobj's Kd values.
    kd.resize(materials->size() - first, true);
    has_kd_.insert(has_kd_.end(), kd.begin(), kd.end());
    dirs_.resize(materials->size(), path.parent_path());
    return true;
  }

  const fs::path& dir(size_t material) const { return dirs_[material]; }
  bool has_kd(size_t material) const { return has_kd_[material]; }

 private:
  fs::path obj_dir_;
  std::vector<fs::path> dirs_;
  std::vector<bool> has_kd_;
};

struct ObjData {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
};

Status parse_obj(const std::string& path, MtlReader& reader, ObjData& data) {
  std::string text, reason;
  if (!read_text(path, text, reason)) return fail(path, reason);
  std::istringstream in(text);
  std::string warn, err;
  // No triangulation (we fan ourselves) and no made-up vertex colours.
  bool ok = tinyobj::LoadObj(&data.attrib, &data.shapes, &data.materials, &warn, &err, &in, &reader,
                             /*triangulate=*/false, /*default_vcols_fallback=*/false);
  if (!ok) return fail(path, err.empty() ? "cannot parse OBJ" : one_line(err));
  return {};
}

// Checks one corner's indices against the attribute arrays (tinyobj has already resolved
// negative, relative indices; -1 means "absent" for uv and normal).
std::string check_corner(const tinyobj::index_t& c, const tinyobj::attrib_t& a) {
  auto describe = [](const char* what, int index, size_t count) {
    return std::string(what) + " index " + std::to_string(int64_t(index) + 1) +
           " out of range (the file has " + std::to_string(count) + ")";
  };
  size_t positions = a.vertices.size() / 3, uvs = a.texcoords.size() / 2;
  size_t normals = a.normals.size() / 3;
  if (c.vertex_index < 0 || size_t(c.vertex_index) >= positions) {
    return describe("position", c.vertex_index, positions);
  }
  if (c.texcoord_index < -1 || (c.texcoord_index >= 0 && size_t(c.texcoord_index) >= uvs)) {
    return describe("texture coordinate", c.texcoord_index, uvs);
  }
  if (c.normal_index < -1 || (c.normal_index >= 0 && size_t(c.normal_index) >= normals)) {
    return describe("normal", c.normal_index, normals);
  }
  return "";
}

Status check_shape(const std::string& path, const ObjData& data, const tinyobj::mesh_t& mesh) {
  // num_face_vertices is an unsigned char: a polygon of 256 or more corners loses its count.
  size_t corners = 0;
  for (unsigned char n : mesh.num_face_vertices) corners += n;
  if (corners != mesh.indices.size()) return fail(path, "polygon with more than 255 vertices");
  if (mesh.material_ids.size() != mesh.num_face_vertices.size()) {
    return fail(path, "material ids do not match the faces");
  }
  for (size_t f = 0; f < mesh.material_ids.size(); ++f) {
    int id = mesh.material_ids[f];
    if (id < -1 || id >= int(data.materials.size())) return fail(path, "bad material id");
  }
  for (const tinyobj::index_t& corner : mesh.indices) {
    if (std::string reason = check_corner(corner, data.attrib); !reason.empty()) {
      return fail(path, reason);
    }
  }
  return {};
}

Status check_finite(const std::string& path, const std::vector<tinyobj::real_t>& values,
                    const char* what, size_t components) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return fail(path,
                  std::string(what) + " " + std::to_string(i / components + 1) + " is not finite");
    }
  }
  return {};
}

Status check_obj(const std::string& path, const ObjData& data) {
  size_t corners = 0;
  for (const tinyobj::shape_t& shape : data.shapes) {
    if (Status s = check_shape(path, data, shape.mesh); !s.ok()) return s;
    corners += shape.mesh.indices.size();
  }
  if (corners == 0) return fail(path, "no faces");
  // Fanning n corners gives 3(n - 2) < 3n indices; they must fit Mesh's 32-bit indices.
  if (corners > UINT32_MAX / 3) return fail(path, "too many faces");
  const tinyobj::attrib_t& a = data.attrib;
  if (Status s = check_finite(path, a.vertices, "position", 3); !s.ok()) return s;
  if (Status s = check_finite(path, a.normals, "normal", 3); !s.ok()) return s;
  return check_finite(path, a.texcoords, "texture coordinate", 2);
}

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

Result<std::vector<Material>> convert_materials(const std::string& path, const ObjData& data,
                                                const MtlReader& reader) {
  std::vector<Material> materials;
  TextureCache cache;
  for (size_t i = 0; i < data.materials.size(); ++i) {
    const tinyobj::material_t& source = data.materials[i];
    Material material;
    material.name = source.name;
    if (reader.has_kd(i)) {
      material.diffuse = {source.diffuse[0], source.diffuse[1], source.diffuse[2]};
    }
    if (!source.diffuse_texname.empty()) {
      auto texture = texture_at(reader.dir(i) / source.diffuse_texname, cache);
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

// Builds the indexed mesh: one vertex per distinct (position, uv, normal) index triple.
class MeshBuilder {
 public:
  explicit MeshBuilder(const tinyobj::attrib_t& attrib) : attrib_(attrib) {}

  void add_face(const tinyobj::index_t* corners, size_t count, int material) {
    // Fan around the first corner: (0, 1, 2), (0, 2, 3), ...
    for (size_t k = 1; k + 1 < count; ++k) {
      add_triangle({corners[0], corners[k], corners[k + 1]}, material);
    }
  }

  // Missing normals become smooth normals per OBJ position index, so vertices that share a
  // position but not a uv still get the same normal.
  Mesh finish() {
    if (needs_smoothing_) {
      auto sums = group_normal_sums(mesh_, position_index_, attrib_.vertices.size() / 3);
      for (size_t v = 0; v < mesh_.normals.size(); ++v) {
        if (!has_normal_[v]) mesh_.normals[v] = unit_or_z(sums[position_index_[v]]);
      }
    }
    return std::move(mesh_);
  }

 private:
  struct Key {
    int v, vt, vn;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint64_t h = uint64_t(uint32_t(k.v)) * 0x9E3779B97F4A7C15ull;
      h ^= (uint64_t(uint32_t(k.vt)) + (h << 6) + (h >> 2)) * 0xC2B2AE3D27D4EB4Full;
      h ^= (uint64_t(uint32_t(k.vn)) + (h << 6) + (h >> 2)) * 0x165667B19E3779F9ull;
      return size_t(h ^ (h >> 29));
    }
  };

  void add_triangle(const std::array<tinyobj::index_t, 3>& corners, int material) {
    if (mesh_.submeshes.empty() || mesh_.submeshes.back().material != material) {
      mesh_.submeshes.push_back({uint32_t(mesh_.indices.size()), 0, material});
    }
    for (const tinyobj::index_t& c : corners) mesh_.indices.push_back(vertex(c));
    mesh_.submeshes.back().index_count += 3;
  }

  uint32_t vertex(const tinyobj::index_t& c) {
    Key key{c.vertex_index, c.texcoord_index, c.normal_index};
    auto [it, inserted] = vertices_.try_emplace(key, uint32_t(mesh_.positions.size()));
    if (!inserted) return it->second;
    const auto& a = attrib_;
    size_t v = size_t(c.vertex_index), vt = size_t(c.texcoord_index), vn = size_t(c.normal_index);
    mesh_.positions.emplace_back(a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]);
    bool has_uv = c.texcoord_index >= 0, has_normal = c.normal_index >= 0;
    mesh_.uvs.push_back(has_uv ? glm::vec2(a.texcoords[2 * vt], a.texcoords[2 * vt + 1])
                               : glm::vec2(0.0f));
    mesh_.normals.push_back(
        has_normal ? glm::vec3(a.normals[3 * vn], a.normals[3 * vn + 1], a.normals[3 * vn + 2])
                   : glm::vec3(0.0f));
    has_normal_.push_back(has_normal);
    position_index_.push_back(uint32_t(c.vertex_index));
    needs_smoothing_ = needs_smoothing_ || !has_normal;
    return it->second;
  }

  const tinyobj::attrib_t& attrib_;
  Mesh mesh_;
  std::unordered_map<Key, uint32_t, KeyHash> vertices_;
  std::vector<bool> has_normal_;
  std::vector<uint32_t> position_index_;  // per vertex: its OBJ position index
  bool needs_smoothing_ = false;
};

Mesh build_mesh(const ObjData& data) {
  MeshBuilder builder(data.attrib);
  for (const tinyobj::shape_t& shape : data.shapes) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    size_t first = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      size_t count = mesh.num_face_vertices[f];
      builder.add_face(&mesh.indices[first], count, mesh.material_ids[f]);
      first += count;
    }
  }
  return builder.finish();
}

}  // namespace

Result<Mesh> load_obj(const std::string& path) {
  MtlReader reader(fs::path(path).parent_path());
  ObjData data;
  if (Status s = parse_obj(path, reader, data); !s.ok()) return s;
  if (Status s = check_obj(path, data); !s.ok()) return s;
  Result<std::vector<Material>> materials = convert_materials(path, data, reader);
  if (!materials.ok()) return materials.status();
  Mesh mesh = build_mesh(data);
  mesh.materials = std::move(*materials);
  return mesh;
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
