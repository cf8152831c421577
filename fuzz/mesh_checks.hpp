// fuzz/mesh_checks.hpp: what every model loader promises of a mesh it returns and of an error it
// reports, checked by the fuzz targets of the loaders (obj, gltf, ply, stl).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"
#include "softrast/mesh.hpp"
#include "softrast/status.hpp"

namespace softrast::fuzz {

// Runs of one kind of element inside its indices, whole elements of `per` indices, naming a
// material or none (-1).
inline void check_runs(const Mesh& mesh, const std::vector<uint32_t>& indices,
                       const std::vector<SubMesh>& runs, uint32_t per) {
  for (uint32_t i : indices) SOFTRAST_FUZZ_REQUIRE(i < mesh.positions.size(), "index out of range");
  for (const SubMesh& s : runs) {
    SOFTRAST_FUZZ_REQUIRE(size_t(s.first_index) + s.index_count <= indices.size(),
                          "submesh past indices");
    SOFTRAST_FUZZ_REQUIRE(s.index_count % per == 0, "submesh not whole elements");
    SOFTRAST_FUZZ_REQUIRE(s.material >= -1 && s.material < int(mesh.materials.size()),
                          "bad material index");
  }
}

// A mesh ready to draw: something to draw (triangles, lines or points), whole triangles and
// segments, indices naming vertices, finite positions, one normal and one uv per position, the
// optional attributes absent or one per position, submeshes inside their indices naming a
// material or none (-1).
inline void check_mesh(const Mesh& mesh) {
  const size_t n = mesh.positions.size();
  SOFTRAST_FUZZ_REQUIRE(
      !mesh.indices.empty() || !mesh.line_indices.empty() || !mesh.point_indices.empty(),
      "nothing to draw");
  SOFTRAST_FUZZ_REQUIRE(mesh.indices.size() % 3 == 0, "index count not 3n");
  SOFTRAST_FUZZ_REQUIRE(mesh.line_indices.size() % 2 == 0, "line index count not 2n");
  SOFTRAST_FUZZ_REQUIRE(mesh.normals.size() == n && mesh.uvs.size() == n,
                        "normals or uvs differ from positions in count");
  SOFTRAST_FUZZ_REQUIRE(mesh.tangents.empty() || mesh.tangents.size() == n, "tangent count");
  SOFTRAST_FUZZ_REQUIRE(mesh.colors.empty() || mesh.colors.size() == n, "colour count");
  SOFTRAST_FUZZ_REQUIRE(mesh.uvs1.empty() || mesh.uvs1.size() == n, "uv1 count");
  for (const glm::vec3& p : mesh.positions) {
    SOFTRAST_FUZZ_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z),
                          "non-finite position");
  }
  check_runs(mesh, mesh.indices, mesh.submeshes, 3);
  check_runs(mesh, mesh.line_indices, mesh.line_submeshes, 2);
  check_runs(mesh, mesh.point_indices, mesh.point_submeshes, 1);
}

// An error a user can read: one line, starting with the file's name and ": " or ":line: ".
inline void check_error(const Status& s, const std::string& name) {
  const std::string& m = s.message();
  bool named = m.rfind(name + ": ", 0) == 0;
  if (!named && m.rfind(name + ":", 0) == 0) {
    size_t digits = name.size() + 1, end = digits;
    while (end < m.size() && m[end] >= '0' && m[end] <= '9') ++end;
    named = end > digits && m.compare(end, 2, ": ") == 0;
  }
  SOFTRAST_FUZZ_REQUIRE(named, "error without the file name: " + m);
  SOFTRAST_FUZZ_REQUIRE(m.find('\n') == std::string::npos, "error of several lines: " + m);
}

}  // namespace softrast::fuzz
