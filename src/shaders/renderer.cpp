// shaders/renderer.cpp: render_mesh, the built-in shaders' entry point.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string_view>

#include "debug/debug_render.hpp"
#include "shaders/builtin_shaders.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr std::array<std::pair<ShaderKind, const char*>, 7> kShaderNames = {{
    {ShaderKind::kFlat, "flat"},
    {ShaderKind::kGouraud, "gouraud"},
    {ShaderKind::kTexture, "texture"},
    {ShaderKind::kPhong, "phong"},
    {ShaderKind::kNormals, "normals"},
    {ShaderKind::kDepth, "depth"},
    {ShaderKind::kWireframe, "wireframe"},
}};

// What one submesh is drawn with.
struct Surface {
  glm::vec3 albedo;
  const Texture* texture;  // null: untextured
};

Surface surface_of(const Mesh& mesh, int material, const RenderOptions& opt) {
  Surface s{opt.color, opt.texture.get()};
  if (material >= 0 && material < int(mesh.materials.size())) {
    const Material& m = mesh.materials[size_t(material)];
    s.albedo = m.diffuse;
    if (!s.texture) s.texture = m.diffuse_map.get();
  }
  return s;
}

// Draws one run of indices with the chosen built-in shader.
void draw_run(Framebuffer& fb, const RenderState& state, const Mesh& mesh, const Camera& camera,
              const glm::mat4& mvp, std::span<const uint32_t> indices, const Surface& surf,
              const RenderOptions& opt, ShaderKind kind) {
  using namespace detail;
  MeshInputs in{&mesh, mvp};
  uint32_t n = uint32_t(mesh.positions.size());
  glm::vec3 light = glm::normalize(opt.light_direction);
  static const Texture kWhite;  // samples as opaque white
  switch (kind) {
    case ShaderKind::kFlat:
      return draw(fb, state, FlatShader{in, glm::vec4(surf.albedo, opt.alpha)}, indices, n);
    case ShaderKind::kWireframe:  // the overlay passes the wire colour as the surface albedo
      return draw(fb, state, FlatShader{in, glm::vec4(surf.albedo, 1.0f)}, indices, n);
    case ShaderKind::kGouraud:
      return draw(fb, state, GouraudShader{in, surf.albedo, light, opt.alpha}, indices, n);
    case ShaderKind::kTexture: {
      const Texture* t = surf.texture ? surf.texture : &kWhite;
      return draw(fb, state, TextureShader{in, t, opt.sampler, opt.alpha}, indices, n);
    }
    case ShaderKind::kPhong:
      return draw(
          fb, state,
          PhongShader{in, surf.albedo, surf.texture, opt.sampler, light, camera.eye, opt.alpha},
          indices, n);
    case ShaderKind::kNormals:
      return draw(fb, state, NormalsShader{in}, indices, n);
    case ShaderKind::kDepth: {
      float near_plane = std::max(camera.near_plane, 1.0e-3f);
      float log_range = std::log(std::max(camera.far_plane / near_plane, 1.0f + 1.0e-3f));
      return draw(fb, state, DepthShader{in, camera.view(), near_plane, log_range}, indices, n);
    }
  }
}

// A mesh whose normals and uvs match its positions (the built-in shaders read all three).
const Mesh& complete_mesh(const Mesh& mesh, Mesh& storage) {
  size_t n = mesh.positions.size();
  if (mesh.normals.size() == n && mesh.uvs.size() == n) return mesh;
  storage = mesh;
  if (storage.normals.size() != n) compute_smooth_normals(storage);
  storage.uvs.resize(n, glm::vec2(0.0f));
  return storage;
}

}  // namespace

std::optional<ShaderKind> parse_shader_kind(std::string_view name) {
  for (const auto& [kind, text] : kShaderNames) {
    if (name == text) return kind;
  }
  return std::nullopt;
}

const char* shader_kind_name(ShaderKind kind) {
  for (const auto& [k, text] : kShaderNames) {
    if (k == kind) return text;
  }
  return "?";
}

void render_mesh(Framebuffer& framebuffer, const Mesh& input, const Camera& camera,
                 const RenderOptions& options) {
  if (options.debug_view != DebugView::kNone) {
    return detail::render_debug_view(framebuffer, input, camera, options);
  }
  Mesh storage;
  const Mesh& mesh = complete_mesh(input, storage);
  float aspect = float(framebuffer.width()) / float(framebuffer.height());
  glm::mat4 mvp = camera.view_projection(aspect);
  std::vector<SubMesh> runs = mesh.submeshes;
  if (runs.empty()) runs.push_back({0, uint32_t(mesh.indices.size()), -1});

  RenderState state = options.state;
  if (options.shader == ShaderKind::kWireframe) state.wireframe = true;
  for (const SubMesh& run : runs) {
    if (size_t(run.first_index) + run.index_count > mesh.indices.size()) continue;
    std::span<const uint32_t> indices(mesh.indices.data() + run.first_index, run.index_count);
    Surface surf = surface_of(mesh, run.material, options);
    draw_run(framebuffer, state, mesh, camera, mvp, indices, surf, options, options.shader);
  }
  if (options.wireframe_overlay && options.shader != ShaderKind::kWireframe) {
    RenderState wire = options.state;
    wire.wireframe = true;
    wire.blend = BlendMode::kOpaque;
    wire.depth_write = false;
    wire.depth_func = DepthFunc::kLessEqual;
    // A line's depth is interpolated along the line, not at the pixel centre the filled
    // triangle was sampled at: up to half a pixel of the triangle's slope apart. One slope
    // (and a few steps) towards the viewer keeps every visible edge pixel, and hides edges
    // behind other surfaces.
    wire.polygon_offset_factor = -1.0f;
    wire.polygon_offset_units = -4.0f;
    std::span<const uint32_t> all(mesh.indices);
    draw_run(framebuffer, wire, mesh, camera, mvp, all, Surface{options.wire_color, nullptr},
             options, ShaderKind::kWireframe);
  }
}

}  // namespace softrast
