// fuzz/model_fuzz.cpp: the PLY and STL parsers on arbitrary bytes, from memory: parse_ply and
// parse_stl are what load_ply, load_stl and load_model run on a file's bytes once read. A mesh
// they return must be ready to draw (mesh_checks.hpp), with vertex colours in [0, 1] and finite
// normals; an error must be one line naming the file.
#include <cmath>
#include <string>

#include "fuzz_entries.hpp"
#include "io/model_formats.hpp"
#include "mesh_checks.hpp"

namespace softrast::fuzz {
namespace {

void check_model(const Result<Mesh>& mesh, const std::string& name) {
  if (!mesh) {
    check_error(mesh.status(), name);
    return;
  }
  check_mesh(*mesh);
  for (const glm::vec3& n : mesh->normals) {
    SOFTRAST_FUZZ_REQUIRE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z),
                          "non-finite normal");
  }
  for (const glm::vec4& c : mesh->colors) {
    for (int k = 0; k < 4; ++k) {
      SOFTRAST_FUZZ_REQUIRE(c[k] >= 0.0f && c[k] <= 1.0f, "vertex colour outside [0, 1]");
    }
  }
}

}  // namespace

int fuzz_ply(const uint8_t* data, size_t size) {
  const std::string name = "fuzz.ply";
  check_model(detail::parse_ply(reinterpret_cast<const char*>(data), size, name), name);
  return 0;
}

int fuzz_stl(const uint8_t* data, size_t size) {
  // Both parsers on every input (load_model chooses by the size and the first word, which a
  // damaged file can get wrong either way).
  const std::string name = "fuzz.stl";
  const char* bytes = reinterpret_cast<const char*>(data);
  check_model(detail::parse_stl(bytes, size, true, name), name);
  check_model(detail::parse_stl(bytes, size, false, name), name);
  return 0;
}

}  // namespace softrast::fuzz
