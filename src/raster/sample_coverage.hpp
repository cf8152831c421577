// raster/sample_coverage.hpp: coverage per sample for multisampling. The same edge functions and
// fill rule as the single-sampled rasterizers (setup.hpp), tested at 2, 4 or 8 sample positions
// inside each pixel instead of its centre.
#pragma once

#include <cstdint>

#include "raster/setup.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::detail {

inline constexpr int kMaxSamples = 8;

// Sample positions inside the pixel, in 1/256 pixel from its top-left corner (y down): the
// standard sample locations of the Vulkan specification (Multisampling, "standard sample
// locations"), which are Direct3D's standard patterns. All are multiples of 1/16 pixel, so they
// lie exactly on the 1/256 grid of the snapped vertices and the edge functions stay exact.
struct SamplePattern {
  int count = 1;
  int32_t x[kMaxSamples] = {};
  int32_t y[kMaxSamples] = {};
};
// The pattern for 1, 2, 4 or 8 samples (1: the pixel centre); nullptr for any other count.
const SamplePattern* standard_sample_pattern(int count);

// A triangle as the multisample rasterizer reads it: the clockwise vertices and their edge
// functions (the fill rule folded in, as setup_triangle makes them), and the pixels whose square
// touches the triangle's bounding box, inside the scissor. Unlike TriangleCoverage::bounds it
// includes pixels whose centre lies outside the triangle but one of whose samples may not.
struct SampleTriangle {
  int32_t vx[3] = {0, 0, 0};
  int32_t vy[3] = {0, 0, 0};
  EdgeFunction edge[3];
  PixelRect bounds;
  // Vertex extents of at most kSmallTriangleFx8 (120 pixels) in x and y: every edge function value
  // at the samples of a block that meets `bounds` fits in int32 (sample_coverage.cpp).
  bool small = false;
};

// Sets up the coverage of the triangle whose snapped signed area (signed_area_fx16) is `area`
// (non-zero): reorders the vertices clockwise into `ordered` (as setup_triangle_coverage does, so
// setup_triangle_interpolants can follow) and makes the edges. False when it touches no pixel of
// `scissor`.
bool setup_sample_triangle(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                           int64_t area, const PixelRect& scissor, SampleTriangle& out,
                           const WindowVertex* ordered[3]);

// Coverage of the 4x4 block whose top-left pixel is (x, y): bit s of cov[4 * row + column] is set
// when sample s of that pixel passes all three edge functions and the pixel lies in `area`.
// Exact (int64) for any triangle inside the guard band. Returns the mask of pixels with at least
// one covered sample (bit 4 * row + column), 0 when none.
uint32_t block_sample_coverage(const SampleTriangle& tri, const SamplePattern& pattern,
                               const PixelRect& area, int x, int y, uint8_t cov[16]);
// The same, compiled for one SIMD level (the same results at every level): for a caller that
// picks it once per draw.
using BlockSampleCoverageFn = uint32_t (*)(const SampleTriangle& tri, const SamplePattern& pattern,
                                           const PixelRect& area, int x, int y, uint8_t cov[16]);
BlockSampleCoverageFn block_sample_coverage_kernel(SimdLevel level);

}  // namespace softrast::detail
