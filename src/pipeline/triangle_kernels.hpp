// pipeline/triangle_kernels.hpp: the binned draw's triangle assembly, culling and coverage setup
// in SIMD, across several triangles at once (8 at AVX2, 16 at AVX-512; the SSE levels keep the
// scalar path). One source (triangle_kernel.inl) compiled per instruction set.
//
// For each triangle of a group it finds what the scalar front end would do with it: nothing
// (an index out of range, culled, zero area, no pixel inside the scissor), the scalar path (a
// vertex outside the clip volume: clipping, or a NaN), or a set-up triangle, whose coverage it
// computes: the vertices in clockwise order, the pixel bounds inside the scissor, the edge
// functions with the fill rule and the 32-bit flag. Bit for bit what setup_triangle_coverage
// computes (tests/triangle_kernel_test.cpp): every quantity is an integer, and the products and
// sums of 16.8 coordinates are exact in double (below 2^49, fixed_point.hpp), so they are
// computed in double lanes and converted back exactly. Then the plane equations of the set-up
// triangles (setup_triangle_interpolants): the same IEEE double operations in the same order,
// lane by lane, so the same bits (the build does not fuse multiplies and adds).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/vertex_kernels.hpp"
#include "raster/setup.hpp"
#include "softrast/render_state.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::detail {

// The triangles of one draw as the kernel reads them.
struct TriangleBatch {
  const uint32_t* indices = nullptr;     // three per triangle
  size_t vertex_count = 0;               // indices at or past it skip their triangle
  const PackedVertex* window = nullptr;  // x is kOutsideVolume where the vertex code is not 0
  // Vertex i's varyings (GeometryStage::varyings): num_varyings floats at varyings + i * stride.
  const float* varyings = nullptr;
  size_t stride = 0;
  int num_varyings = 0;
  CullMode cull = CullMode::kNone;
  FrontFace front_face = FrontFace::kCounterClockwise;
  PixelRect scissor;
};

// One group's results, lane l for triangle first + l. Bit l of `ready` marks a triangle set up
// here (the arrays below hold its coverage), of `scalar` one for the scalar path; a lane in
// neither draws nothing.
struct TriangleLanes {
  static constexpr int kMaxLanes = 16;
  uint32_t ready = 0;
  uint32_t scalar = 0;
  uint32_t small = 0;                         // TriRecord::small, for ready lanes
  alignas(64) uint32_t vertex[3][kMaxLanes];  // vertex indices, clockwise
  alignas(64) int32_t x[3][kMaxLanes];        // TriangleCoverage::vx
  alignas(64) int32_t y[3][kMaxLanes];        // TriangleCoverage::vy
  alignas(64) int32_t edge_a[3][kMaxLanes];   // EdgeFunction::a (|a| < 2^24)
  alignas(64) int32_t edge_b[3][kMaxLanes];   // EdgeFunction::b
  alignas(64) int64_t edge_c[3][kMaxLanes];   // EdgeFunction::c
  alignas(64) int64_t area[kMaxLanes];        // signed_area_fx16 of the triangle as submitted
  alignas(64) int32_t bounds[4][kMaxLanes];   // x0, y0, x1, y1 (PixelRect)
  // TriRecord::blocks: a speck's coverage by block (bounds of at most 5x5 pixels), else 0.
  alignas(64) uint32_t blocks[2][kMaxLanes];  // its low and high 32 bits
  // The Interpolants of the ready lanes but those in `scalar_planes`: a vertex's 1/w is outside
  // [2^-20, 2^20], where setup rescales it (rare: a scene in tiny or huge units), and the scalar
  // setup_triangle_interpolants makes them. front_facing and num_varyings are not stored.
  uint32_t scalar_planes = 0;
  alignas(64) float x_ref[kMaxLanes];
  alignas(64) float y_ref[kMaxLanes];
  alignas(64) double z[3][kMaxLanes];                 // DepthPlane a0, dadx, dady
  alignas(64) float inv_w[3][kMaxLanes];              // Plane a0, dadx, dady
  alignas(64) float var[kMaxVaryings][3][kMaxLanes];  // var[i]'s a0, dadx, dady
};

// Sets up triangles [first, first + count) of the batch, count <= the kernel's lanes.
// Preconditions: batch.vertex_count >= 1 and 6 * vertex_count < 2^31.
using TriangleKernelFn = void (*)(const TriangleBatch& batch, size_t first, int count,
                                  TriangleLanes& out);
// The same in two steps, so that the set-up triangles of several groups can be gathered into full
// groups before the rest is made (on a dense closed mesh about 40 % of the lanes are culled or
// dropped, and the rest costs the same for a lane that is not ready): `select` finds ready,
// scalar, and for the ready lanes vertex, x, y, area and blocks (the rest is left as it was);
// `append` copies those of `from`'s lanes in `mask`, in lane order, to `to`'s lanes at, at + 1,
// ... (at + their number <= lanes) and sets them in to.ready; `finish` makes the rest for
// out.ready's lanes (bounds, small, the edges, the planes, scalar_planes). select, then finish,
// is fn; so is select, append into a group, then finish, lane for lane.
using TriangleFinishFn = void (*)(const TriangleBatch& batch, TriangleLanes& out);
using AppendLanesFn = void (*)(const TriangleLanes& from, uint32_t mask, TriangleLanes& to, int at);
struct TriangleKernel {
  TriangleKernelFn fn = nullptr;  // null at the SSE levels: the scalar path
  int lanes = 0;
  TriangleKernelFn select = nullptr;
  TriangleFinishFn finish = nullptr;
  AppendLanesFn append = nullptr;  // null where gathering does not pay (AVX2)
};
TriangleKernel triangle_kernel(SimdLevel level);

}  // namespace softrast::detail
