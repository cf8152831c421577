// shaders/shadow_map.cpp: the depth pass from the light.
#include "shaders/shadow_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/unit_scale.hpp"
#include "shaders/builtin_shaders.hpp"
#include "softrast/framebuffer.hpp"

namespace softrast::detail {
namespace {

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  bool empty() const { return !(lo.x <= hi.x); }
};

Box bounds_of(const Mesh& mesh) {
  Box b;
  for (const glm::vec3& p : mesh.positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}

}  // namespace

ShadowMap build_shadow_map(const Mesh& mesh, glm::vec3 towards_light, int size, int threads) {
  ShadowMap map;
  map.size = size;
  map.depth.assign(size_t(size) * size_t(size), 1.0f);
  Box box = bounds_of(mesh);
  glm::vec3 l = glm::normalize(towards_light);
  if (box.empty() || !std::isfinite(l.x + l.y + l.z)) {
    map.light_vp = glm::mat4(0.0f);  // every point maps to the centre at depth 0.5: lit
    return map;
  }
  // The map is fitted in units where the box's largest coordinate is in [0.5, 1) when it lies
  // outside 2^-20 .. 2^20 (a model in units of 1e30 or 1e-30: the box's diagonal squared
  // overflowed float, or the floors below were larger than the model). The units are a power of
  // two times the world's, so the fit is exact, and light_vp takes world positions: the scale is
  // its first step.
  float largest = std::max({std::abs(box.lo.x), std::abs(box.lo.y), std::abs(box.lo.z),
                            std::abs(box.hi.x), std::abs(box.hi.y), std::abs(box.hi.z)});
  float unit = 1.0f;
  if (std::isfinite(largest) && largest > 0.0f && (largest > 0x1p20f || largest < 0x1p-20f)) {
    unit = unit_scale(largest);
    box.lo *= unit;
    box.hi *= unit;
  }
  // A view from the light towards the box's centre, then the orthographic box that holds the
  // eight corners exactly (with a small margin in depth, so the nearest and farthest surfaces
  // are not clipped).
  glm::vec3 centre = (box.lo + box.hi) * 0.5f;
  float radius = std::max(glm::length(box.hi - box.lo) * 0.5f, 1.0e-6f);
  glm::vec3 up = std::abs(l.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  glm::mat4 view = glm::lookAtRH(centre + l * (2.0f * radius), centre, up);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (int k = 0; k < 8; ++k) {
    glm::vec3 corner((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y,
                     (k & 4) ? box.hi.z : box.lo.z);
    glm::vec3 v = glm::vec3(view * glm::vec4(corner, 1.0f));
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  float margin = radius * 0.01f;
  float near_plane = -hi.z - margin, far_plane = -lo.z + margin;
  float w = std::max(hi.x - lo.x, 1.0e-6f), h = std::max(hi.y - lo.y, 1.0e-6f);
  glm::mat4 proj = glm::orthoRH_NO(lo.x, lo.x + w, lo.y, lo.y + h, near_plane, far_plane);
  map.light_vp = proj * view;
  if (unit != 1.0f) map.light_vp = map.light_vp * glm::scale(glm::mat4(1.0f), glm::vec3(unit));
  map.texel_depth = std::max(w, h) / float(size) / (far_plane - near_plane);

  Framebuffer fb(size, size);
  fb.clear(glm::vec4(0.0f), 1.0f, threads);
  RenderState state;
  state.cull = CullMode::kNone;  // both faces cast shadows: open meshes too
  state.threads = threads;
  FlatShader shader{{&mesh, map.light_vp}, glm::vec4(1.0f)};
  draw(fb, state, shader, mesh.indices, uint32_t(mesh.positions.size()));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x)
      map.depth[size_t(y) * size_t(size) + size_t(x)] = fb.depth_at(x, y);
  }
  return map;
}

}  // namespace softrast::detail
