// softrast/renderer.hpp: the high-level API: draw a Mesh through a Camera with one of the
// built-in shaders. For your own shaders, see softrast/shader.hpp.
#pragma once

#include <memory>
#include <optional>
#include <string_view>

#include <glm/vec3.hpp>

#include "softrast/camera.hpp"
#include "softrast/debug_view.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/mesh.hpp"
#include "softrast/render_state.hpp"
#include "softrast/texture.hpp"

namespace softrast {

// The built-in shaders. flat, gouraud, texture and phong follow ../shared/bench/SCENES.md
// exactly (light direction, albedo, ambient 0.15, diffuse 0.85, specular 0.4, shininess 32).
enum class ShaderKind {
  kFlat,       // the albedo, unlit
  kGouraud,    // Lambert per vertex, colour interpolated
  kTexture,    // the texture at the interpolated uv
  kPhong,      // Blinn-Phong per pixel, albedo from the texture when there is one
  kNormals,    // debug: the normal as colour, n * 0.5 + 0.5
  kDepth,      // debug: view depth as grey on a log scale, white at the nearest visible
               // pixel, black at the farthest (the ramp spans the depth range in the image)
  kWireframe,  // triangle edges in the albedo colour, after culling
  kPbr,        // glTF metallic-roughness (PbrMaterial), sky/ground light plus the key light,
               // tone-mapped and sRGB-encoded; the default for glTF models
};
std::optional<ShaderKind> parse_shader_kind(std::string_view name);
const char* shader_kind_name(ShaderKind kind);

struct RenderOptions {
  ShaderKind shader = ShaderKind::kPhong;
  RenderState state;
  // Albedo for flat, gouraud and untextured phong when the mesh has no material of its own.
  glm::vec3 color{0.9f, 0.6f, 0.3f};
  float alpha = 1.0f;  // output alpha of every shader (times the texture's alpha)
  // Overrides the materials' diffuse maps for texture and phong when set.
  std::shared_ptr<const Texture> texture;
  Sampler sampler;
  glm::vec3 light_direction{0.3f, 0.5f, 0.8f};  // towards the light, world space; normalised
  // A point light at this world position instead of the directional light (no fall-off with
  // distance: the light's strength is light_intensity everywhere).
  std::optional<glm::vec3> light_position;
  // Which of the materials' maps phong uses: every map, or only the diffuse ones (the look of
  // a plain textured model, as OpenGL's reference renders it), or none.
  enum class Maps { kAll, kDiffuse, kNone };
  Maps maps = Maps::kAll;
  // Linear workflow: colour textures (ColorSpace::kSrgb) decoded to linear, light computed in
  // linear space, the output encoded to sRGB. Off (the default): everything read and written as
  // stored, today's images.
  bool srgb = false;
  // The lit shaders (gouraud, phong) shade albedo * (ambient + 0.85 * light_intensity * n.l)
  // plus, for phong, 0.4 * light_intensity * the Blinn-Phong highlight. SCENES.md: 0.15 and 1.
  float ambient = 0.15f;
  float light_intensity = 1.0f;
  // Back-facing triangles (drawn when state.cull is not kBack) are lit with their normal
  // flipped, so an open or single-sided surface looks the same from both sides.
  bool two_sided_lighting = true;
  // Shadows of the light (light_direction, a directional light) for the phong shader: the mesh
  // is first drawn from the light into a shadow_map_size^2 depth map fitted to its bounds; the
  // diffuse and specular terms are multiplied by the fraction of the 3x3 map texels around each
  // pixel that see it (percentage-closer filtering, with a slope-scaled depth bias).
  bool shadows = false;
  int shadow_map_size = 2048;
  // Draws the culled triangle edges over the shaded mesh as well (hidden edges stay hidden).
  bool wireframe_overlay = false;
  glm::vec3 wire_color{0.05f, 0.05f, 0.05f};
  // A picture of the pipeline's work instead of (tiles, cost: over) the shaded image. The
  // overdraw view replaces every pixel's colour; the others draw like a shader.
  DebugView debug_view = DebugView::kNone;
  // kPbr: the exposure in stops (the linear colour is scaled by 2^exposure before the tone map).
  float exposure = 0.0f;
};

// Draws `mesh` (positions in world space) seen by `camera` into `framebuffer`, which is not
// cleared first. The aspect ratio is the framebuffer's.
void render_mesh(Framebuffer& framebuffer, const Mesh& mesh, const Camera& camera,
                 const RenderOptions& options);

// The built-in demo scene: textured, lit objects on a large floor that crosses the near plane
// and the image border, and the camera to look at it with.
struct DemoScene {
  Mesh mesh;
  Camera camera;
};
DemoScene make_demo_scene();

}  // namespace softrast
