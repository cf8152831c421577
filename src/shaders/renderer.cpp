// shaders/renderer.cpp: render_mesh, the built-in shaders' entry point.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string_view>
#include <vector>

#include "debug/debug_render.hpp"
#include "shaders/builtin_shaders.hpp"
#include "shaders/pbr_render.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr std::array<std::pair<ShaderKind, const char*>, 8> kShaderNames = {{
    {ShaderKind::kFlat, "flat"},
    {ShaderKind::kGouraud, "gouraud"},
    {ShaderKind::kTexture, "texture"},
    {ShaderKind::kPhong, "phong"},
    {ShaderKind::kNormals, "normals"},
    {ShaderKind::kDepth, "depth"},
    {ShaderKind::kWireframe, "wireframe"},
    {ShaderKind::kPbr, "pbr"},
}};

// What one submesh is drawn with.
struct Surface {
  glm::vec3 albedo;
  const Texture* texture;      // null: untextured
  detail::SurfaceMaps maps{};  // phong's material (maps.diffuse is `texture`)
  // The material's placement of its maps (Material::uv_scale, uv_offset, clamp_maps).
  glm::vec2 uv_scale{1.0f};
  glm::vec2 uv_offset{0.0f};
  bool clamp_maps = false;
};

using Maps = RenderOptions::Maps;

Surface surface_of(const Mesh& mesh, int material, const RenderOptions& opt) {
  Surface s{opt.color, opt.texture.get()};
  s.maps.specular_color = glm::vec3(detail::kSpecular * opt.light_intensity);
  if (material >= 0 && material < int(mesh.materials.size())) {
    const Material& m = mesh.materials[size_t(material)];
    s.albedo = m.diffuse;
    if (!s.texture && opt.maps != Maps::kNone) s.texture = m.diffuse_map.get();
    s.maps.specular_color = m.specular * opt.light_intensity;
    s.maps.shininess = m.shininess;
    s.maps.opacity = m.opacity;
    s.uv_scale = m.uv_scale;
    s.uv_offset = m.uv_offset;
    s.clamp_maps = m.clamp_maps;
    if (opt.maps == Maps::kAll) {
      s.maps.specular = m.specular_map.get();
      s.maps.normal = m.normal_map.get();
      s.maps.object_space = m.normal_space == NormalSpace::kObject;
      s.maps.normal_scale = m.normal_scale;
      s.maps.alpha = m.alpha_map.get();
    }
  }
  s.maps.diffuse = s.texture;
  return s;
}

// Whether a surface lets what is behind it show (phong and texture): a material opacity below
// 1 (MTL d), an alpha map, or a diffuse map with translucent texels (a cornea over an eye).
bool translucent(const Surface& s, const RenderOptions& opt) {
  if (opt.shader == ShaderKind::kTexture) return s.texture && s.texture->translucent();
  if (opt.shader != ShaderKind::kPhong) return false;
  return s.maps.opacity < 1.0f || s.maps.alpha || (s.maps.diffuse && s.maps.diffuse->translucent());
}

// Whether phong needs the mesh's tangents for `material`: a tangent-space normal map in use.
bool needs_tangents(const Mesh& mesh, const RenderOptions& opt) {
  if (opt.shader != ShaderKind::kPhong || opt.maps != Maps::kAll) return false;
  return std::any_of(mesh.materials.begin(), mesh.materials.end(), [](const Material& m) {
    return m.normal_map && m.normal_space == NormalSpace::kTangent;
  });
}

// The view depths the depth view's grey ramp spans.
struct DepthRange {
  float nearest, farthest;
};

detail::Lighting lighting_of(const RenderOptions& opt) {
  detail::Lighting l;
  l.light = glm::normalize(opt.light_direction);
  l.ambient = opt.ambient;
  l.diffuse = detail::kDiffuse * opt.light_intensity;
  l.specular = detail::kSpecular * opt.light_intensity;
  l.two_sided = opt.two_sided_lighting;
  l.point = opt.light_position.has_value();
  if (l.point) l.position = *opt.light_position;
  l.srgb_output = opt.srgb;
  return l;
}

// Draws one run of indices with the chosen built-in shader.
void draw_run(Framebuffer& fb, const RenderState& state, const Mesh& mesh, const Camera& camera,
              const glm::mat4& mvp, std::span<const uint32_t> indices, const Surface& surf,
              const RenderOptions& opt, ShaderKind kind, DepthRange depth,
              const detail::ShadowMap* shadow = nullptr) {
  using namespace detail;
  MeshInputs in{&mesh, mvp, surf.uv_scale, surf.uv_offset};
  uint32_t n = uint32_t(mesh.positions.size());
  Lighting lighting = lighting_of(opt);
  lighting.shadow = shadow;
  // Two-sided Gouraud interpolates a second colour; only worth it when back faces are drawn.
  bool two_sided = lighting.two_sided && state.cull != CullMode::kBack;
  static const Texture kWhite;  // samples as opaque white
  Sampler sampler = opt.sampler;
  sampler.srgb_decode = opt.srgb;
  if (surf.clamp_maps) sampler.wrap_u = sampler.wrap_v = Wrap::kClampToEdge;
  // Vertex colours (OBJ, PLY) are the albedo of flat, gouraud and phong where no diffuse map is.
  ColorSource colors{mesh.colors.size() == mesh.positions.size() && !surf.maps.diffuse, opt.srgb};
  switch (kind) {
    case ShaderKind::kFlat:
      if (colors.use) {  // unlit, interpolated: Gouraud with the ambient term alone, at 1
        Lighting unlit = lighting;
        unlit.ambient = 1.0f, unlit.diffuse = 0.0f;
        return draw(fb, state,
                    GouraudShader<false, true>{in, surf.albedo, unlit, opt.alpha, colors}, indices,
                    n);
      }
      return draw(fb, state, FlatShader{in, glm::vec4(surf.albedo, opt.alpha), opt.srgb}, indices,
                  n);
    case ShaderKind::kWireframe:  // the overlay passes the wire colour as the surface albedo
      return draw(fb, state, FlatShader{in, glm::vec4(surf.albedo, 1.0f)}, indices, n);
    case ShaderKind::kGouraud: {
      // The mesh's vertex colours as the albedo: the lit colour interpolated; else the intensity.
      auto gouraud = [&]<bool kTwoSided, bool kVertexAlbedo>() {
        return draw(
            fb, state,
            GouraudShader<kTwoSided, kVertexAlbedo>{in, surf.albedo, lighting, opt.alpha, colors},
            indices, n);
      };
      if (colors.use) {
        return two_sided ? gouraud.template operator()<true, true>()
                         : gouraud.template operator()<false, true>();
      }
      return two_sided ? gouraud.template operator()<true, false>()
                       : gouraud.template operator()<false, false>();
    }
    case ShaderKind::kTexture: {
      const Texture* t = surf.texture ? surf.texture : &kWhite;
      return draw(fb, state, TextureShader{in, SampledTexture(*t, sampler), opt.alpha, opt.srgb},
                  indices, n);
    }
    case ShaderKind::kPhong:
    case ShaderKind::kPbr: {  // pbr is drawn by render_pbr; phong if it ever gets here
      SurfaceMaps maps = surf.maps;
      in.position_scale = detail::shading_scale(camera, opt);
      const glm::vec3 eye = camera.eye * in.position_scale;
      lighting.position *= in.position_scale;
      bool tangents = maps.normal && !maps.object_space;
      if (tangents && mesh.tangents.size() == mesh.positions.size()) {
        return draw(fb, state,
                    PhongShader<PhongInputs::kTangentFrame>{
                        in, surf.albedo, maps, sampler, lighting, eye, opt.alpha, {}},
                    indices, n);
      }
      if (tangents) maps.normal = nullptr;  // no tangent frame: the interpolated normal
      if (maps.diffuse || maps.specular || maps.normal || maps.alpha) {
        return draw(fb, state,
                    PhongShader<PhongInputs::kUv>{
                        in, surf.albedo, maps, sampler, lighting, eye, opt.alpha, {}},
                    indices, n);
      }
      if (colors.use) {
        return draw(fb, state,
                    PhongShader<PhongInputs::kColors>{in, surf.albedo, maps, sampler, lighting, eye,
                                                      opt.alpha, colors},
                    indices, n);
      }
      return draw(fb, state,
                  PhongShader<PhongInputs::kPlain>{
                      in, surf.albedo, maps, sampler, lighting, eye, opt.alpha, {}},
                  indices, n);
    }
    case ShaderKind::kNormals:
      return draw(fb, state, NormalsShader{in}, indices, n);
    case ShaderKind::kDepth:
      return draw(fb, state, DepthShader(in, camera.view(), depth.nearest, depth.farthest), indices,
                  n);
  }
}

// The view depth (distance along the view direction) of window depth `z` in [0, 1]. In double:
// n * f overflows float for a model in units of 1e30 (and underflows it at 1e-30).
float view_depth(const Camera& camera, float z) {
  double n = camera.near_plane, f = camera.far_plane;
  if (camera.orthographic) return float(n + z * (f - n));
  double z_ndc = 2.0 * z - 1.0;
  return float(2.0 * n * f / ((f + n) - z_ndc * (f - n)));
}

// The nearest and farthest view depth among the pixels `runs` cover with the depth test on: a
// depth-only pass into a scratch buffer. The camera's near and far when nothing is visible.
DepthRange visible_depth_range(int width, int height, const Mesh& mesh, const Camera& camera,
                               const glm::mat4& mvp, std::span<const SubMesh> runs,
                               const RenderState& state) {
  Framebuffer scratch(width, height);
  scratch.clear_depth(1.0f);
  RenderState depth_only = state;
  depth_only.depth_test = true;
  depth_only.depth_write = true;
  depth_only.depth_func = DepthFunc::kLess;
  depth_only.blend = BlendMode::kOpaque;
  detail::FlatShader shader{{&mesh, mvp}, glm::vec4(1.0f)};
  for (const SubMesh& run : runs) {
    std::span<const uint32_t> indices(mesh.indices.data() + run.first_index, run.index_count);
    draw(scratch, depth_only, shader, indices, uint32_t(mesh.positions.size()));
  }
  float lo = 1.0f, hi = 0.0f;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float d = scratch.depth_at(x, y);
      if (d >= 1.0f) continue;  // the clear value: nothing drawn here
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  if (lo > hi) return {camera.near_plane, camera.far_plane};
  return {view_depth(camera, lo), view_depth(camera, hi)};
}

// The mesh's lines and points (OBJ's l and p, glTF's line and point modes), after its triangles:
// one pixel wide, unlit in each run's diffuse colour (or the vertex colours, as the flat shader
// draws them), depth-tested as the triangles are, never culled.
void draw_lines_and_points(Framebuffer& fb, const RenderState& triangles, const Mesh& mesh,
                           const Camera& camera, const glm::mat4& mvp, const RenderOptions& opt,
                           DepthRange depth) {
  struct Kind {
    Primitive primitive;
    const std::vector<uint32_t>& indices;
    const std::vector<SubMesh>& runs;
  };
  for (const Kind& kind : {Kind{Primitive::kLines, mesh.line_indices, mesh.line_submeshes},
                           Kind{Primitive::kPoints, mesh.point_indices, mesh.point_submeshes}}) {
    if (kind.indices.empty()) continue;
    RenderState state = triangles;
    state.primitive = kind.primitive;
    state.wireframe = false;
    state.cull = CullMode::kNone;
    std::vector<SubMesh> runs = kind.runs;
    if (runs.empty()) runs.push_back({0, uint32_t(kind.indices.size()), -1});
    for (const SubMesh& run : runs) {
      if (size_t(run.first_index) + run.index_count > kind.indices.size()) continue;
      Surface surf = surface_of(mesh, run.material, opt);
      surf.maps = {};
      surf.texture = nullptr;
      std::span<const uint32_t> indices(kind.indices.data() + run.first_index, run.index_count);
      draw_run(fb, state, mesh, camera, mvp, indices, surf, opt, ShaderKind::kFlat, depth);
    }
  }
}

// A mesh whose normals and uvs match its positions (the built-in shaders read all three), and
// its tangents when `tangents` (loaders compute them for their normal maps: this is the
// fallback for meshes built otherwise).
const Mesh& complete_mesh(const Mesh& mesh, Mesh& storage, bool tangents) {
  size_t n = mesh.positions.size();
  bool need_tangents = tangents && mesh.tangents.size() != n;
  if (mesh.normals.size() == n && mesh.uvs.size() == n && !need_tangents) return mesh;
  storage = mesh;
  if (storage.normals.size() != n) compute_smooth_normals(storage);
  storage.uvs.resize(n, glm::vec2(0.0f));
  if (need_tangents) compute_tangents(storage);
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
  const Mesh& mesh = complete_mesh(input, storage, needs_tangents(input, options));
  float aspect = float(framebuffer.width()) / float(framebuffer.height());
  glm::mat4 mvp = camera.view_projection(aspect);
  // The mesh's runs as they are (no copy, so that a frame after the first allocates nothing), or
  // one run of every index; runs past the indices (a malformed mesh) dropped, in a copy.
  const SubMesh whole{0, uint32_t(mesh.indices.size()), -1};
  std::span<const SubMesh> runs(&whole, 1);
  if (!mesh.submeshes.empty()) runs = mesh.submeshes;
  auto outside = [&](const SubMesh& run) {
    return size_t(run.first_index) + run.index_count > mesh.indices.size();
  };
  std::vector<SubMesh> valid;
  if (std::any_of(runs.begin(), runs.end(), outside)) {
    valid.assign(runs.begin(), runs.end());
    std::erase_if(valid, outside);
    runs = valid;
  }

  RenderState state = options.state;
  if (options.shader == ShaderKind::kWireframe) state.wireframe = true;
  DepthRange depth{camera.near_plane, camera.far_plane};
  if (options.shader == ShaderKind::kDepth) {
    depth = visible_depth_range(framebuffer.width(), framebuffer.height(), mesh, camera, mvp, runs,
                                state);
  }
  std::optional<detail::ShadowMap> shadow;
  if (options.shadows && options.shader == ShaderKind::kPhong) {
    shadow = detail::build_shadow_map(mesh, options.light_direction, options.shadow_map_size,
                                      options.state.threads);
  }
  if (options.shader == ShaderKind::kPbr) {
    detail::render_pbr(framebuffer, mesh, camera, mvp, runs, state, options);
  } else {
    // Opaque runs first, then (when the state is opaque, as by default) the translucent ones
    // blended over them without writing depth, in submission order.
    RenderState blended = state;
    blended.blend = BlendMode::kAlpha;
    blended.depth_write = false;
    for (bool second_pass : {false, true}) {
      for (const SubMesh& run : runs) {
        Surface surf = surface_of(mesh, run.material, options);
        bool late = state.blend == BlendMode::kOpaque && translucent(surf, options);
        if (late != second_pass) continue;
        std::span<const uint32_t> indices(mesh.indices.data() + run.first_index, run.index_count);
        draw_run(framebuffer, late ? blended : state, mesh, camera, mvp, indices, surf, options,
                 options.shader, depth, shadow ? &*shadow : nullptr);
      }
    }
  }
  draw_lines_and_points(framebuffer, state, mesh, camera, mvp, options, depth);
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
    draw_run(framebuffer, wire, mesh, camera, mvp, all, Surface{options.wire_color, nullptr, {}},
             options, ShaderKind::kWireframe, depth);
  }
}

}  // namespace softrast
