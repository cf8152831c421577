// pipeline/triangle_kernels.cpp: triangle_kernel.inl for AVX2 (8 triangles) and AVX-512 (16),
// picked at run time.
#include "pipeline/triangle_kernels.hpp"

#include "core/isa_target.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "raster/fixed_point.hpp"
#include "softrast/simd.hpp"

namespace softrast::detail {

SOFTRAST_TARGET_BEGIN_AVX2
namespace avx2 {
#define SOFTRAST_TRIANGLE_LANES 8
#include "pipeline/triangle_kernel.inl"
#undef SOFTRAST_TRIANGLE_LANES
}  // namespace avx2
SOFTRAST_TARGET_END

SOFTRAST_TARGET_BEGIN_AVX512
namespace avx512 {
#define SOFTRAST_TRIANGLE_LANES 16
#include "pipeline/triangle_kernel.inl"
#undef SOFTRAST_TRIANGLE_LANES
}  // namespace avx512
SOFTRAST_TARGET_END

TriangleKernel triangle_kernel(SimdLevel level) {
  switch (level) {
    case SimdLevel::kAvx512:
      return {&avx512::setup_triangles, 16, &avx512::select_triangles, &avx512::finish_triangles,
              &avx512::append_lanes};
    case SimdLevel::kAvx2:
      return {&avx2::setup_triangles, 8, &avx2::select_triangles, &avx2::finish_triangles, nullptr};
    default:
      return {};
  }
}

}  // namespace softrast::detail
