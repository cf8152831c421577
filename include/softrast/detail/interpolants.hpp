// softrast/detail/interpolants.hpp: the contract between triangle setup and the fragment stage:
// plane equations for depth, 1/w and varying/w, and the per-block shading entry point.
// Internal: included only through softrast/shader.hpp, the opt-in header for custom shaders.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

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

// Depth's plane, in double: on a steep or sliver triangle the terms dzdx (x - x_ref) and
// dzdy (y - y_ref) grow far beyond the depth itself, and summed in float their rounding reaches
// hundreds of units of a 24-bit depth buffer. In double the sum is exact to far below one unit,
// and only the final value is rounded to float.
struct DepthPlane {
  double a0 = 0.0;
  double dadx = 0.0;
  double dady = 0.0;
};

// Everything the fragment stage needs of one primitive. Depth is linear in window space; the
// varyings are stored divided by w, so value = plane(var) / plane(inv_w) is perspective-correct.
// `var` comes last and the fragment stage reads only var[0 .. num_varyings): a producer may keep
// a record cut short after var[num_varyings - 1] (interpolants_bytes), as the bins do.
struct Interpolants {
  float x_ref = 0.0f;
  float y_ref = 0.0f;
  DepthPlane z;
  Plane inv_w;
  int num_varyings = 0;
  bool front_facing = true;
  Plane var[kMaxVaryings];
};

// Bytes of an Interpolants record that holds `num_varyings` planes.
constexpr size_t interpolants_bytes(int num_varyings) {
  return offsetof(Interpolants, var) + sizeof(Plane) * size_t(num_varyings);
}

// Where fragments go. With `resolved`, visibility has already been decided for the block (the
// deferred path: depth test done, depth written): the mask holds exactly the pixels this
// primitive won, and the fragment stage shades them and writes their colour, nothing else.
struct ShadeTarget {
  Framebuffer* framebuffer = nullptr;
  const RenderState* state = nullptr;
  bool resolved = false;
};

// Shades one 4x4 block of pixels whose top-left pixel is (x, y), both multiples of 4; bit
// (4 * row + column) of `mask` marks the pixels covered by the primitive. The one indirect call
// the rasterizer makes per block: everything inside is the shader's inlined code.
using ShadeBlockFn = void (*)(const void* shader, const ShadeTarget& target,
                              const Interpolants& interp, int x, int y, uint32_t mask);

// A 4x4 block whose pixels several triangles of one facing cover, shaded in one call
// (ShadeMixedFn): triangle k's interpolants and its pixels, disjoint from the others'. Resolved
// (deferred tiles): the pixels each triangle won; immediate (BlockBatch): the pixels each covers.
struct MixedBlock {
  const Interpolants* winner[16];
  uint32_t mask[16];
  int count = 0;
  bool front_facing = true;
};

// Shades a MixedBlock at (x, y): each pixel interpolates its own triangle's planes, so it gets
// the bits a ShadeBlockFn call for its triangle alone would give. Only for shaders that read no
// derivatives: a 2x2 quad's pixels may belong to different triangles.
using ShadeMixedFn = void (*)(const void* shader, const ShadeTarget& target,
                              const MixedBlock& block, int x, int y);

// `deferrable`: the shader neither discards nor writes depth, so with an opaque, depth-writing
// less / less-equal state the image depends only on the nearest fragment of each pixel, and the
// pipeline may resolve visibility first and shade each visible pixel once (ShadeTarget::resolved).
struct FragmentProgram {
  ShadeBlockFn shade_block = nullptr;
  const void* shader = nullptr;
  bool deferrable = false;
  bool writes_depth = false;           // the shader sets the depth (late depth test)
  ShadeMixedFn shade_mixed = nullptr;  // deferrable shaders that read no derivatives in this draw
  // Whether deferred tiles' winners take shade_mixed too (else only immediate tiles' held blocks:
  // kCheapToShade shaders, whose deferred blocks are mostly one triangle's).
  bool mixed_winners = true;
};

// The vertex stage's output: per vertex a clip-space position (x, y, z, w) followed by
// `num_varyings` floats, `stride` floats apart.
struct ClipVertices {
  const float* data = nullptr;
  size_t count = 0;
  int stride = 4;
  int num_varyings = 0;
};

// The vertices a draw's indices name: `names` gets the distinct indices below vertex_count, in
// the order they first appear, and `renumbered` each index's place in `names` (in the order of
// `indices`; an index >= vertex_count becomes 0xffffffff, still out of range). In time linear in
// the indices (a sort made a draw of 30,000 indices cost more than shading a 120,000-vertex
// array), with a scratch array of one entry per vertex kept per thread. The vectors only grow.
void compact_draw(std::span<const uint32_t> indices, uint32_t vertex_count,
                  std::vector<uint32_t>& names, std::vector<uint32_t>& renumbered);

// Runs primitive assembly, clipping, the divide, setup, rasterization and the fragment program
// for one draw. Indices that are out of range skip their primitive.
void draw_clip_space(Framebuffer& framebuffer, const RenderState& state,
                     const ClipVertices& vertices, const uint32_t* indices, size_t index_count,
                     const FragmentProgram& program);

}  // namespace softrast::detail
