// softrast/detail/shade_block.hpp: the fragment stage for one shader type, compiled into the
// caller's code: interpolation, early depth test, the shader, late depth test, blending.
// Internal: included through softrast/shader.hpp. Scalar, per 2x2 quad: the readable reference.
#pragma once

#include <algorithm>
#include <cstdint>

#include <glm/common.hpp>  // glm::clamp
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/detail/interpolants.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"

namespace softrast {

// What the fragment shader sees of one pixel.
struct FragmentInput {
  glm::vec2 position;               // window coordinates of the sample, (x + 0.5, y + 0.5)
  float depth = 0.0f;               // window depth in [0, 1]; a shader with kWritesDepth may set it
  bool front_facing = true;         // the primitive's facing (lines and points: true)
  const float* varyings = nullptr;  // the shader's kVaryings values, perspective-correct
  const float* ddx = nullptr;       // their change to the next pixel right, across the 2x2 quad
  const float* ddy = nullptr;       // their change to the next pixel down, across the 2x2 quad

  glm::vec2 vec2(int i) const { return {varyings[i], varyings[i + 1]}; }
  glm::vec3 vec3(int i) const { return {varyings[i], varyings[i + 1], varyings[i + 2]}; }
  glm::vec4 vec4(int i) const {
    return {varyings[i], varyings[i + 1], varyings[i + 2], varyings[i + 3]};
  }
};

namespace detail {

template <class S>
concept WritesDepth = requires {
  requires S::kWritesDepth;
};

inline bool depth_passes(DepthFunc f, float z, float stored) {
  switch (f) {
    case DepthFunc::kNever:
      return false;
    case DepthFunc::kLess:
      return z < stored;
    case DepthFunc::kEqual:
      return z == stored;
    case DepthFunc::kLessEqual:
      return z <= stored;
    case DepthFunc::kGreater:
      return z > stored;
    case DepthFunc::kNotEqual:
      return z != stored;
    case DepthFunc::kGreaterEqual:
      return z >= stored;
    case DepthFunc::kAlways:
      return true;
  }
  return false;
}

// Blends a shaded colour over the stored RGBA8 pixel. Source colours are clamped to [0, 1].
inline uint32_t blend_pixel(BlendMode mode, glm::vec4 src, uint32_t dst_packed) {
  if (mode == BlendMode::kOpaque) return pack_rgba8(src);
  src = glm::clamp(src, glm::vec4(0.0f), glm::vec4(1.0f));
  glm::vec4 dst = unpack_rgba8(dst_packed);
  if (mode == BlendMode::kAdditive) return pack_rgba8(src + dst);
  glm::vec4 out = src * src.a + dst * (1.0f - src.a);
  out.a = src.a + dst.a * (1.0f - src.a);
  return pack_rgba8(out);
}

inline float eval_plane(const Plane& p, float dx, float dy) {
  return p.a0 + p.dadx * dx + p.dady * dy;
}
// Depth: the plane in double, rounded to float once (interpolants.hpp).
inline float eval_plane(const DepthPlane& p, float dx, float dy) {
  return float(p.a0 + p.dadx * double(dx) + p.dady * double(dy));
}

// Shades the pixels of `quad_mask` (bit k = pixel (k & 1, k >> 1)) of the 2x2 quad at (x, y).
// All four pixels are interpolated so that the shader gets derivatives, as GPUs do with helper
// pixels.
// kCommon compiles the state most draws use (depth test less with writes, opaque, no shader
// depth) with every branch on the state resolved at compile time.
template <class S, bool kCommon>
void shade_quad(const S& shader, const ShadeTarget& target, const Interpolants& in, int x, int y,
                uint32_t quad_mask) {
  constexpr int kN = S::kVaryings > 0 ? S::kVaryings : 1;
  constexpr bool kLateDepth = WritesDepth<S>;
  Framebuffer& fb = *target.framebuffer;
  const RenderState& st = *target.state;
  const bool depth_test = kCommon || st.depth_test;
  const DepthFunc depth_func = kCommon ? DepthFunc::kLess : st.depth_func;
  const bool depth_write = kCommon || st.depth_write;
  const BlendMode blend = kCommon ? BlendMode::kOpaque : st.blend;

  float dx[4], dy[4], z[4];
  for (int k = 0; k < 4; ++k) {
    dx[k] = float(x + (k & 1)) + 0.5f - in.x_ref;
    dy[k] = float(y + (k >> 1)) + 0.5f - in.y_ref;
    z[k] = std::clamp(eval_plane(in.z, dx[k], dy[k]), 0.0f, 1.0f);
  }
  if (!kLateDepth && depth_test) {  // early depth test: the shader cannot change depth
    for (int k = 0; k < 4; ++k) {
      if ((quad_mask >> k & 1) &&
          !depth_passes(depth_func, z[k], fb.depth_at(x + (k & 1), y + (k >> 1)))) {
        quad_mask &= ~(1u << k);
      }
    }
    if (quad_mask == 0) return;
  }

  float var[4][kN];
  for (int k = 0; k < 4; ++k) {
    // Helper pixels outside the primitive extrapolate, past the horizon too, where 1/w is
    // negative: the varyings there are the projective continuation (what GPUs and llvmpipe
    // compute), which keeps derivatives finite. Only a 1/w too close to 0 to divide by is moved.
    float inv_w = eval_plane(in.inv_w, dx[k], dy[k]);
    if (inv_w < 1.0e-30f && inv_w > -1.0e-30f) inv_w = 1.0e-30f;
    float w = 1.0f / inv_w;
    for (int i = 0; i < S::kVaryings; ++i) var[k][i] = eval_plane(in.var[i], dx[k], dy[k]) * w;
  }
  float ddx[kN], ddy[kN];
  for (int i = 0; i < S::kVaryings; ++i) {
    ddx[i] = var[1][i] - var[0][i];
    ddy[i] = var[2][i] - var[0][i];
  }

  for (int k = 0; k < 4; ++k) {
    if (!(quad_mask >> k & 1)) continue;
    int px = x + (k & 1), py = y + (k >> 1);
    FragmentInput fi;
    fi.position = {float(px) + 0.5f, float(py) + 0.5f};
    fi.depth = z[k];
    fi.front_facing = in.front_facing;
    fi.varyings = var[k];
    fi.ddx = ddx;
    fi.ddy = ddy;
    glm::vec4 color;
    if (!shader.fragment(fi, color)) continue;  // discarded
    float* depth = fb.depth_pixel(px, py);
    if (kLateDepth) {
      fi.depth = std::clamp(fi.depth, 0.0f, 1.0f);
      if (!(fi.depth >= 0.0f)) fi.depth = 0.0f;  // NaN
      if (depth_test && !depth_passes(depth_func, fi.depth, *depth)) continue;
    }
    if (depth_test && depth_write) *depth = fi.depth;
    uint32_t* pixel = fb.color_pixel(px, py);
    *pixel = blend == BlendMode::kOpaque ? pack_rgba8(color) : blend_pixel(blend, color, *pixel);
  }
}

// The ShadeBlockFn for shader type S: splits the 4x4 block into its four 2x2 quads.
template <class S>
void shade_block(const void* shader, const ShadeTarget& target, const Interpolants& interp, int x,
                 int y, uint32_t mask) {
  const S& s = *static_cast<const S*>(shader);
  const RenderState& st = *target.state;
  bool common = !WritesDepth<S> && st.depth_test && st.depth_func == DepthFunc::kLess &&
                st.depth_write && st.blend == BlendMode::kOpaque;
  for (int q = 0; q < 4; ++q) {
    int qx = (q & 1) * 2, qy = (q >> 1) * 2;
    uint32_t row0 = (mask >> (4 * qy + qx)) & 3u;
    uint32_t row1 = (mask >> (4 * (qy + 1) + qx)) & 3u;
    uint32_t quad_mask = row0 | row1 << 2;
    if (!quad_mask) continue;
    if (common) {
      shade_quad<S, true>(s, target, interp, x + qx, y + qy, quad_mask);
    } else {
      shade_quad<S, false>(s, target, interp, x + qx, y + qy, quad_mask);
    }
  }
}

}  // namespace detail
}  // namespace softrast
