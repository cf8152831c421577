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
      case 1: p[0] *= 3000.0f; break;             // beyond the guard band
      case 2: p[3] = -p[3]; break;                // behind the eye
      case 3: p[3] = 1e-7f; p[0] = p[1] = 0; break;  // below kMinClipW
      case 4: p[2] = p[3]; break;                 // on the far plane
      case 5: p[2] = -p[3]; break;                // on the near plane
      case 6: p[i % 4] = (i % 24 < 12) ? nan : inf; break;
      case 7: p[0] = 1e30f, p[3] = 1e30f; break;  // huge
      case 8: p[1] = -inf; break;
      case 9: p[0] = p[3] * 0.999f; break;        // near the image edge
      default: break;
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
          detail::PackedVertex expected{w.x, w.y, w.z, w.inv_w};
          ASSERT_EQ(std::memcmp(&window[i], &expected, sizeof(expected)), 0)
              << simd_level_name(SimdLevel(level)) << " vertex " << i << " size " << size
              << " bias " << bias << ": " << window[i].x << "," << window[i].y << ","
              << window[i].z << " vs " << w.x << "," << w.y << "," << w.z;
        }
      }
    }
  }
}

// The plane kernels against setup_triangle's scalar planes: the same Interpolants, bit for bit,
// for every varying count, both windings and facings, tiny and huge triangles.
TEST(VertexKernel, PlanesEqualTheScalarSetup) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int32_t> coord(-(1 << 22), 1 << 22), near(-2000, 2000);
  std::vector<float> varyings(3 * detail::kMaxVaryings);
  for (int i = 0; i < 3000; ++i) {
    int num_varyings = i % (detail::kMaxVaryings + 1);
    detail::WindowVertex v[3];
    for (int k = 0; k < 3; ++k) {
      v[k].x = i % 2 ? coord(rng) : near(rng);
      v[k].y = i % 2 ? coord(rng) : near(rng);
      v[k].z = std::abs(unit(rng));
      v[k].inv_w = 0.01f + std::abs(unit(rng)) * (i % 3 ? 1.0f : 1e5f);
      v[k].varyings = &varyings[size_t(k) * detail::kMaxVaryings];
    }
    for (float& f : varyings) f = unit(rng) * (i % 5 ? 1.0f : 1e6f);
    FrontFace face = i % 4 < 2 ? FrontFace::kCounterClockwise : FrontFace::kClockwise;
    detail::TriangleSetup tri;
    if (!detail::setup_triangle(v[0], v[1], v[2], num_varyings, CullMode::kNone, face,
                                {-(1 << 23), -(1 << 23), 1 << 23, 1 << 23}, tri)) {
      continue;
    }
    const detail::WindowVertex* ordered[3];
    int64_t area = detail::signed_area_fx16(v[0], v[1], v[2]);
    detail::TriangleCoverage coverage;
    ASSERT_TRUE(detail::setup_triangle_coverage(v[0], v[1], v[2], area,
                                                {-(1 << 23), -(1 << 23), 1 << 23, 1 << 23},
                                                coverage, ordered));
    for (int level = 0; level <= int(cpu_simd_level()); ++level) {
      detail::Interpolants wide;
      detail::plane_kernel(SimdLevel(level))(ordered, num_varyings, area, face, wide);
      const detail::Interpolants& scalar = tri.interp;
      auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; };
      bool equal = same(wide.x_ref, scalar.x_ref) && same(wide.y_ref, scalar.y_ref) &&
                   same(wide.z, scalar.z) && same(wide.inv_w, scalar.inv_w) &&
                   wide.num_varyings == scalar.num_varyings &&
                   wide.front_facing == scalar.front_facing &&
                   std::memcmp(wide.var, scalar.var, sizeof(detail::Plane) * num_varyings) == 0;
      ASSERT_TRUE(equal) << simd_level_name(SimdLevel(level)) << " triangle " << i;
    }
  }
}

}  // namespace
}  // namespace softrast
