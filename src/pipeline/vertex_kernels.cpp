// pipeline/vertex_kernels.cpp: vertex_kernel.inl for SSE2 (2 doubles), AVX2 (4) and AVX-512 (8),
// picked at run time.
#include "pipeline/vertex_kernels.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "geometry/clip.hpp"
#include "raster/fixed_point.hpp"

namespace softrast::detail {

namespace sse2 {
#define SOFTRAST_DOUBLES 2
#include "pipeline/vertex_kernel.inl"
#undef SOFTRAST_DOUBLES
}  // namespace sse2

#pragma GCC push_options
#pragma GCC target("avx2")
#if defined(__clang__)  // clang ignores GCC target pragmas (the fuzz preset builds with it)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#endif
namespace avx2 {
#define SOFTRAST_DOUBLES 4
#include "pipeline/vertex_kernel.inl"
#undef SOFTRAST_DOUBLES
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
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC bug 105593, see tile_kernels.cpp
namespace avx512 {
#define SOFTRAST_DOUBLES 8
#include "pipeline/vertex_kernel.inl"
#undef SOFTRAST_DOUBLES
}  // namespace avx512
#pragma GCC diagnostic pop
#if defined(__clang__)
#pragma clang attribute pop
#endif
#pragma GCC pop_options

VertexKernelFn vertex_kernel(SimdLevel level) {
  switch (level) {
    case SimdLevel::kAvx512:
      return &avx512::transform_vertices;
    case SimdLevel::kAvx2:
      return &avx2::transform_vertices;
    default:
      return &sse2::transform_vertices;
  }
}

}  // namespace softrast::detail
