// pipeline/tile_kernels.hpp: the edge-equation rasterizer specialised for one 64x64 tile of
// binned records, with SIMD coverage of 4x4 blocks, feeding either the fragment stage directly
// (immediate) or the tile's depth resolve (deferred). One source (tile_kernel.inl) compiled for
// SSE2, AVX2 and AVX-512; the widest that simd_level() allows is picked per draw.
//
// Coverage is exactly rasterize_triangle_edge_equations' (tests/tile_kernel_test.cpp): the same
// edge functions evaluated at the same samples, exactly (int32 where fixed_point.hpp proves the
// values fit, int64 otherwise).
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/prefetch.hpp"
#include "pipeline/block_batch.hpp"
#include "pipeline/tile_visibility.hpp"
#include "pipeline/triangle_record.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::detail {

// The lines of the tile a worker draws next (its colour and depth, 16 KiB each), asked of the
// cache a pair at a time as the current tile's blocks are drawn (step), not all at once: 512
// prefetches in a row filled the line fill buffers and held the worker until they drained (7 % of
// quad_grid's frame on those instructions).
struct TilePrefetch {
  const char* color = nullptr;
  const char* depth = nullptr;
  uint32_t next = 0;  // bytes of each already asked for
  uint32_t end = 0;   // bytes of each in all (0: nothing)
  [[gnu::always_inline]] void step() {
    if (next < end) {
      prefetch_line(color + next);
      prefetch_line(depth + next);
      next += 64;
    }
  }
  // The lines not yet asked for (a tile with few blocks).
  void rest() {
    while (next < end) step();
  }
};

struct TileJob {
  PixelRect region;  // the tile's pixels inside the image
  // Immediate: blocks go to program.shade_block with `target`, or through `batch` when set.
  const FragmentProgram* program = nullptr;
  const ShadeTarget* target = nullptr;
  BlockBatch* batch = nullptr;
  // Deferred: blocks go to the depth resolve; record k of the tile gets id next_id + k and its
  // interpolants in interps[id] (sized by the caller).
  TileVisibility* visibility = nullptr;
  bool less_equal = false;
  const Interpolants** interps = nullptr;
  int32_t next_id = 0;
  // The next tile's lines, a step per block (none when null).
  TilePrefetch* prefetch = nullptr;
};

// Rasterizes `count` records of `arena` (at `offsets`, in submission order) into the tile.
using TileKernelFn = void (*)(TileJob& job, const std::byte* arena, const uint32_t* offsets,
                              size_t count);
struct TileKernels {
  TileKernelFn immediate;
  TileKernelFn deferred;         // LESS or LEQUAL as job.less_equal says
  ResolveBlockFn resolve_block;  // for blocks from another rasterizer (the scanline one)
};
TileKernels tile_kernels(SimdLevel level);

}  // namespace softrast::detail
