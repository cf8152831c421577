// pipeline/vertex_kernels.hpp: the binned draw's per-vertex front end in SIMD: each vertex's clip
// outcode and, inside the clip volume, its snapped window position, several vertices at once in
// double precision. One source (vertex_kernel.inl) compiled for SSE2, AVX2 and AVX-512.
//
// Bit for bit the scalar GeometryStage::vertex_code and window_vertex (Viewport::to_window): the
// same IEEE double operations in the same order, the same rounding (the current mode, like
// std::nearbyint), the same clamps (tests/vertex_kernel_test.cpp). A vertex shared by an
// accepted triangle and a clipped one is therefore in the same place for both: watertight.
#pragma once

#include <cstddef>
#include <cstdint>

#include "softrast/simd_level.hpp"

namespace softrast::detail {

// A vertex in window space: WindowVertex without the varyings pointer. Where the vertex's code is
// not 0 (outside the clip volume, or NaN), only x is set: kOutsideVolume, which no snapped
// coordinate equals (|x| < kMaxCoordFx8), so that the triangle kernels find the triangles that
// are not trivially accepted from the positions alone.
inline constexpr int32_t kOutsideVolume = INT32_MIN;
struct PackedVertex {
  int32_t x, y;  // 1/256 pixel
  float z, inv_w;
  float x_residual, y_residual;  // WindowVertex's
};

struct VertexBatch {
  const float* data = nullptr;  // clip-space vertices (x, y, z, w, varyings...), `stride` floats
  int stride = 4;
  double guard_x = 1.0, guard_y = 1.0;  // ClipVolume
  int width = 1, height = 1;            // Viewport
  float depth_bias = 0.0f;              // RenderState::depth_bias
  uint8_t* codes = nullptr;             // out: GeometryStage::vertex_code
  PackedVertex* window = nullptr;       // out: the window vertex (PackedVertex)
};

// Transforms vertices [begin, end) of the batch.
using VertexKernelFn = void (*)(const VertexBatch& batch, size_t begin, size_t end);
VertexKernelFn vertex_kernel(SimdLevel level);

}  // namespace softrast::detail
