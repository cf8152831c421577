// The SIMD vertex kernels (pipeline/vertex_kernels.hpp) at every level this CPU has, against the
// scalar front end (GeometryStage::vertex_code and window_vertex): the same outcode and the same
// window vertex, bit for bit, for ordinary, huge, tiny, negative-w, on-plane and NaN/Inf
// vertices, odd image sizes and a depth bias; and batch ends that are not multiples of the width.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "pipeline/geometry_stage.hpp"

namespace softrast {
namespace {

std::vector<float> test_vertices(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> v;
  for (int i = 0; i < count; ++i) {
    float w = 0.1f + 3.0f * std::abs(unit(rng));
    float p[5] = {unit(rng) * 1.3f * w, unit(rng) * 1.3f * w, unit(rng) * 1.3f * w, w, unit(rng)};
    switch (i % 12) {
      case 1:
        p[0] *= 3000.0f;
        break;  // beyond the guard band
      case 2:
        p[3] = -p[3];
        break;  // behind the eye
      case 3:
        p[3] = 1e-7f;
        p[0] = p[1] = 0;
        break;  // below kMinClipW
      case 4:
        p[2] = p[3];
        break;  // on the far plane
      case 5:
        p[2] = -p[3];
        break;  // on the near plane
      case 6:
        p[i % 4] = (i % 24 < 12) ? nan : inf;
        break;
      case 7:
        p[0] = 1e30f, p[3] = 1e30f;
        break;  // huge
      case 8:
        p[1] = -inf;
        break;
      case 9:
        p[0] = p[3] * 0.999f;
        break;  // near the image edge
      default:
        break;
    }
    v.insert(v.end(), p, p + 5);
  }
  return v;
}

TEST(VertexKernel, EqualsTheScalarFrontEnd) {
  std::vector<float> data = test_vertices(4001, 17);
  detail::ClipVertices vertices{data.data(), data.size() / 5, 5, 1};
  for (int size : {1, 7, 301, 1920, 16384}) {
    for (float bias : {0.0f, -0.001f, 0.3f}) {
      RenderState state;
      state.depth_bias = bias;
      detail::GeometryStage geometry(size, size * 2 / 3 + 1, state, vertices);
      for (int level = 0; level <= int(cpu_simd_level()); ++level) {
        std::vector<uint8_t> codes(vertices.count, 0xff);
        std::vector<detail::PackedVertex> window(vertices.count);
        detail::VertexBatch batch = geometry.vertex_batch(codes.data(), window.data());
        detail::VertexKernelFn kernel = detail::vertex_kernel(SimdLevel(level));
        kernel(batch, 0, 13);  // ends that are not multiples of the vector width
        kernel(batch, 13, vertices.count);
        for (uint32_t i = 0; i < vertices.count; ++i) {
          ASSERT_EQ(codes[i], geometry.vertex_code(i))
              << simd_level_name(SimdLevel(level)) << " vertex " << i << " size " << size;
          if (codes[i] != 0) continue;
          detail::WindowVertex w = geometry.window_vertex(i);
          detail::PackedVertex expected{w.x, w.y, w.z, w.inv_w, w.x_residual, w.y_residual};
          ASSERT_EQ(std::memcmp(&window[i], &expected, sizeof(expected)), 0)
              << simd_level_name(SimdLevel(level)) << " vertex " << i << " size " << size
              << " bias " << bias << ": " << window[i].x << "," << window[i].y << "," << window[i].z
              << " vs " << w.x << "," << w.y << "," << w.z;
        }
      }
    }
  }
}

}  // namespace
}  // namespace softrast
