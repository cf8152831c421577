// softrast/detail/interpolants.hpp: the contract between triangle setup and the fragment stage:
// plane equations for depth, 1/w and varying/w, and the per-block shading entry point.
// Internal: included only through softrast/shader.hpp, the opt-in header for custom shaders.
#pragma once

#include <cstddef>
#include <cstdint>

namespace softrast {
class Framebuffer;
struct RenderState;
}  // namespace softrast

namespace softrast::detail {

// Most floats a vertex shader may pass to the fragment shader.
inline constexpr int kMaxVaryings = 16;

// a(x, y) = a0 + dadx * (x - x_ref) + dady * (y - y_ref), in window coordinates (pixels).
struct Plane {
  float a0 = 0.0f;
  float dadx = 0.0f;
  float dady = 0.0f;
};

// Everything the fragment stage needs of one primitive. Depth is linear in window space; the
// varyings are stored divided by w, so value = plane(var) / plane(inv_w) is perspective-correct.
struct Interpolants {
  float x_ref = 0.0f;
  float y_ref = 0.0f;
  Plane z;
  Plane inv_w;
  Plane var[kMaxVaryings];
  int num_varyings = 0;
  bool front_facing = true;
};

// Where fragments go.
struct ShadeTarget {
  Framebuffer* framebuffer = nullptr;
  const RenderState* state = nullptr;
};

// Shades one 4x4 block of pixels whose top-left pixel is (x, y), both multiples of 4; bit
// (4 * row + column) of `mask` marks the pixels covered by the primitive. The one indirect call
// the rasterizer makes per block: everything inside is the shader's inlined code.
using ShadeBlockFn = void (*)(const void* shader, const ShadeTarget& target,
                              const Interpolants& interp, int x, int y, uint32_t mask);

struct FragmentProgram {
  ShadeBlockFn shade_block = nullptr;
  const void* shader = nullptr;
};

// The vertex stage's output: per vertex a clip-space position (x, y, z, w) followed by
// `num_varyings` floats, `stride` floats apart.
struct ClipVertices {
  const float* data = nullptr;
  size_t count = 0;
  int stride = 4;
  int num_varyings = 0;
};

// Runs primitive assembly, clipping, the divide, setup, rasterization and the fragment program
// for one draw. Indices that are out of range skip their primitive.
void draw_clip_space(Framebuffer& framebuffer, const RenderState& state,
                     const ClipVertices& vertices, const uint32_t* indices, size_t index_count,
                     const FragmentProgram& program);

}  // namespace softrast::detail
