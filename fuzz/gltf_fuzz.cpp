// fuzz/gltf_fuzz.cpp: glTF and GLB on arbitrary bytes, from memory (no file is read: external
// buffers and images are refused, as a document's own bytes are what is being tested). Parse and
// validate (read_gltf_document), read every accessor the document has (used or not), flatten
// into a mesh (gltf_to_mesh), check the mesh, and render it with the pbr shader at 16x16.
#include <cmath>
#include <string>

#include "fuzz_entries.hpp"
#include "io/gltf_document.hpp"
#include "mesh_checks.hpp"
#include "softrast/renderer.hpp"

namespace softrast::fuzz {

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
  SOFTRAST_FUZZ_REQUIRE(mesh->positions.size() <= size_t(kMaxGltfVertices),
                        "more vertices than the limit");
  for (const SubMesh& s : mesh->submeshes) {
    SOFTRAST_FUZZ_REQUIRE(s.material >= 0, "a glTF submesh without a material");
  }
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
