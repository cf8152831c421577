// fuzz/gltf_fuzz.cpp: glTF and GLB on arbitrary bytes, from memory (no file is read: external
// buffers and images are refused, as a document's own bytes are what is being tested). Parse and
// validate (read_gltf_document), read every accessor the document has (used or not), flatten
// into a mesh (gltf_to_mesh), check the mesh, and render it with the pbr shader at 16x16.
#include <cmath>
#include <string>

#include "fuzz_entries.hpp"
#include "io/gltf_document.hpp"
#include "softrast/renderer.hpp"

namespace softrast::fuzz {
namespace {

void check_mesh(const Mesh& mesh) {
  size_t n = mesh.positions.size();
  SOFTRAST_FUZZ_REQUIRE(!mesh.indices.empty() && mesh.indices.size() % 3 == 0,
                        "index count not 3n > 0");
  SOFTRAST_FUZZ_REQUIRE(mesh.normals.size() == n && mesh.uvs.size() == n,
                        "normals or uvs differ from positions in count");
  SOFTRAST_FUZZ_REQUIRE(mesh.tangents.empty() || mesh.tangents.size() == n, "tangent count");
  SOFTRAST_FUZZ_REQUIRE(mesh.colors.empty() || mesh.colors.size() == n, "colour count");
  SOFTRAST_FUZZ_REQUIRE(mesh.uvs1.empty() || mesh.uvs1.size() == n, "uv1 count");
  SOFTRAST_FUZZ_REQUIRE(n <= size_t(kMaxGltfVertices), "more vertices than the limit");
  for (uint32_t i : mesh.indices) SOFTRAST_FUZZ_REQUIRE(i < n, "index out of range");
  for (const glm::vec3& p : mesh.positions) {
    SOFTRAST_FUZZ_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z),
                          "non-finite position");
  }
  for (const SubMesh& s : mesh.submeshes) {
    SOFTRAST_FUZZ_REQUIRE(size_t(s.first_index) + s.index_count <= mesh.indices.size(),
                          "submesh past indices");
    SOFTRAST_FUZZ_REQUIRE(s.index_count % 3 == 0, "submesh not whole triangles");
    SOFTRAST_FUZZ_REQUIRE(s.material >= 0 && s.material < int(mesh.materials.size()),
                          "bad material index");
  }
}

void check_error(const Status& s, const std::string& name) {
  const std::string& m = s.message();
  SOFTRAST_FUZZ_REQUIRE(m.rfind(name + ": ", 0) == 0, "error without the file name: " + m);
  SOFTRAST_FUZZ_REQUIRE(m.find('\n') == std::string::npos, "error of several lines: " + m);
}

}  // namespace

int fuzz_gltf(const uint8_t* data, size_t size) {
  const std::string name = "fuzz.gltf";
  Result<detail::GltfDocument> doc = detail::read_gltf_document(data, size, name, "");
  if (!doc) {
    check_error(doc.status(), name);
    return 0;
  }
  (void)detail::gltf_read_every_accessor(*doc);
  Result<Mesh> mesh = detail::gltf_to_mesh(*doc, name, "");
  if (!mesh) {
    check_error(mesh.status(), name);
    return 0;
  }
  check_mesh(*mesh);
  Camera camera;
  camera.eye = {0.0f, 0.0f, 3.0f};
  RenderOptions options;
  options.shader = ShaderKind::kPbr;
  options.state.threads = 1;
  Framebuffer fb(16, 16);
  fb.clear_color(glm::vec4(0.0f));
  fb.clear_depth(1.0f);
  render_mesh(fb, *mesh, camera, options);
  return 0;
}

}  // namespace softrast::fuzz
