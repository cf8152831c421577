// pipeline/tile_visibility.hpp: deferred shading in one 64x64 tile. Visibility is resolved first
// for all the tile's triangles in submission order (depth test and depth write into a tile-local
// copy of the depth buffer, plus the id of the winning triangle per pixel), then every visible
// pixel is shaded once, by its winner, with ShadeTarget::resolved.
//
// Why the image is the immediate path's bit for bit: with an opaque, depth-writing LESS or LEQUAL
// state and a shader that neither discards nor writes depth, a pixel's final colour is the colour
// of the last fragment that passed the depth test, and which fragments pass depends only on the
// depths, which are computed here exactly as the fragment stage computes them (same float
// operations in the same order, no contraction). So the last passing fragment of each pixel is
// the winner recorded here, and shading it alone gives the same colour; the stored depth is the
// same sequence of writes.
#pragma once

#include <cstdint>
#include <vector>

#include "raster/raster.hpp"
#include "softrast/detail/interpolants.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"

namespace softrast::detail {

// What a tile's records of one draw amount to, for worth_deferring: its pixels (inside the
// image), the area of the records' bounding boxes clipped to it, the pixels they cover in it
// (estimated: each box's share times the triangle's share of its whole box, at most a half) and
// how many there are.
struct TileLoad {
  int64_t pixels = 0;
  int64_t boxes = 0;
  double cover = 0.0;
  int64_t records = 0;
};

// Deferred shading pays for its visibility pass where triangles overlap, and where they are small
// (the visible pixels of many triangles shaded in full groups instead of each triangle's partly
// covered blocks). A tile whose boxes add up to at most kDeferredDepth times its area (one layer
// of a mesh: each triangle's box is about twice its area) is shaded immediately; so is a tile of
// large triangles (kDeferredPixels of the tile each or more, on average) that overlap little
// (covering at most kDeferredCover times its area), such as quad_grid's tiles where a few long
// triangles cross: their boxes add up to more than three tiles, yet they cover each pixel once.
// Either way gives the same image (the deferred tests compare the two bit for bit); this only
// picks the faster.
inline constexpr int64_t kDeferredDepth = 3;
inline constexpr double kDeferredCover = 1.5;
inline constexpr double kDeferredPixels = 128.0;
// Whether worth_deferring reads t.cover (boxes past kDeferredDepth tiles, and few enough records
// that their average share of the tile could reach kDeferredPixels): elsewhere its answer is the
// same whatever the cover, which need not be estimated.
inline bool cover_matters(const TileLoad& t) {
  return t.boxes > kDeferredDepth * t.pixels &&
         kDeferredPixels * double(t.records) <= kDeferredCover * double(t.pixels);
}
inline bool worth_deferring(const TileLoad& t) {
  if (t.boxes <= kDeferredDepth * t.pixels) return false;
  return t.cover > kDeferredCover * double(t.pixels) ||
         t.cover < kDeferredPixels * double(t.records);
}

// A tile's depth and winners, 4x4-block-major: block (bx, by) of the tile holds its 16 pixels in
// one 64-byte line each for depth and id (lane 4 * row + column, like the coverage masks), so the
// resolve kernels load and store whole blocks as one vector. A block's depth is copied in from the
// framebuffer the first time a triangle reaches it and written back after shading, so a tile that
// few triangles touch costs little. Between tiles every id is kNoWinner.
struct TileVisibility {
  static constexpr int kBlocksPerRow = kTileSize / kBlockSize;   // 16
  static constexpr int kBlocks = kBlocksPerRow * kBlocksPerRow;  // 256
  static constexpr int32_t kNoWinner = -1;

  TileVisibility();

  // Starts a tile: `tile_region` is the tile's pixels inside the image, origin at its corner.
  void begin(Framebuffer& fb, const PixelRect& tile_region);
  // The block of pixel (x, y), its depth loaded.
  int block(int x, int y) {
    int b = block_index(x, y);
    if (!loaded(b)) load_block(b);
    return b;
  }
  int block_index(int x, int y) const {
    return ((y - region.y0) >> 2) * kBlocksPerRow + ((x - region.x0) >> 2);
  }
  bool loaded(int b) const { return touched[b >> 6] >> (b & 63) & 1; }
  // For a caller that filled depth[b] itself (the tile kernels, with one wide store).
  void mark_loaded(int b) { touched[b >> 6] |= uint64_t(1) << (b & 63); }
  // Writes the touched blocks' depth back to the framebuffer (before shading: the resolved
  // contract says depth is already written).
  void store_depth() const;
  // Ends the tile: clears the touched blocks' ids (after shading).
  void reset();

  alignas(64) float depth[kBlocks][16];
  alignas(64) int32_t id[kBlocks][16];
  uint64_t touched[kBlocks / 64];  // blocks whose depth is loaded
  PixelRect region;
  Framebuffer* framebuffer = nullptr;

 private:
  void load_block(int b);
};

// What the resolve kernels need of a triangle: its depth plane (window space, as the fragment
// stage evaluates it) and the id recorded for the pixels it wins.
struct DepthPlaneRef {
  float x_ref, y_ref;
  DepthPlane z;
};

// Depth-tests the pixels of `mask` in the 4x4 block at pixel (x, y) of the tile against the
// tile's depth (LESS, or LEQUAL when `less_equal`), and where the test passes writes the
// fragment's depth and `id`. resolve_block_kernel() picks the widest kernel simd_level() allows.
using ResolveBlockFn = void (*)(const DepthPlaneRef& plane, int x, int y, uint32_t mask, int32_t id,
                                bool less_equal, float* depth, int32_t* ids);
ResolveBlockFn resolve_block_kernel();

// Whether a draw may take the deferred path (see the file comment for why these conditions).
inline bool deferred_shading_applies(const RenderState& state, const FragmentProgram& program) {
  return program.deferrable && state.primitive == Primitive::kTriangles && !state.wireframe &&
         state.depth_test && state.depth_write &&
         (state.depth_func == DepthFunc::kLess || state.depth_func == DepthFunc::kLessEqual) &&
         state.blend == BlendMode::kOpaque;
}

// Calls program.shade_block once per (block, winning triangle) with the mask of the pixels that
// triangle won; `interps[id]` are the interpolants of triangle `id`.
void shade_winners(const TileVisibility& vis, const Interpolants* const* interps,
                   const FragmentProgram& program, const ShadeTarget& resolved_target);

}  // namespace softrast::detail
