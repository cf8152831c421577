// softrast/pbr_material.hpp: glTF 2.0's metallic-roughness material, as the glTF loader fills it
// and the pbr shader (ShaderKind::kPbr) draws it. Colours are linear; the maps marked sRGB are
// decoded to linear when sampled.
#pragma once

#include <memory>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/texture.hpp"

namespace softrast {

// A texture as a material uses it: the image, its sampler, which uv set of the mesh it reads and
// KHR_texture_transform's affine map of that uv set (in softrast's uv convention, v up).
struct TextureSlot {
  std::shared_ptr<const Texture> texture;  // null: no map (the factor alone)
  Sampler sampler;
  int uv_set = 0;  // 0: Mesh::uvs, 1: Mesh::uvs1
  // uv' = (dot(u_row, (u, v, 1)), dot(v_row, (u, v, 1))); the identity unless transformed.
  glm::vec3 u_row{1.0f, 0.0f, 0.0f};
  glm::vec3 v_row{0.0f, 1.0f, 0.0f};
  bool transformed = false;
  explicit operator bool() const { return texture != nullptr; }
};

// glTF's alphaMode: OPAQUE ignores alpha; MASK discards below the cutoff and is otherwise
// opaque; BLEND blends over what is behind (drawn after the opaque surfaces, back to front).
enum class AlphaMode { kOpaque, kMask, kBlend };

struct PbrMaterial {
  glm::vec4 base_color{1.0f};  // linear RGBA factor, times the map (sRGB) and vertex colour
  TextureSlot base_color_map;
  float metallic = 1.0f;   // factor, times the map's blue channel
  float roughness = 1.0f;  // perceptual roughness factor, times the map's green channel
  TextureSlot metallic_roughness_map;
  TextureSlot normal_map;  // tangent space, MikkTSpace; needs Mesh::tangents
  float normal_scale = 1.0f;
  TextureSlot occlusion_map;  // red channel
  float occlusion_strength = 1.0f;
  glm::vec3 emissive{0.0f};  // linear, already times KHR_materials_emissive_strength
  TextureSlot emissive_map;  // sRGB
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;  // false: back faces are culled
};

}  // namespace softrast
