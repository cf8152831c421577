// raster/raster.hpp: coverage. Turns a set-up primitive into 4x4 blocks of covered pixels.
// Reads only the setup contract (raster/setup.hpp); knows nothing of geometry or shaders.
#pragma once

#include <cstdint>

#include "raster/setup.hpp"

namespace softrast::detail {

// Pixels come out in 4x4 blocks: (x, y) is the block's top-left pixel (multiples of 4) and bit
// (4 * row + column) of the mask marks a covered pixel. Masks are never zero.
inline constexpr int kBlockSize = 4;
// Tiles are the unit of work the edge-equation rasterizer walks (and, later, binning and
// threads); a tile is split into 16x16 blocks for trivial accept/reject, then into 4x4 blocks.
inline constexpr int kTileSize = 64;
inline constexpr int kMidBlockSize = 16;

struct BlockSink {
  void (*emit)(void* context, int x, int y, uint32_t mask) = nullptr;
  void* context = nullptr;
  void operator()(int x, int y, uint32_t mask) const { emit(context, x, y, mask); }
};

// Both triangle rasterizers cover exactly the pixels whose sample (x + 0.5, y + 0.5) passes all
// three edge functions, restricted to `region` (a rectangle whose origin is a multiple of 4;
// pass the scissor, or one tile). Blocks are emitted in a rasterizer-specific order.
// (a) Edge equations: hierarchical half-space tests over 64x64 tiles, 16x16 and 4x4 blocks.
void rasterize_triangle_edge_equations(const TriangleCoverage& tri, const PixelRect& region,
                                       const BlockSink& sink);
// (b) Edge walking: the triangle split at its middle vertex into two trapezoids, each walked
// scanline by scanline along its left and right edges.
void rasterize_triangle_scanline(const TriangleCoverage& tri, const PixelRect& region,
                                 const BlockSink& sink);

// Lines by OpenGL's diamond-exit rule (with its endpoint perturbation deciding ties): the pixels
// whose diamond |x - cx| + |y - cy| < 1/2 the segment meets, except the one its end lies in, so
// connected segments (wireframe edges) never hit their shared vertex twice.
void rasterize_line(const LineSetup& line, const PixelRect& region, const BlockSink& sink);

// The mask of a block that covers columns [c0, c1) and rows [r0, r1) (all within 0..4).
inline uint32_t block_rect_mask(int c0, int c1, int r0, int r1) {
  uint32_t row = ((1u << c1) - 1u) & ~((1u << c0) - 1u);
  uint32_t mask = 0;
  for (int r = r0; r < r1; ++r) mask |= row << (4 * r);
  return mask;
}

}  // namespace softrast::detail
