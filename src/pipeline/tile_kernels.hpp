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

#include "pipeline/block_batch.hpp"
#include "pipeline/tile_visibility.hpp"
#include "pipeline/triangle_record.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::detail {

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
