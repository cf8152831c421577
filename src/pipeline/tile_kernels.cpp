// pipeline/tile_kernels.cpp: tile_kernel.inl compiled three times, for the x86-64 baseline
// (SSE2, 4 lanes), AVX2 (8 lanes) and AVX-512 F/BW/DQ/VL (16 lanes); the choice is made at run
// time from simd_level(), so the binary runs on any x86-64.
#include "pipeline/tile_kernels.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cstring>

namespace softrast::detail {

namespace sse2 {
#define SOFTRAST_LANES 4
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace sse2

#pragma GCC push_options
#pragma GCC target("avx2")
#if defined(__clang__)  // clang ignores GCC target pragmas (the fuzz preset builds with it)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#endif
namespace avx2 {
#define SOFTRAST_LANES 8
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#endif
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f,avx512bw,avx512dq,avx512vl")
#if defined(__clang__)  // clang ignores GCC target pragmas (the fuzz preset builds with it)
#pragma clang attribute push(__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))), \
                             apply_to = function)
#endif
// GCC 12's _mm512_undefined_ps initialises a variable with itself and -Wmaybe-uninitialized
// reports it inside every AVX-512 min/max (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
namespace avx512 {
#define SOFTRAST_LANES 16
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace avx512
#pragma GCC diagnostic pop
#if defined(__clang__)
#pragma clang attribute pop
#endif
#pragma GCC pop_options

TileKernels tile_kernels(SimdLevel level) {
  switch (level) {
    case SimdLevel::kAvx512:
      return {&avx512::raster_immediate, &avx512::raster_deferred, &avx512::resolve_block};
    case SimdLevel::kAvx2:
      return {&avx2::raster_immediate, &avx2::raster_deferred, &avx2::resolve_block};
    default:  // SSE4 adds nothing these kernels use
      return {&sse2::raster_immediate, &sse2::raster_deferred, &sse2::resolve_block};
  }
}

ResolveBlockFn resolve_block_kernel() {
  return tile_kernels(simd_level()).resolve_block;
}

}  // namespace softrast::detail
