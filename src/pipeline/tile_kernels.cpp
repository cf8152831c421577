// pipeline/tile_kernels.cpp: tile_kernel.inl compiled three times, for the x86-64 baseline
// (SSE2, 4 lanes), AVX2 (8 lanes) and AVX-512 F/BW/DQ/VL (16 lanes); the choice is made at run
// time from simd_level(), so the binary runs on any x86-64.
#include "pipeline/tile_kernels.hpp"

#include "core/isa_target.hpp"
#include "core/prefetch.hpp"
#include "core/store_mode.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <utility>

namespace softrast::detail {

namespace sse2 {
#define SOFTRAST_LANES 4
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace sse2

SOFTRAST_TARGET_BEGIN_AVX2
namespace avx2 {
#define SOFTRAST_LANES 8
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace avx2
SOFTRAST_TARGET_END

SOFTRAST_TARGET_BEGIN_AVX512
namespace avx512 {
#define SOFTRAST_LANES 16
#include "pipeline/tile_kernel.inl"
#undef SOFTRAST_LANES
}  // namespace avx512
SOFTRAST_TARGET_END

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
