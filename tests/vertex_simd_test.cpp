// The wide vertex shaders of the built-in shaders (softrast/detail/vertex_simd.hpp) at every SIMD
// level this CPU has, against their scalar vertex(): the same position and varyings, bit for bit
// (or NaN where the scalar one is NaN), for consecutive vertices and for named ones (a draw over
// part of a mesh), with a short last group, ordinary, huge, tiny, zero, NaN and Inf inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shaders/builtin_shaders.hpp"
#include "softrast/simd_level.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

// A mesh whose every kind of value appears in several lanes of a group: vertex i's case is
// i % 13, so the 16 lanes of each group see a different mix.
Mesh test_mesh(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Mesh m;
  for (int i = 0; i < count; ++i) {
    glm::vec3 p(unit(rng) * 5.0f, unit(rng) * 5.0f, unit(rng) * 5.0f);
    glm::vec3 n(unit(rng), unit(rng), unit(rng));
    glm::vec2 uv(unit(rng) * 3.0f, unit(rng) * 3.0f);
    glm::vec4 t(unit(rng), unit(rng), unit(rng), i % 2 ? 1.0f : -1.0f);
    switch (i % 13) {
      case 1:
        p *= 1e30f, n *= 1e-30f;  // huge positions, tiny normals (their squares underflow)
        break;
      case 2:
        n = glm::vec3(0.0f);  // normalize(0): NaN
        break;
      case 3:
        p.y = nan, n.z = nan, uv.x = nan, t.w = nan;
        break;
      case 4:
        p.x = inf, n.x = -inf, uv.y = inf;
        break;
      case 5:
        p = glm::vec3(0.0f), n = glm::vec3(0.0f, 0.0f, 1e20f);  // its square overflows
        break;
      case 6:
        n = glm::vec3(1e-45f, 0.0f, 0.0f);  // a denormal
        break;
      default:
        break;
    }
    m.positions.push_back(p);
    m.normals.push_back(n);
    m.uvs.push_back(uv);
    m.tangents.push_back(t);
  }
  return m;
}

detail::MeshInputs test_inputs(const Mesh& mesh) {
  detail::MeshInputs in;
  in.mesh = &mesh;
  in.mvp = glm::mat4(1.3f, 0.2f, -0.4f, 0.1f,     // column 0
                     -0.3f, 1.7f, 0.25f, -0.2f,   // column 1
                     0.5f, -0.6f, -1.01f, -1.0f,  // column 2
                     0.7f, -0.9f, 4.3f, 5.0f);    // column 3
  in.uv_scale = {2.0f, -0.75f};
  in.uv_offset = {0.125f, 1.5f};
  in.position_scale = 0.25f;
  return in;
}

bool same(float a, float b) {
  if (std::isnan(a)) return std::isnan(b);
  uint32_t x, y;
  std::memcpy(&x, &a, 4);
  std::memcpy(&y, &b, 4);
  return x == y;
}

// Runs the scalar vertex() and the wide form at each level over vertices begin..end-1 (named by
// `name` when not null) and expects the same floats, including the ones around the range
// untouched.
template <class S>
void expect_same_vertices(const S& shader, const std::string& what, uint32_t mesh_vertices) {
  constexpr int kStride = 4 + S::kVaryings;
  std::mt19937 rng(7);
  std::vector<uint32_t> names(53);
  for (uint32_t& n : names) n = rng() % mesh_vertices;
  struct Range {
    const uint32_t* name;
    uint32_t begin, end;
  };
  const Range ranges[] = {{nullptr, 0, mesh_vertices},
                          {nullptr, 16, 16 + 32},
                          {nullptr, 32, 32 + 7},
                          {names.data(), 0, uint32_t(names.size())}};
  for (const Range& r : ranges) {
    const size_t floats = size_t(r.end + 16) * kStride;
    std::vector<float> want(floats, -7.0f);
    for (uint32_t k = r.begin; k < r.end; ++k) {
      float* v = want.data() + size_t(k) * kStride;
      glm::vec4 p = shader.vertex(r.name != nullptr ? r.name[k] : k, v + 4);
      v[0] = p.x, v[1] = p.y, v[2] = p.z, v[3] = p.w;
    }
    for (SimdLevel level : test::levels_of_this_cpu()) {
      std::vector<float> got(floats, -7.0f);
      detail::wide_shade_vertices<S>(level)(&shader, r.name, r.begin, r.end, got.data());
      int differ = 0;
      size_t first = 0;
      for (size_t f = 0; f < floats; ++f) {
        if (!same(want[f], got[f]) && differ++ == 0) first = f;
      }
      EXPECT_EQ(differ, 0) << what << " at " << simd_level_name(level) << ", vertices " << r.begin
                           << " to " << r.end << (r.name ? " (named)" : "") << ": first at vertex "
                           << first / kStride << " float " << first % kStride << ", " << want[first]
                           << " vs " << got[first];
    }
  }
}

TEST(WideVertexShader, BuiltInShadersMatchTheirScalarVertexBitForBit) {
  constexpr uint32_t kCount = 16 * 6 + 9;
  const Mesh mesh = test_mesh(kCount, 3);
  const detail::MeshInputs in = test_inputs(mesh);
  detail::Lighting lighting;
  lighting.light = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));

  expect_same_vertices(detail::FlatShader{in, glm::vec4(1.0f)}, "flat", kCount);
  expect_same_vertices(
      detail::GouraudShader<false>{in, glm::vec3(0.9f, 0.6f, 0.3f), lighting, 1.0f, {}}, "gouraud",
      kCount);
  expect_same_vertices(
      detail::GouraudShader<true>{in, glm::vec3(0.2f, 0.7f, 0.4f), lighting, 1.0f, {}},
      "gouraud two-sided", kCount);
  expect_same_vertices(
      detail::GouraudShader<false, true>{in, glm::vec3(0.9f, 0.6f, 0.3f), lighting, 1.0f, {}},
      "gouraud, lit colour", kCount);
  expect_same_vertices(
      detail::GouraudShader<true, true>{in, glm::vec3(0.2f, 0.7f, 0.4f), lighting, 1.0f, {}},
      "gouraud two-sided, lit colour", kCount);
  expect_same_vertices(detail::TextureShader(in), "texture", kCount);
  expect_same_vertices(detail::NormalsShader{in}, "normals", kCount);
  const detail::SurfaceMaps maps;
  const Sampler sampler;
  const glm::vec3 eye(0.0f, 0.0f, 5.0f);
  using detail::PhongInputs;
  expect_same_vertices(detail::PhongShader<PhongInputs::kPlain>(in, glm::vec3(0.5f), maps, sampler,
                                                                lighting, eye, 1.0f, {}),
                       "phong", kCount);
  expect_same_vertices(detail::PhongShader<PhongInputs::kUv>(in, glm::vec3(0.5f), maps, sampler,
                                                             lighting, eye, 1.0f, {}),
                       "phong with uv", kCount);
  expect_same_vertices(detail::PhongShader<PhongInputs::kTangentFrame>(
                           in, glm::vec3(0.5f), maps, sampler, lighting, eye, 1.0f, {}),
                       "phong with tangents", kCount);
}

// Vertex colours go through std::pow when decoded: those draws keep the scalar vertex().
TEST(WideVertexShader, VertexColoursTakeTheScalarVertexShader) {
  const Mesh mesh = test_mesh(20, 4);
  const detail::MeshInputs in = test_inputs(mesh);
  detail::GouraudShader<false, true> plain{in, glm::vec3(0.5f), {}, 1.0f, {}};
  EXPECT_TRUE(detail::uses_wide_vertices(plain));
  detail::GouraudShader<false, true> coloured = plain;
  coloured.colors.use = true;
  EXPECT_FALSE(detail::uses_wide_vertices(coloured));
  const detail::SurfaceMaps maps;
  detail::PhongShader<detail::PhongInputs::kColors> phong(in, glm::vec3(0.5f), maps, Sampler(), {},
                                                          glm::vec3(0.0f), 1.0f, {});
  EXPECT_FALSE(detail::uses_wide_vertices(phong));
}

}  // namespace
}  // namespace softrast
