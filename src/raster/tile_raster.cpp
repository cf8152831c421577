// raster/tile_raster.cpp: the edge-equation (half-space) rasterizer. Walks 64x64 tiles, then
// 16x16 and 4x4 blocks; a block entirely inside all edges is emitted without per-pixel tests, a
// block entirely outside one edge is skipped, only the rest is tested pixel by pixel.
#include <algorithm>

#include "raster/raster.hpp"

namespace softrast::detail {
namespace {

enum class BlockTest { kOutside, kInside, kPartial };

// Classifies the samples of the size x size block at pixel (x, y) against the three edges.
// E is linear, so its extremes over the block's samples are at corner samples chosen by the
// signs of a and b; the test is exact.
BlockTest classify_block(const TriangleCoverage& tri, int x, int y, int size) {
  bool inside = true;
  int64_t span = int64_t(size - 1) * kSubpixelOne;
  int64_t sx = sample_fx8(x), sy = sample_fx8(y);
  for (const EdgeFunction& e : tri.edge) {
    int64_t corner = e.at(sx, sy);
    int64_t ax = e.a * span, by = e.b * span;
    int64_t emax = corner + std::max<int64_t>(ax, 0) + std::max<int64_t>(by, 0);
    int64_t emin = corner + std::min<int64_t>(ax, 0) + std::min<int64_t>(by, 0);
    if (emax < 0) return BlockTest::kOutside;
    if (emin < 0) inside = false;
  }
  return inside ? BlockTest::kInside : BlockTest::kPartial;
}

// Per-pixel coverage of a 4x4 block (the scalar reference the SIMD paths will be checked with).
uint32_t block_coverage(const TriangleCoverage& tri, int x, int y) {
  uint32_t mask = 0xffffu;
  for (const EdgeFunction& e : tri.edge) {
    int64_t row_start = e.at(sample_fx8(x), sample_fx8(y));
    int64_t step_x = e.a * kSubpixelOne, step_y = e.b * kSubpixelOne;
    uint32_t edge_mask = 0;
    for (int r = 0; r < 4; ++r, row_start += step_y) {
      int64_t value = row_start;
      for (int c = 0; c < 4; ++c, value += step_x) {
        if (value >= 0) edge_mask |= 1u << (4 * r + c);
      }
    }
    mask &= edge_mask;
  }
  return mask;
}

// Mask of the pixels of the 4x4 block at (x, y) that lie inside `area`.
uint32_t area_mask(const PixelRect& area, int x, int y) {
  int c0 = std::clamp(area.x0 - x, 0, 4), c1 = std::clamp(area.x1 - x, 0, 4);
  int r0 = std::clamp(area.y0 - y, 0, 4), r1 = std::clamp(area.y1 - y, 0, 4);
  if (c0 >= c1 || r0 >= r1) return 0;
  return block_rect_mask(c0, c1, r0, r1);
}

void raster_4x4(const TriangleCoverage& tri, const PixelRect& area, int x, int y, BlockTest test,
                const BlockSink& sink) {
  uint32_t mask = area_mask(area, x, y);
  if (mask == 0) return;
  if (test == BlockTest::kPartial) mask &= block_coverage(tri, x, y);
  if (mask != 0) sink(x, y, mask);
}

void raster_16x16(const TriangleCoverage& tri, const PixelRect& area, int x, int y,
                  const BlockSink& sink) {
  BlockTest test = classify_block(tri, x, y, kMidBlockSize);
  if (test == BlockTest::kOutside) return;
  for (int by = y; by < y + kMidBlockSize && by < area.y1; by += kBlockSize) {
    for (int bx = x; bx < x + kMidBlockSize && bx < area.x1; bx += kBlockSize) {
      BlockTest sub = test;
      if (test == BlockTest::kPartial) sub = classify_block(tri, bx, by, kBlockSize);
      if (sub != BlockTest::kOutside) raster_4x4(tri, area, bx, by, sub, sink);
    }
  }
}

int align_down(int v, int a) {
  return int(floor_div(v, a) * a);
}

}  // namespace

void rasterize_triangle_edge_equations(const TriangleCoverage& tri, const PixelRect& region,
                                       const BlockSink& sink) {
  PixelRect area = intersect(tri.bounds, region);
  if (area.empty()) return;
  for (int ty = align_down(area.y0, kTileSize); ty < area.y1; ty += kTileSize) {
    for (int tx = align_down(area.x0, kTileSize); tx < area.x1; tx += kTileSize) {
      int y_end = std::min(ty + kTileSize, area.y1), x_end = std::min(tx + kTileSize, area.x1);
      for (int y = std::max(ty, align_down(area.y0, kMidBlockSize)); y < y_end;
           y += kMidBlockSize) {
        for (int x = std::max(tx, align_down(area.x0, kMidBlockSize)); x < x_end;
             x += kMidBlockSize) {
          raster_16x16(tri, area, x, y, sink);
        }
      }
    }
  }
}

}  // namespace softrast::detail
