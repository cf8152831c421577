// pipeline/vertex_kernels.cpp: vertex_kernel.inl for SSE2 (2 doubles), AVX2 (4) and AVX-512 (8),
// picked at run time.
#include "pipeline/vertex_kernels.hpp"

#include "core/isa_target.hpp"

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

SOFTRAST_TARGET_BEGIN_AVX2
namespace avx2 {
#define SOFTRAST_DOUBLES 4
#include "pipeline/vertex_kernel.inl"
#undef SOFTRAST_DOUBLES
}  // namespace avx2
SOFTRAST_TARGET_END

SOFTRAST_TARGET_BEGIN_AVX512
namespace avx512 {
#define SOFTRAST_DOUBLES 8
#include "pipeline/vertex_kernel.inl"
#undef SOFTRAST_DOUBLES
}  // namespace avx512
SOFTRAST_TARGET_END

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
