// raster/sample_coverage.cpp: the standard sample patterns and the per-sample coverage kernel.
#include "raster/sample_coverage.hpp"

#include "core/isa_target.hpp"

#include <algorithm>

#include "raster/raster.hpp"

// The kernel's 16-lane vectors (sample_coverage_kernel.inl) never cross a function boundary of
// this file's: GCC's note that their ABI changed with AVX-512 cannot matter.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace softrast::detail {
namespace {

// Positions in 1/16 pixel from the pixel's top-left corner, times 16 = 1/256 pixel. Vulkan's table
// (and Direct3D's, given there as offsets from the centre in 1/16 pixel: 4x is (-2,-6), (6,-2),
// (-6,2), (2,6)).
constexpr SamplePattern kPattern1{1, {128}, {128}};
constexpr SamplePattern kPattern2{2, {12 * 16, 4 * 16}, {12 * 16, 4 * 16}};
constexpr SamplePattern kPattern4{
    4, {6 * 16, 14 * 16, 2 * 16, 10 * 16}, {2 * 16, 6 * 16, 10 * 16, 14 * 16}};
constexpr SamplePattern kPattern8{
    8,
    {9 * 16, 7 * 16, 13 * 16, 5 * 16, 3 * 16, 1 * 16, 11 * 16, 15 * 16},
    {5 * 16, 11 * 16, 9 * 16, 3 * 16, 13 * 16, 7 * 16, 15 * 16, 1 * 16}};

PixelRect touched_pixels(const int32_t vx[3], const int32_t vy[3]) {
  // Pixel i is the square [256 i, 256 i + 256); every sample lies inside its pixel's square, so
  // the pixels whose square meets the bounding box hold every sample the triangle can cover.
  int64_t xmin = std::min({vx[0], vx[1], vx[2]}), xmax = std::max({vx[0], vx[1], vx[2]});
  int64_t ymin = std::min({vy[0], vy[1], vy[2]}), ymax = std::max({vy[0], vy[1], vy[2]});
  PixelRect r;
  r.x0 = int(floor_div(xmin, kSubpixelOne));
  r.x1 = int(floor_div(xmax, kSubpixelOne)) + 1;
  r.y0 = int(floor_div(ymin, kSubpixelOne));
  r.y1 = int(floor_div(ymax, kSubpixelOne)) + 1;
  return r;
}

// The pixels of the 4x4 block at (x, y) inside `area`.
uint32_t area_pixels(const PixelRect& area, int x, int y) {
  int c0 = std::clamp(area.x0 - x, 0, 4), c1 = std::clamp(area.x1 - x, 0, 4);
  int r0 = std::clamp(area.y0 - y, 0, 4), r1 = std::clamp(area.y1 - y, 0, 4);
  if (c0 >= c1 || r0 >= r1) return 0;
  return block_rect_mask(c0, c1, r0, r1);
}

// The 32-bit path. For a triangle whose vertex extents W, H are at most S = kSmallTriangleFx8, a
// block meeting the touched pixels has its samples within 5 pixels of the vertex extents (the
// bounds reach up to a pixel past them, the block 3 pixels past the bounds, a sample 1 pixel into
// its pixel), so with (xi, yi) a vertex of the edge, |px - xi| < W + 5 * 256 and likewise y:
//   |E| <= |a| |px - xi| + |b| |py - yi| + 1 < 2 S (S + 1280) + 1 < 2^31,
// and the steps across the block, (|a| + |b|) * 3 * 256, are smaller still.
static_assert(2 * kSmallTriangleFx8 * (kSmallTriangleFx8 + 5 * kSubpixelOne) + 1 <
                  (int64_t(1) << 31),
              "32-bit sample edge functions overflow");

enum class BlockTest { kOutside, kInside, kPartial };

// E is linear, so over the rectangle spanned by the block's samples its extremes lie at corners
// chosen by the signs of a and b. Samples span [256 x + min offset, 256 (x + 3) + max offset].
BlockTest classify(const SampleTriangle& tri, const SamplePattern& p, int x, int y) {
  int32_t ox0 = *std::min_element(p.x, p.x + p.count), ox1 = *std::max_element(p.x, p.x + p.count);
  int32_t oy0 = *std::min_element(p.y, p.y + p.count), oy1 = *std::max_element(p.y, p.y + p.count);
  int64_t x0 = int64_t(x) * kSubpixelOne + ox0, x1 = int64_t(x + 3) * kSubpixelOne + ox1;
  int64_t y0 = int64_t(y) * kSubpixelOne + oy0, y1 = int64_t(y + 3) * kSubpixelOne + oy1;
  bool inside = true;
  for (const EdgeFunction& e : tri.edge) {
    int64_t emax = e.at(e.a > 0 ? x1 : x0, e.b > 0 ? y1 : y0);
    int64_t emin = e.at(e.a > 0 ? x0 : x1, e.b > 0 ? y0 : y1);
    if (emax < 0) return BlockTest::kOutside;
    if (emin < 0) inside = false;
  }
  return inside ? BlockTest::kInside : BlockTest::kPartial;
}

}  // namespace

const SamplePattern* standard_sample_pattern(int count) {
  switch (count) {
    case 1:
      return &kPattern1;
    case 2:
      return &kPattern2;
    case 4:
      return &kPattern4;
    case 8:
      return &kPattern8;
    default:
      return nullptr;
  }
}

bool setup_sample_triangle(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                           int64_t area, const PixelRect& scissor, SampleTriangle& out,
                           const WindowVertex* ordered[3]) {
  bool ccw = area < 0;  // reorder to clockwise, as setup_triangle_coverage does
  ordered[0] = &v0;
  ordered[1] = ccw ? &v2 : &v1;
  ordered[2] = ccw ? &v1 : &v2;
  for (int k = 0; k < 3; ++k) {
    out.vx[k] = ordered[k]->x;
    out.vy[k] = ordered[k]->y;
  }
  out.bounds = intersect(touched_pixels(out.vx, out.vy), scissor);
  if (out.bounds.empty()) return false;
  for (int k = 0; k < 3; ++k) {
    int j = (k + 1) % 3;
    out.edge[k] = triangle_edge(out.vx[k], out.vy[k], out.vx[j], out.vy[j]);
  }
  auto extent = [](const int32_t v[3]) {
    return int64_t(std::max({v[0], v[1], v[2]})) - std::min({v[0], v[1], v[2]});
  };
  out.small = extent(out.vx) <= kSmallTriangleFx8 && extent(out.vy) <= kSmallTriangleFx8;
  return true;
}

namespace baseline {
#include "raster/sample_coverage_kernel.inl"
}  // namespace baseline

SOFTRAST_TARGET_BEGIN_AVX2
namespace avx2 {
#include "raster/sample_coverage_kernel.inl"
}  // namespace avx2
SOFTRAST_TARGET_END

SOFTRAST_TARGET_BEGIN_AVX512
namespace avx512 {
#include "raster/sample_coverage_kernel.inl"
}  // namespace avx512
SOFTRAST_TARGET_END

BlockSampleCoverageFn block_sample_coverage_kernel(SimdLevel level) {
  switch (level) {
    case SimdLevel::kAvx512:
      return &avx512::block_sample_coverage;
    case SimdLevel::kAvx2:
      return &avx2::block_sample_coverage;
    default:
      return &baseline::block_sample_coverage;
  }
}

uint32_t block_sample_coverage(const SampleTriangle& tri, const SamplePattern& pattern,
                               const PixelRect& area, int x, int y, uint8_t cov[16]) {
  return block_sample_coverage_kernel(simd_level())(tri, pattern, area, x, y, cov);
}

}  // namespace softrast::detail
