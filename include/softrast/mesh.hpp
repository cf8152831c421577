// softrast/mesh.hpp: indexed triangle meshes with materials, and the OBJ/MTL loader.
// Positions are in model (here: world) space; the renderer applies the camera.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "softrast/status.hpp"
#include "softrast/texture.hpp"

namespace softrast {

struct Material {
  std::string name;
  glm::vec3 diffuse{0.9f, 0.6f, 0.3f};         // Kd; the default is SCENES.md's albedo A
  std::shared_ptr<const Texture> diffuse_map;  // map_Kd, or null
};

// A run of indices drawn with one material.
struct SubMesh {
  uint32_t first_index = 0;  // into Mesh::indices
  uint32_t index_count = 0;  // a multiple of 3
  int material = -1;         // into Mesh::materials, or -1 for the default material
};

// Vertices are de-duplicated (one per distinct position/normal/uv triple); every vertex has a
// normal and a uv (missing normals are area-weighted smooth normals, missing uvs are (0, 0)).
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<uint32_t> indices;   // three per triangle
  std::vector<SubMesh> submeshes;  // cover `indices`; empty means one run with material -1
  std::vector<Material> materials;

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

// Loads a Wavefront OBJ (polygons fan-triangulated) with its MTL library (Kd and map_Kd at
// least). Texture paths are relative to the MTL file. Errors name the file and, where it helps,
// the line: missing file, no faces, index out of range, unreadable texture.
Result<Mesh> load_obj(const std::string& path);

// Fills `mesh.normals` with area-weighted smooth normals per position (used when the file has
// none). Degenerate neighbourhoods get (0, 0, 1).
void compute_smooth_normals(Mesh& mesh);

}  // namespace softrast
