// raster/fixed_point.hpp: the fixed-point format of window coordinates and its bit budget.
// Everything that snaps, sets up edges or walks them uses these constants and nothing else.
#pragma once

#include <cstdint>

#include "softrast/image.hpp"

namespace softrast::detail {

// Window coordinates snap to 1/256 pixel: 16.8 fixed point in an int32.
inline constexpr int kSubpixelBits = 8;
inline constexpr int32_t kSubpixelOne = 1 << kSubpixelBits;  // one pixel
inline constexpr int32_t kSubpixelHalf = kSubpixelOne / 2;   // offset of a pixel's sample point

// The guard band: clipping in x and y only keeps window coordinates within +-kGuardBandPixels,
// so that snapped coordinates have at most 16 integer bits (plus sign). Triangles that leave the
// image but stay inside the band are not clipped; the scissor (the image) trims them instead.
// The margin of 256 pixels absorbs rounding between the clip test (in clip space) and snapping.
inline constexpr int32_t kGuardBandPixels = (1 << 15) - 256;
inline constexpr int64_t kMaxCoordFx8 = int64_t(1) << (15 + kSubpixelBits);  // |x_fx8| below this

// Bit budget of an edge function E(x, y) = a*x + b*y + c (all in 1/256 pixel):
//   |a|, |b| = |coordinate difference| < 2 * kMaxCoordFx8 = 2^24
//   |a*x|, |b*y| < 2^24 * 2^23 = 2^47, |c| = |a*x0 + b*y0| < 2^48, |E| < 2^49 (+1 for the bias)
// so int64 evaluates every edge function exactly, with 14 bits to spare.
static_assert(kMaxCoordFx8 == (int64_t(1) << 23));
static_assert((2 * kMaxCoordFx8) * kMaxCoordFx8 * 4 < (int64_t(1) << 62),
              "edge functions overflow");
// The 32-bit coverage fast path. A triangle whose vertices span at most kSmallTriangleFx8 in x
// and in y (120 pixels) has every edge function value at every sample of a 4x4 block that
// overlaps its pixel bounds within int32. With (xi, yi) either vertex of the edge,
//   E(p) = a (px - xi) + b (py - yi) (- 1 for the fill-rule bias), |a| = |dy| <= H, |b| = |dx| <= W
// where W, H <= S = kSmallTriangleFx8 are the vertex extents; a block overlapping the bounds has
// its samples within 3 pixels (768) of the extents, so |px - xi| < W + 4 * 256 and likewise y:
//   |E| < 2 S (S + 1024) + 1 = 1,950,351,361 < 2^31.
// The per-pixel offsets inside a block, |a| * 3 * 256 + |b| * 3 * 256 < 2^26, fit as well, and so
// do the block offsets of a tile's row of blocks (tile_kernel.inl), 15 * 4 * 256 * |a| < 2^29.
// Larger triangles take the exact int64 path. (The bound was 64 pixels; at 120, the larger
// triangles of a textured ground plane near the camera, quad_grid's, take the faster path too.)
inline constexpr int64_t kSmallTriangleFx8 = 120 * kSubpixelOne;
static_assert(2 * kSmallTriangleFx8 * (kSmallTriangleFx8 + 4 * kSubpixelOne) + 1 <
                  (int64_t(1) << 31),
              "32-bit edge functions overflow");

// The largest image must fit well inside the guard band (the band is at least 1.9 images wide on
// each side of the largest image, and far wider for usual sizes).
static_assert(kMaxImageSize * 19 / 10 <= kGuardBandPixels, "guard band narrower than the image");

// Floor and ceiling of a / b for b > 0 (C++ division truncates towards zero).
inline int64_t floor_div(int64_t a, int64_t b) {
  int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}
inline int64_t ceil_div(int64_t a, int64_t b) {
  int64_t q = a / b;
  return (a % b != 0 && a > 0) ? q + 1 : q;
}

}  // namespace softrast::detail
