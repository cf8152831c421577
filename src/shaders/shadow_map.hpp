// shaders/shadow_map.hpp: shadows of a directional light. A depth pass from the light over the
// scene's bounds (drawn with the library's own pipeline) and the lookup the lit shaders multiply
// into their diffuse and specular terms: percentage-closer filtering over 3x3 texels with a
// slope-scaled bias.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "softrast/mesh.hpp"
#include "softrast/render_state.hpp"
#include "softrast/simd.hpp"

namespace softrast::detail {

// The light's depth image: window depth (0 nearest the light) of the nearest surface per texel,
// seen through an orthographic projection fitted to the scene's bounding box.
struct ShadowMap {
  int size = 0;              // texels per side
  std::vector<float> depth;  // size * size, row 0 at the top, 1 where nothing was drawn
  glm::mat4 light_vp{1.0f};  // world -> the light's clip space (orthographic, w = 1)
  float texel_depth = 0.0f;  // a texel's world size in window-depth units
  // Bias in texels' worth of depth: kConstantBias + kSlopeBias * tan(angle of incidence). The
  // slope term covers the depth change of a surface across the 3x3 filter (the farthest tap's
  // centre is 1.5 texels from the receiver) plus the half texel between the receiver and the
  // centre its depth was sampled at; the constant covers float rounding of both depths.
  static constexpr float kConstantBias = 1.0f;
  static constexpr float kSlopeBias = 2.5f;
  static constexpr float kMaxSlope =
      10.0f;  // tan of about 84 degrees: grazing light is unlit anyway
};

// Draws `mesh` (both faces) from the direction `towards_light` into a size x size depth image.
ShadowMap build_shadow_map(const Mesh& mesh, glm::vec3 towards_light, int size, int threads);

// Visibility of the light, 0 (in shadow) to 1 (lit), of the surface at world position p whose
// normal makes cos_incidence = n.l with the direction towards the light: the fraction of the 3x3
// texels around p's texel whose stored depth is not nearer than p's depth minus the bias.
// Points outside the map are lit.
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> shadow_visibility(const ShadowMap& map, const simd::Vec3<N>& p,
                                                      const simd::Float<N>& cos_incidence) {
  using F = simd::Float<N>;
  const glm::mat4& m = map.light_vp;
  F cx = F(m[0][0]) * p.x + F(m[1][0]) * p.y + F(m[2][0]) * p.z + F(m[3][0]);
  F cy = F(m[0][1]) * p.x + F(m[1][1]) * p.y + F(m[2][1]) * p.z + F(m[3][1]);
  F cz = F(m[0][2]) * p.x + F(m[1][2]) * p.y + F(m[2][2]) * p.z + F(m[3][2]);
  const F half(0.5f), size(float(map.size));
  F u = (cx * half + half) * size;  // texel units, x right
  F v = (half - cy * half) * size;  // y down, as the viewport maps it
  F c = simd::clamp(cos_incidence, F(0.05f), F(1.0f));
  F tan = simd::min(simd::sqrt(F(1.0f) - c * c) / c, F(ShadowMap::kMaxSlope));
  F ref = cz * half + half -
          F(map.texel_depth) * (F(ShadowMap::kConstantBias) + F(ShadowMap::kSlopeBias) * tan);
  const float limit = float(map.size);
  float us[simd::kLanes], vs[simd::kLanes], rs[simd::kLanes], out[simd::kLanes];
  u.store(us);
  v.store(vs);
  ref.store(rs);
  for (int i = 0; i < simd::kLanes; ++i) {
    out[i] = 1.0f;
    if (!(us[i] >= 0.0f && us[i] < limit && vs[i] >= 0.0f && vs[i] < limit)) {
      continue;  // outside the map (or NaN): lit
    }
    int tx = int(us[i]), ty = int(vs[i]), lit = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      const float* row =
          &map.depth[size_t(std::clamp(ty + dy, 0, map.size - 1)) * size_t(map.size)];
      for (int dx = -1; dx <= 1; ++dx) lit += rs[i] <= row[std::clamp(tx + dx, 0, map.size - 1)];
    }
    out[i] = float(lit) * (1.0f / 9.0f);
  }
  return F::load(out);
}

}  // namespace softrast::detail
