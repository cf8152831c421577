// SIMD levels: every level this CPU has renders the golden scenes with identical coverage and
// depth and colours within 1/255 of each other; the wide sampler and the wide operations give
// the scalar reference's bits at every level.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shaders/builtin_shaders.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

// Restores the level cap when a test ends, whatever it set.
class SimdLevelGuard {
 public:
  ~SimdLevelGuard() { set_simd_level(SimdLevel::kAvx512); }
};

// Restores the gather mode a test changed (the one chosen for this CPU).
class GatherModeGuard {
 public:
  ~GatherModeGuard() { set_gather_mode(saved_); }

 private:
  GatherMode saved_ = gather_mode(cpu_simd_level());
};

struct Rendered {
  Image image;
  std::vector<float> depth;
};

Rendered render_demo_at(SimdLevel level, const RenderOptions& options) {
  static const DemoScene scene = make_demo_scene();
  set_simd_level(level);
  EXPECT_EQ(simd_level(), level);
  Framebuffer fb(320, 240);
  render_mesh(fb, scene.mesh, scene.camera, options);
  Rendered r{fb.to_image(), {}};
  r.depth = fb.depth_values();
  return r;
}

TEST(SimdLevel, NamesRoundTripAndCapIsHonoured) {
  SimdLevelGuard guard;
  for (SimdLevel level : test::levels_of_this_cpu()) {
    EXPECT_EQ(parse_simd_level(simd_level_name(level)), level);
    set_simd_level(level);
    EXPECT_EQ(simd_level(), level);
  }
  EXPECT_FALSE(parse_simd_level("avx1024").has_value());
  set_simd_level(SimdLevel::kAvx512);
  EXPECT_EQ(simd_level(), cpu_simd_level());  // the cap never raises the level past the CPU
}

class SimdLevelGolden : public ::testing::TestWithParam<ShaderKind> {};

TEST_P(SimdLevelGolden, EveryLevelGivesTheSameCoverageAndColoursWithinOne) {
  SimdLevelGuard guard;
  RenderOptions options;
  options.shader = GetParam();
  std::vector<SimdLevel> levels = test::levels_of_this_cpu();
  Rendered widest = render_demo_at(levels.back(), options);
  for (SimdLevel level : levels) {
    Rendered r = render_demo_at(level, options);
    ASSERT_EQ(r.depth.size(), widest.depth.size());
    int depth_differs = 0, colour_out = 0;
    for (size_t i = 0; i < r.depth.size(); ++i) {
      depth_differs += r.depth[i] != widest.depth[i];  // depth is written exactly where covered
    }
    for (size_t i = 0; i < r.image.rgba.size(); ++i) {
      colour_out += std::abs(int(r.image.rgba[i]) - int(widest.image.rgba[i])) > 1;
    }
    EXPECT_EQ(depth_differs, 0) << simd_level_name(level) << " vs "
                                << simd_level_name(levels.back());
    EXPECT_EQ(colour_out, 0) << simd_level_name(level) << " vs " << simd_level_name(levels.back());
  }
}

INSTANTIATE_TEST_SUITE_P(AllShaders, SimdLevelGolden,
                         ::testing::Values(ShaderKind::kFlat, ShaderKind::kGouraud,
                                           ShaderKind::kTexture, ShaderKind::kPhong,
                                           ShaderKind::kNormals, ShaderKind::kDepth,
                                           ShaderKind::kWireframe),
                         [](const auto& info) {
                           return std::string(shader_kind_name(info.param));
                         });

// The built-in Gouraud shader's blocks of several small triangles: at AVX-512 they are shaded in
// one call, each lane with its own triangle's planes (shade_mixed, kCheapToShade), below it one
// call per triangle. Either way every pixel gets the bits of the reference path (one triangle at
// a time, no tiles), at every level, for one-sided and two-sided lighting (culling off: both
// facings, never mixed in one call) and for one and two threads. At 96 x 72 the demo scene's
// sphere and torus are triangles of a few pixels, whose blocks several of them share.
TEST(SimdLevel, GouraudOfSmallTrianglesEqualsTheReferencePathAtEveryLevel) {
  SimdLevelGuard guard;
  static const DemoScene scene = make_demo_scene();
  for (SimdLevel level : test::levels_of_this_cpu()) {
    set_simd_level(level);
    for (bool two_sided : {false, true}) {
      RenderOptions options;
      options.shader = ShaderKind::kGouraud;
      options.two_sided_lighting = two_sided;
      options.state.cull = two_sided ? CullMode::kNone : CullMode::kBack;
      std::vector<Image> images;
      for (int threads : {0, 1, 2}) {  // 0: the reference path
        options.state.threads = threads;
        options.state.reference_path = threads == 0;
        Framebuffer fb(96, 72);
        render_mesh(fb, scene.mesh, scene.camera, options);
        images.push_back(fb.to_image());
      }
      for (size_t i = 1; i < images.size(); ++i) {
        EXPECT_TRUE(images[i].rgba == images[0].rgba)
            << simd_level_name(level) << (two_sided ? " two-sided" : " one-sided") << ", " << i
            << " thread(s)";
      }
    }
  }
}

// The built-in Gouraud shader interpolates the light's intensity alone where the albedo is the
// material's (one varying a face), and the lit colour where each vertex has its own albedo
// (three): the same colours up to the rounding of one product. Drawn both ways over the demo
// scene at every level, with one thread and two: one-sided, and two-sided with each winding as
// the front (culling off; the scene's closed meshes show the faces the other winding makes
// back faces): the same depth everywhere, no channel more than 1 apart, and the scene lit.
TEST(SimdLevel, GouraudByIntensityGivesTheLitColourWithinOne) {
  SimdLevelGuard guard;
  static const DemoScene scene = make_demo_scene();
  constexpr int kWidth = 160, kHeight = 120;
  detail::Lighting lighting;
  lighting.light = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
  const glm::vec3 albedo(0.8f, 0.55f, 0.3f);
  const detail::MeshInputs in{&scene.mesh,
                              scene.camera.view_projection(float(kWidth) / float(kHeight))};
  const auto vertices = uint32_t(scene.mesh.positions.size());
  struct Drawn {
    Image image;
    std::vector<float> depth;
  };
  auto drawn = [&](const auto& shader, int threads, FrontFace front) {
    RenderState state;
    state.cull = CullMode::kNone;
    state.front_face = front;
    state.threads = threads;
    Framebuffer fb(kWidth, kHeight);
    fb.clear(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    draw(fb, state, shader, scene.mesh.indices, vertices);
    return Drawn{fb.to_image(), fb.depth_values()};
  };
  auto expect_within_one = [&](const Drawn& a, const Drawn& b, const std::string& where) {
    EXPECT_TRUE(a.depth == b.depth) << where;
    int apart = 0, lit = 0;
    for (size_t i = 0; i < a.image.rgba.size(); ++i) {
      apart += std::abs(int(a.image.rgba[i]) - int(b.image.rgba[i])) > 1;
      lit += i % 4 != 3 && a.image.rgba[i] > 0;
    }
    EXPECT_EQ(apart, 0) << where;
    EXPECT_GT(lit, kWidth * kHeight / 4) << where;  // the scene is drawn, and lit
  };
  for (SimdLevel level : test::levels_of_this_cpu()) {
    set_simd_level(level);
    for (int threads : {1, 2}) {
      const std::string at =
          std::string(simd_level_name(level)) + ", " + std::to_string(threads) + " thread(s)";
      const FrontFace ccw = FrontFace::kCounterClockwise;
      expect_within_one(
          drawn(detail::GouraudShader<false>{in, albedo, lighting, 1.0f, {}}, threads, ccw),
          drawn(detail::GouraudShader<false, true>{in, albedo, lighting, 1.0f, {}}, threads, ccw),
          at + ", one-sided");
      for (FrontFace front : {ccw, FrontFace::kClockwise}) {
        expect_within_one(
            drawn(detail::GouraudShader<true>{in, albedo, lighting, 1.0f, {}}, threads, front),
            drawn(detail::GouraudShader<true, true>{in, albedo, lighting, 1.0f, {}}, threads,
                  front),
            at + ", two-sided" + (front == ccw ? "" : ", clockwise front"));
      }
    }
  }
}

// The wide sampler against Texture::sample, lane by lane, at one level (N lanes per vector).
// Derivatives for the trilinear case: each lane's uv changes by (lane-dependent) amounts that
// span magnification to far past the last level.
// Lod::kNear keeps every lane within 1.5 levels of the base instead (1 to 2.8 texels a pixel
// along each axis), so that whole groups of lanes read levels with room for both of their columns
// (the AVX-512 trilinear sampler's row pairs).
enum class Lod { kWide, kNear };
glm::vec2 test_ddx(size_t i, Lod lod = Lod::kWide, const Texture* t = nullptr) {
  if (lod == Lod::kNear) return {std::exp2(float(i % 4) * 0.5f) / float(t->width()), 0.0f};
  return {std::ldexp(1.0f, int(i % 23) - 12) * 0.7f, std::ldexp(1.0f, int(i % 7) - 9)};
}
glm::vec2 test_ddy(size_t i, Lod lod = Lod::kWide, const Texture* t = nullptr) {
  if (lod == Lod::kNear) return {0.0f, std::exp2(float(i % 3) * 0.7f) / float(t->height())};
  return {-std::ldexp(1.0f, int(i % 5) - 10), std::ldexp(1.0f, int(i % 19) - 11) * 1.3f};
}

template <int N>
void expect_sampler_matches_scalar(const Texture& texture, const Sampler& sampler,
                                   const std::vector<glm::vec2>& uvs, Lod lod) {
  auto ddx = [&](size_t i) { return test_ddx(i, lod, &texture); };
  auto ddy = [&](size_t i) { return test_ddy(i, lod, &texture); };
  for (size_t first = 0; first + simd::kLanes <= uvs.size(); first += simd::kLanes) {
    simd::Vec2<N> uv, dx, dy;
    for (int i = 0; i < simd::kLanes; ++i) {
      uv.x.set_lane(i, uvs[first + i].x);
      uv.y.set_lane(i, uvs[first + i].y);
      dx.x.set_lane(i, ddx(first + i).x);
      dx.y.set_lane(i, ddx(first + i).y);
      dy.x.set_lane(i, ddy(first + i).x);
      dy.y.set_lane(i, ddy(first + i).y);
    }
    // The pair, and the two bound as a SampledTexture (the built-in shaders' way): the same.
    const SampledTexture bound(texture, sampler);
    for (int way = 0; way < 2; ++way) {
      simd::Vec4<N> got;
      if (sampler.filter == Filter::kTrilinear) {
        got = way == 0 ? sample<N>(texture, sampler, uv, dx, dy) : sample<N>(bound, uv, dx, dy);
      } else {
        got = way == 0 ? sample<N>(texture, sampler, uv) : sample<N>(bound, uv);
      }
      for (int i = 0; i < simd::kLanes; ++i) {
        glm::vec4 want =
            sampler.filter == Filter::kTrilinear
                ? texture.sample(sampler, uvs[first + i], ddx(first + i), ddy(first + i))
                : texture.sample(sampler, uvs[first + i]);
        ASSERT_EQ(got.x.lane(i), want.r) << (way == 0 ? "pair" : "bound") << ", uv "
                                         << uvs[first + i].x << "," << uvs[first + i].y;
        ASSERT_EQ(got.y.lane(i), want.g);
        ASSERT_EQ(got.z.lane(i), want.b);
        ASSERT_EQ(got.w.lane(i), want.a);
      }
      if (sampler.filter == Filter::kTrilinear) continue;
      // The packed form (the texture shader's opaque output): the bytes the fragment stage makes
      // of the scalar sample. Bilinear filtering rounds its 16-bit levels straight to bytes there.
      simd::Int<N> packed =
          way == 0 ? sample_rgba8<N>(texture, sampler, uv) : sample_rgba8<N>(bound, uv);
      for (int i = 0; i < simd::kLanes; ++i) {
        uint32_t want = pack_rgba8(texture.sample(sampler, uvs[first + i]));
        ASSERT_EQ(uint32_t(packed.lane(i)), want) << (way == 0 ? "pair" : "bound") << ", uv "
                                                  << uvs[first + i].x << "," << uvs[first + i].y;
      }
    }
  }
}

// Runs the check inside a function compiled for the level, as the fragment stage does.
template <int N>
void check_sampler_at_native_width(const Texture& t, const Sampler& s,
                                   const std::vector<glm::vec2>& uvs, Lod lod = Lod::kWide);
template <>
void check_sampler_at_native_width<4>(const Texture& t, const Sampler& s,
                                      const std::vector<glm::vec2>& uvs, Lod lod) {
  expect_sampler_matches_scalar<4>(t, s, uvs, lod);
}
template <>
[[gnu::target("avx2")]] void check_sampler_at_native_width<8>(const Texture& t, const Sampler& s,
                                                              const std::vector<glm::vec2>& uvs,
                                                              Lod lod) {
  expect_sampler_matches_scalar<8>(t, s, uvs, lod);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] void check_sampler_at_native_width<16>(
    const Texture& t, const Sampler& s, const std::vector<glm::vec2>& uvs, Lod lod) {
  expect_sampler_matches_scalar<16>(t, s, uvs, lod);
}

Texture noise_texture(int width, int height, unsigned seed, bool srgb = false) {
  std::mt19937 rng(seed);
  Image image(width, height);
  for (uint8_t& b : image.rgba) b = uint8_t(rng());
  return Texture::from_image(image, srgb ? ColorSpace::kSrgb : ColorSpace::kLinear);
}

// simd::rsqrt (an estimate and a Newton step) against 1 / sqrt in double, over positive floats
// from 1e-30 to 1e30, at one level: the largest relative error.
template <int N>
double rsqrt_worst_error(const std::vector<float>& xs);
template <int N>
double rsqrt_worst_error_impl(const std::vector<float>& xs) {
  double worst = 0.0;
  for (size_t first = 0; first + simd::kLanes <= xs.size(); first += simd::kLanes) {
    simd::Float<N> x;
    for (int i = 0; i < simd::kLanes; ++i) x.set_lane(i, xs[first + i]);
    simd::Float<N> r = simd::rsqrt(x);
    for (int i = 0; i < simd::kLanes; ++i) {
      double want = 1.0 / std::sqrt(double(xs[first + i]));
      worst = std::max(worst, std::abs(double(r.lane(i)) - want) / want);
    }
  }
  return worst;
}
template <>
double rsqrt_worst_error<4>(const std::vector<float>& xs) {
  return rsqrt_worst_error_impl<4>(xs);
}
template <>
[[gnu::target("avx2,fma")]] double rsqrt_worst_error<8>(const std::vector<float>& xs) {
  return rsqrt_worst_error_impl<8>(xs);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] double rsqrt_worst_error<16>(
    const std::vector<float>& xs) {
  return rsqrt_worst_error_impl<16>(xs);
}

TEST(SimdRsqrt, WithinAFewUnitsInTheLastPlaceAtEveryLevel) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> exponent(-30.0f, 30.0f);
  std::vector<float> xs;
  for (int i = 0; i < 16384; ++i) xs.push_back(std::pow(10.0f, exponent(rng)));
  for (float x : {1.0f, 2.0f, 4.0f, 0.25f, 3.0f}) xs.insert(xs.end(), 16, x);
  // The estimate alone is up to 1.5 * 2^-12 (3.7e-4) off; the Newton step squares that, leaving
  // the rounding of its own arithmetic. Seen here: 2.1e-7 (SSE, AVX2), 1.3e-7 (AVX-512). The bound
  // is 3 units in the last place (2^-23 each).
  const double bound = 3.0 * std::ldexp(1.0, -23);
  EXPECT_LT(rsqrt_worst_error<4>(xs), bound);
  if (cpu_simd_level() >= SimdLevel::kAvx2) {
    EXPECT_LT(rsqrt_worst_error<8>(xs), bound);
  }
  if (cpu_simd_level() >= SimdLevel::kAvx512) {
    EXPECT_LT(rsqrt_worst_error<16>(xs), bound);
  }
}

// simd::fma at one level over the lanes of a, b, c: how many lanes differ from `expected`.
template <int N>
int fma_mismatches(const float* a, const float* b, const float* c, const float* expected);
template <int N>
int fma_mismatches_impl(const float* a, const float* b, const float* c, const float* expected) {
  simd::Float<N> x, y, z;
  for (int i = 0; i < simd::kLanes; ++i) {
    x.set_lane(i, a[i]);
    y.set_lane(i, b[i]);
    z.set_lane(i, c[i]);
  }
  simd::Float<N> r = simd::fma(x, y, z);
  int mismatches = 0;
  for (int i = 0; i < simd::kLanes; ++i) mismatches += r.lane(i) != expected[i];
  return mismatches;
}
template <>
int fma_mismatches<4>(const float* a, const float* b, const float* c, const float* expected) {
  return fma_mismatches_impl<4>(a, b, c, expected);
}
template <>
[[gnu::target("avx2,fma")]] int fma_mismatches<8>(const float* a, const float* b, const float* c,
                                                  const float* expected) {
  return fma_mismatches_impl<8>(a, b, c, expected);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] int fma_mismatches<16>(
    const float* a, const float* b, const float* c, const float* expected) {
  return fma_mismatches_impl<16>(a, b, c, expected);
}

// simd::fma rounds once where the level has FMA (AVX2, AVX-512: std::fma's result) and twice at
// SSE (a * b, then + c), on operands where the two differ.
TEST(SimdFma, FusedWhereTheLevelHasFma) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int differ = 0;
  for (int round = 0; round < 256; ++round) {
    float a[simd::kLanes], b[simd::kLanes], c[simd::kLanes], fused[simd::kLanes],
        twice[simd::kLanes];
    for (int i = 0; i < simd::kLanes; ++i) {
      a[i] = unit(rng);
      b[i] = unit(rng);
      c[i] = -a[i] * b[i] + unit(rng) * 1.0e-3f;  // cancellation: the product's rounding shows
      fused[i] = std::fma(a[i], b[i], c[i]);
      volatile float product = a[i] * b[i];
      twice[i] = product + c[i];
      differ += fused[i] != twice[i];
    }
    EXPECT_EQ(fma_mismatches<4>(a, b, c, twice), 0);
    if (cpu_simd_level() >= SimdLevel::kAvx2) {
      EXPECT_EQ(fma_mismatches<8>(a, b, c, fused), 0);
    }
    if (cpu_simd_level() >= SimdLevel::kAvx512) {
      EXPECT_EQ(fma_mismatches<16>(a, b, c, fused), 0);
    }
  }
  EXPECT_GT(differ, 1000);  // the operands do tell the two apart
}

// simd::normalize against glm::normalize at one level: how many lanes differ in any bit.
template <int N>
int normalize_mismatches(const std::vector<glm::vec3>& vs);
template <int N>
int normalize_mismatches_impl(const std::vector<glm::vec3>& vs) {
  int mismatches = 0;
  for (size_t first = 0; first + simd::kLanes <= vs.size(); first += simd::kLanes) {
    alignas(64) float x[simd::kLanes], y[simd::kLanes], z[simd::kLanes];
    for (int i = 0; i < simd::kLanes; ++i) {
      x[i] = vs[first + i].x;
      y[i] = vs[first + i].y;
      z[i] = vs[first + i].z;
    }
    simd::Vec3<N> n = simd::normalize(
        simd::Vec3<N>{simd::Float<N>::load(x), simd::Float<N>::load(y), simd::Float<N>::load(z)});
    for (int i = 0; i < simd::kLanes; ++i) {
      glm::vec3 want = glm::normalize(vs[first + i]);
      mismatches += n.x.lane(i) != want.x || n.y.lane(i) != want.y || n.z.lane(i) != want.z;
    }
  }
  return mismatches;
}
template <>
int normalize_mismatches<4>(const std::vector<glm::vec3>& vs) {
  return normalize_mismatches_impl<4>(vs);
}
template <>
[[gnu::target("avx2,fma")]] int normalize_mismatches<8>(const std::vector<glm::vec3>& vs) {
  return normalize_mismatches_impl<8>(vs);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] int normalize_mismatches<16>(
    const std::vector<glm::vec3>& vs) {
  return normalize_mismatches_impl<16>(vs);
}

// simd::normalize stays glm's at every level, although simd::dot fuses where it can.
TEST(SimdFma, NormalizeEqualsGlmAtEveryLevel) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec3> vs;
  for (int i = 0; i < 4096; ++i) vs.push_back({unit(rng), unit(rng), unit(rng) * 1.0e3f});
  EXPECT_EQ(normalize_mismatches<4>(vs), 0);
  if (cpu_simd_level() >= SimdLevel::kAvx2) {
    EXPECT_EQ(normalize_mismatches<8>(vs), 0);
  }
  if (cpu_simd_level() >= SimdLevel::kAvx512) {
    EXPECT_EQ(normalize_mismatches<16>(vs), 0);
  }
}

// A depth plane at one level (detail::eval_plane on 16 lanes) against the scalar eval_plane, over
// planes and pixel offsets: how many lanes differ. +0 and -0 count as equal (the vector form adds
// a0 to +0 first; both compare equal in every depth test), as does NaN against NaN.
struct PlaneCase {
  detail::DepthPlane plane;
  float dx[simd::kLanes], dy[simd::kLanes];
};
template <int N>
int depth_plane_mismatches(const std::vector<PlaneCase>& cases);
template <int N>
int depth_plane_mismatches_impl(const std::vector<PlaneCase>& cases) {
  int mismatches = 0;
  for (const PlaneCase& c : cases) {
    float z[simd::kLanes];
    detail::eval_plane<N>(c.plane, simd::Float<N>::load(c.dx), simd::Float<N>::load(c.dy)).store(z);
    for (int i = 0; i < simd::kLanes; ++i) {
      float want = detail::eval_plane(c.plane, c.dx[i], c.dy[i]);
      mismatches += !(z[i] == want || (std::isnan(z[i]) && std::isnan(want)));
    }
  }
  return mismatches;
}
template <>
int depth_plane_mismatches<4>(const std::vector<PlaneCase>& cases) {
  return depth_plane_mismatches_impl<4>(cases);
}
template <>
[[gnu::target("avx2,fma")]] int depth_plane_mismatches<8>(const std::vector<PlaneCase>& cases) {
  return depth_plane_mismatches_impl<8>(cases);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] int depth_plane_mismatches<16>(
    const std::vector<PlaneCase>& cases) {
  return depth_plane_mismatches_impl<16>(cases);
}

// The highlight's x^32 (pow32, five squarings) makes no denormal: a base below kPow32Floor gives
// 0, one above it the five squarings' own result. And the floor changes no 8-bit colour: for
// every base below it, Phong's colour albedo * lit + ks * x^32 (fused or not) packs to the same
// byte with the power (denormal or not, as the squarings make it) as with 0, for every albedo byte,
// lights from none to the brightest --light-intensity allows (specular 0.4 * 100).
TEST(SimdShadingMath, Pow32MakesNoDenormalAndItsFloorChangesNoColour) {
  auto squarings = [](float x) {
    for (int k = 0; k < 5; ++k) x = x * x;
    return x;
  };
  auto pack = [](float v) { return int(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f); };
  std::vector<float> below;
  for (int i = 0; i <= 400000; ++i) {
    const float x = float(i) / 400000.0f;
    simd::Float<4> r = detail::pow32<4>(simd::Float<4>(x));
    const float power = r.lane(0);
    ASSERT_TRUE(power == 0.0f || power >= std::numeric_limits<float>::min()) << x;
    if (x >= detail::kPow32Floor) {
      ASSERT_EQ(power, squarings(x)) << x;
    } else {
      ASSERT_EQ(power, 0.0f) << x;
      below.push_back(x);
    }
  }
  ASSERT_GT(below.size(), 20000u);
  int checked = 0;
  for (size_t b = 0; b < below.size(); b += 97) {
    const float power = squarings(below[b]);
    for (int albedo = 0; albedo <= 255; ++albedo) {
      for (float lit : {0.0f, 0.15f, 1.0f, 100.0f}) {
        for (float ks : {0.4f, 4.0f, 40.0f}) {
          const float a = float(albedo) / 255.0f;
          // Fused where the level has FMA, a product and a sum at SSE (simd::fma).
          ASSERT_EQ(pack(std::fma(a, lit, ks * power)), pack(std::fma(a, lit, ks * 0.0f)))
              << below[b] << " " << albedo << " " << lit << " " << ks;
          ASSERT_EQ(pack(a * lit + ks * power), pack(a * lit + ks * 0.0f))
              << below[b] << " " << albedo << " " << lit << " " << ks;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 100000);
}

// The fragment stage's depth is the scalar plane's, bit for bit, at every level: the tile kernels'
// depth resolve computes the same double sum, and deferred shading is exact only if the two agree.
// Half the planes nearly cancel at one pixel, so that a change of the operations' order (a
// reassociated sum, a fused multiply-add, a float product) changes the rounded depth there (a
// reassociated sum changes about half of those lanes).
TEST(SimdDepthPlane, EqualsTheScalarPlaneBitForBitAtEveryLevel) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> offset(-40.0f, 40.0f);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<PlaneCase> cases(2048);
  for (size_t k = 0; k < cases.size(); ++k) {
    PlaneCase& c = cases[k];
    for (int i = 0; i < simd::kLanes; ++i) c.dx[i] = offset(rng), c.dy[i] = offset(rng);
    c.plane.dadx = unit(rng) * 1.0e-2;
    c.plane.dady = unit(rng) * 1.0e-2;
    c.plane.a0 = 0.5 + unit(rng) * 0.5;
    if (k % 2 == 1) {  // about 1e-12 at lane 0: there a double's rounding shows in the float
      c.plane.a0 =
          -(c.plane.dadx * double(c.dx[0]) + c.plane.dady * double(c.dy[0])) + unit(rng) * 1.0e-12;
    }
  }
  cases[0].plane = {-0.0, 0.0, -0.0};  // zeros of both signs
  EXPECT_EQ(depth_plane_mismatches<4>(cases), 0);
  if (cpu_simd_level() >= SimdLevel::kAvx2) {
    EXPECT_EQ(depth_plane_mismatches<8>(cases), 0);
  }
  if (cpu_simd_level() >= SimdLevel::kAvx512) {
    EXPECT_EQ(depth_plane_mismatches<16>(cases), 0);
  }
}

TEST(SimdSampler, MatchesScalarSamplingBitForBitAtEveryLevel) {
  GatherModeGuard guard;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> near_range(-3.0f, 3.0f), far_range(-1.0e6f, 1.0e6f);
  std::vector<glm::vec2> uvs;
  for (int i = 0; i < 1024; ++i) uvs.push_back({near_range(rng), near_range(rng)});
  for (int i = 0; i < 256; ++i) uvs.push_back({far_range(rng), far_range(rng)});
  // Columns inside the texture and rows across its bottom and top edges: whole groups of lanes
  // whose columns are neighbours even when clamped (the AVX2 and AVX-512 samplers' row pairs,
  // Texture::row_pairs), with rows below the first, on the first and last, and above the last.
  std::uniform_real_distribution<float> inside(0.05f, 0.95f), across(-0.1f, 1.1f);
  for (int i = 0; i < 512; ++i) uvs.push_back({inside(rng), across(rng)});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (float special : {nan, inf, -inf, 1.0e30f, -0.0f, 0.5f}) {
    for (int i = 0; i < 16; ++i) uvs.push_back({special, near_range(rng)});
  }
  for (auto [w, h] : {std::pair{64, 32}, std::pair{37, 19}, std::pair{1, 1}, std::pair{256, 5}}) {
    for (bool srgb : {false, true}) {
      // An sRGB texture read through the decode table (its chain built in linear space).
      Texture texture = noise_texture(w, h, unsigned(w * 100 + h), srgb);
      for (Filter filter : {Filter::kNearest, Filter::kBilinear, Filter::kTrilinear}) {
        // Each mode on both axes, and repeat on one axis with clamping on the other.
        for (auto [wrap_u, wrap_v] : {std::pair{Wrap::kRepeat, Wrap::kRepeat},
                                      std::pair{Wrap::kClampToEdge, Wrap::kClampToEdge},
                                      std::pair{Wrap::kMirroredRepeat, Wrap::kMirroredRepeat},
                                      std::pair{Wrap::kRepeat, Wrap::kClampToEdge},
                                      std::pair{Wrap::kClampToEdge, Wrap::kRepeat}}) {
          Sampler sampler{filter, wrap_u, wrap_v, srgb};
          SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " filter " +
                       std::to_string(int(filter)) + " wrap " + std::to_string(int(wrap_u)) + "," +
                       std::to_string(int(wrap_v)) + (srgb ? " srgb" : ""));
          for (Lod lod : {Lod::kWide, Lod::kNear}) {
            if (lod == Lod::kNear && filter != Filter::kTrilinear) continue;
            SCOPED_TRACE(lod == Lod::kNear ? "lod near the base" : "lod over every level");
            check_sampler_at_native_width<4>(texture, sampler, uvs, lod);
            // Both ways of gathering texels: the instruction and one load per lane.
            for (GatherMode mode : {GatherMode::kInstruction, GatherMode::kLoads}) {
              SCOPED_TRACE(gather_mode_name(mode));
              set_gather_mode(mode);
              if (cpu_simd_level() >= SimdLevel::kAvx2) {
                check_sampler_at_native_width<8>(texture, sampler, uvs, lod);
              }
              if (cpu_simd_level() >= SimdLevel::kAvx512) {
                check_sampler_at_native_width<16>(texture, sampler, uvs, lod);
              }
            }
          }
        }
      }
    }
  }
}

// The two forms of each gather (simd::isa): the instruction and one load per lane (with the
// indices by either route, simd::IndexRoute), against the elements they should read, at indices
// all over a table (the first and last elements among them), inside functions compiled for the
// width's level as the shaders are.
// r[i] = table[index[i]] by the form asked for, and the pairs lo[i] = table[index[i]], hi[i] =
// table[index[i] + 1] through gather_pair in that mode. Inlined into the functions below.
template <int N>
SOFTRAST_SIMD_INLINE void gather_by(const int32_t* table, const typename simd::Native<N>::I& index,
                                    bool loads, simd::IndexRoute route,
                                    typename simd::Native<N>::I& r, typename simd::Native<N>::I& lo,
                                    typename simd::Native<N>::I& hi) {
  if (loads) {
    simd::isa::gather_loads(table, index, r, route);  // (16 lanes: the route is ignored)
  } else {
    simd::isa::gather_instruction(table, index, r);
  }
  set_gather_mode(loads ? GatherMode::kLoads : GatherMode::kInstruction);
  simd::isa::gather_pair(table, index, lo, hi, route);
}
template <int N>
struct GatherForms {
  using V = typename simd::Native<N>::I;
  static void run(const int32_t* table, const V& index, bool loads, simd::IndexRoute route, V& r,
                  V& lo, V& hi);
};
template <>
[[gnu::target("avx2")]] void GatherForms<8>::run(const int32_t* table, const V& index, bool loads,
                                                 simd::IndexRoute route, V& r, V& lo, V& hi) {
  gather_by<8>(table, index, loads, route, r, lo, hi);
}
template <>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] void GatherForms<16>::run(
    const int32_t* table, const V& index, bool loads, simd::IndexRoute route, V& r, V& lo, V& hi) {
  gather_by<16>(table, index, loads, route, r, lo, hi);
}

template <int N>
void expect_gathers_read_their_elements() {
  using V = typename simd::Native<N>::I;
  constexpr int kSize = 1000;
  std::vector<int32_t> table(kSize);
  for (int i = 0; i < kSize; ++i) table[size_t(i)] = int32_t(i * 7919 + 13);
  std::mt19937 rng(N);
  std::uniform_int_distribution<int> pick(0, kSize - 2);  // a pair's second element exists
  for (int round = 0; round < 200; ++round) {
    V index;
    for (int i = 0; i < N; ++i) index[i] = pick(rng);
    if (round == 0) index[0] = 0, index[N - 1] = kSize - 2;
    for (bool loads : {false, true}) {
      for (simd::IndexRoute route : {simd::IndexRoute::kMemory, simd::IndexRoute::kRegisters}) {
        const char* form = !loads                               ? "instruction"
                           : route == simd::IndexRoute::kMemory ? "loads, indices through memory"
                                                                : "loads, indices by extracts";
        V r, lo, hi;
        GatherForms<N>::run(table.data(), index, loads, route, r, lo, hi);
        for (int i = 0; i < N; ++i) {
          ASSERT_EQ(r[i], table[size_t(index[i])]) << form << " lane " << i;
          ASSERT_EQ(lo[i], table[size_t(index[i])]) << form << " lane " << i;
          ASSERT_EQ(hi[i], table[size_t(index[i]) + 1]) << form << " lane " << i;
        }
      }
    }
  }
}

TEST(SimdGather, InstructionAndLoadsReadTheSameElements) {
  GatherModeGuard guard;
  if (cpu_simd_level() < SimdLevel::kAvx2) GTEST_SKIP() << "no AVX2: no gather instruction";
  expect_gathers_read_their_elements<8>();
  if (cpu_simd_level() >= SimdLevel::kAvx512) expect_gathers_read_their_elements<16>();
}

TEST(SimdGather, ModeIsChosenOverriddenAndReported) {
  GatherModeGuard guard;
  // Below AVX2 there is no instruction: always loads.
  EXPECT_EQ(gather_mode(SimdLevel::kSse2), GatherMode::kLoads);
  EXPECT_EQ(gather_mode(SimdLevel::kSse4), GatherMode::kLoads);
  for (GatherMode mode : {GatherMode::kInstruction, GatherMode::kLoads}) {
    set_gather_mode(mode);
    EXPECT_EQ(gather_mode(SimdLevel::kAvx2), mode);
    EXPECT_EQ(gather_mode(SimdLevel::kAvx512), mode);
  }
  EXPECT_STREQ(gather_mode_name(GatherMode::kInstruction), "instruction");
  EXPECT_STREQ(gather_mode_name(GatherMode::kLoads), "loads");
}

// Every shader that samples, at every level, with either form of gather: the same image bit for
// bit (trilinear too, which also gathers from the level table).
TEST(SimdGather, TexturedRendersAreTheSameWithEitherForm) {
  SimdLevelGuard level_guard;
  GatherModeGuard guard;
  // A power-of-two texture (the AVX-512 bilinear fast path), another size (the general path), and
  // an sRGB one read through the decode table.
  const auto pow2 = std::make_shared<Texture>(noise_texture(64, 64, 5));
  const auto odd = std::make_shared<Texture>(noise_texture(37, 19, 6));
  const auto srgb = std::make_shared<Texture>(noise_texture(32, 32, 7, true));
  for (SimdLevel level : test::levels_of_this_cpu()) {
    if (level < SimdLevel::kAvx2) continue;
    for (ShaderKind kind : {ShaderKind::kTexture, ShaderKind::kPhong}) {
      for (Filter filter : {Filter::kBilinear, Filter::kTrilinear, Filter::kNearest}) {
        for (const auto& texture : {pow2, odd, srgb}) {
          RenderOptions options;
          options.shader = kind;
          options.texture = texture;
          options.srgb = texture == srgb;
          options.sampler = Sampler{filter, Wrap::kRepeat, Wrap::kClampToEdge, texture == srgb};
          set_gather_mode(GatherMode::kInstruction);
          Rendered instruction = render_demo_at(level, options);
          set_gather_mode(GatherMode::kLoads);
          Rendered loads = render_demo_at(level, options);
          EXPECT_EQ(instruction.image.rgba, loads.image.rgba)
              << simd_level_name(level) << " " << shader_kind_name(kind) << " filter "
              << int(filter) << " texture " << texture->width() << "x" << texture->height();
          EXPECT_EQ(instruction.depth, loads.depth);
        }
      }
    }
  }
}

// A wide shader with a discard, drawn at every level: the same image as its scalar twin.
struct HoleWide {
  static constexpr int kVaryings = 2;
  static constexpr bool kDiscards = true;
  glm::vec4 vertex(uint32_t i, float* v) const {
    static const glm::vec2 kCorners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    v[0] = kCorners[i].x * 0.5f + 0.5f;
    v[1] = kCorners[i].y * 0.5f + 0.5f;
    return {kCorners[i] * 0.9f, 0.0f, 1.0f};
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    F du = f.varying(0) - F(0.5f), dv = f.varying(1) - F(0.5f);
    f.discard(du * du + dv * dv < F(0.04f));
    f.color = {f.varying(0), f.varying(1), simd::sqrt(f.varying(0)), F(1.0f)};
  }
};
struct HoleScalar {
  static constexpr int kVaryings = 2;
  glm::vec4 vertex(uint32_t i, float* v) const { return HoleWide{}.vertex(i, v); }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    float du = in.varyings[0] - 0.5f, dv = in.varyings[1] - 0.5f;
    if (du * du + dv * dv < 0.04f) return false;
    out = {in.varyings[0], in.varyings[1], std::sqrt(in.varyings[0]), 1.0f};
    return true;
  }
};

TEST(SimdShader, DiscardingWideShaderEqualsItsScalarTwinAtEveryLevel) {
  SimdLevelGuard guard;
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  RenderState state;
  state.cull = CullMode::kNone;
  Framebuffer want(97, 61);
  draw(want, state, HoleScalar{}, indices, 4);
  for (SimdLevel level : test::levels_of_this_cpu()) {
    set_simd_level(level);
    Framebuffer got(97, 61);
    draw(got, state, HoleWide{}, indices, 4);
    int differ = 0;
    for (int y = 0; y < 61; ++y) {
      for (int x = 0; x < 97; ++x) differ += got.color_at(x, y) != want.color_at(x, y);
    }
    EXPECT_EQ(differ, 0) << simd_level_name(level);
    EXPECT_NE(want.color_at(48, 30), want.color_at(10, 30));  // the hole is there
  }
}

// The fragment stage's guard on 1/w: where |1/w| < 1e-30 (zero included) a pixel divides as if it
// were 1e-30 (shade_quad's rule). The pipeline's setup keeps 1/w planes far from that, so the
// block functions are called here with planes made for it: 1/w of -1.5e-30, -0.5e-30, 0.5e-30
// and 1.5e-30 across each row of the block, so that the middle two columns are guarded, and a
// varying whose values come out -0.2, 0.3, 0.3 and 0.2 (the guarded ones would differ with any
// other guard). Whole blocks and blocks of two triangles, at every level, against the scalar
// stage bit for bit.
struct GuardWide {
  static constexpr int kVaryings = 1;
  bool reads_derivatives() const { return false; }
  template <int N>
  void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    f.color = {f.varying(0) + F(0.5f), F(0.25f), F(0.5f), F(1.0f)};
  }
};
struct GuardScalar {
  static constexpr int kVaryings = 1;
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    out = {in.varyings[0] + 0.5f, 0.25f, 0.5f, 1.0f};
    return true;
  }
};

TEST(SimdShader, TinyInverseWIsGuardedAsTheScalarStageDoesAtEveryLevel) {
  SimdLevelGuard guard;
  detail::Interpolants in;
  in.z = {0.5, 0.0, 0.0};
  in.inv_w = {-2.0e-30f, 1.0e-30f, 0.0f};  // at pixel centres x + 0.5 of the block at x = 0
  in.num_varyings = 1;
  in.var[0] = {3.0e-31f, 0.0f, 0.0f};
  detail::Interpolants other = in;  // the second triangle of a shared block: the same planes
  RenderState state;
  Framebuffer want(4, 4);
  want.prepare_tile(0, 0);  // the block functions write the tile's storage: no clear pending
  const detail::ShadeTarget want_target{&want, &state, false};
  GuardScalar scalar;
  detail::shade_block<GuardScalar>(&scalar, want_target, in, 0, 0, 0xffffu);
  // The guard acted: columns 1 and 2 are 0.3 + 0.5, columns 0 and 3 are -0.2 + 0.5 and 0.2 + 0.5.
  const int red[4] = {int(want.color_at(0, 0) & 0xffu), int(want.color_at(1, 0) & 0xffu),
                      int(want.color_at(2, 0) & 0xffu), int(want.color_at(3, 0) & 0xffu)};
  EXPECT_NEAR(red[0], 77, 1);
  EXPECT_NEAR(red[1], 204, 1);
  EXPECT_EQ(red[1], red[2]);
  EXPECT_NEAR(red[3], 179, 1);
  GuardWide wide;
  for (SimdLevel level : test::levels_of_this_cpu()) {
    Framebuffer whole(4, 4), shared(4, 4);
    whole.prepare_tile(0, 0);
    shared.prepare_tile(0, 0);
    const detail::ShadeTarget whole_target{&whole, &state, false};
    const detail::ShadeTarget shared_target{&shared, &state, false};
    detail::wide_shade_block<GuardWide>(level)(&wide, whole_target, in, 0, 0, 0xffffu);
    detail::MixedBlock block;
    block.winner[0] = &in;
    block.mask[0] = 0x0f0fu;
    block.winner[1] = &other;
    block.mask[1] = 0xf0f0u;
    block.count = 2;
    detail::wide_shade_mixed<GuardWide>(level)(&wide, shared_target, block, 0, 0);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 4; ++x) {
        EXPECT_EQ(whole.color_at(x, y), want.color_at(x, y)) << simd_level_name(level) << " whole";
        EXPECT_EQ(shared.color_at(x, y), want.color_at(x, y))
            << simd_level_name(level) << " shared";
      }
    }
  }
}

// The same textured quad through a custom wide shader that writes packed bytes
// (Fragments::set_rgba8 of sample_rgba8) and one that writes f.color = sample(...): opaque, the
// same image at every level; blended, the packed one blends from byte / 255, as its twin that
// writes the unpacked bytes as floats does.
struct TexturedQuad {
  static constexpr int kVaryings = 2;
  const Texture* texture;
  Sampler sampler;
  bool packed;
  bool reads_derivatives() const { return false; }
  glm::vec4 vertex(uint32_t i, float* v) const {
    static const glm::vec2 kCorners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    v[0] = kCorners[i].x * 1.7f + 0.3f;  // repeats the texture a few times, magnified
    v[1] = kCorners[i].y * 1.3f - 0.2f;
    return {kCorners[i].x * 0.9f, kCorners[i].y * 0.8f, 0.25f * kCorners[i].x, 1.0f};
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    if (packed) {
      f.set_rgba8(sample_rgba8<N>(*texture, sampler, f.vec2(0)));
    } else {
      f.color = sample<N>(*texture, sampler, f.vec2(0));
    }
  }
};
struct TexturedQuadUnpacked : TexturedQuad {
  template <int N>
  void shade(Fragments<N>& f) const {  // the packed bytes, as floats
    f.color = detail::unpack_rgba8<N>(sample_rgba8<N>(*texture, sampler, f.vec2(0)));
  }
};

TEST(SimdShader, PackedOutputEqualsFloatOutputAtEveryLevel) {
  SimdLevelGuard guard;
  Texture texture = noise_texture(64, 32, 11);
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  for (Filter filter : {Filter::kNearest, Filter::kBilinear}) {
    for (BlendMode blend : {BlendMode::kOpaque, BlendMode::kAlpha}) {
      RenderState state;
      state.cull = CullMode::kNone;
      state.blend = blend;
      Sampler sampler{filter, Wrap::kRepeat, Wrap::kRepeat, false};
      for (SimdLevel level : test::levels_of_this_cpu()) {
        set_simd_level(level);
        Framebuffer want(131, 77), got(131, 77);
        want.clear_color({0.2f, 0.4f, 0.6f, 1.0f});
        got.clear_color({0.2f, 0.4f, 0.6f, 1.0f});
        if (blend == BlendMode::kOpaque) {
          draw(want, state, TexturedQuad{&texture, sampler, false}, indices, 4);
        } else {
          draw(want, state, TexturedQuadUnpacked{{&texture, sampler, true}}, indices, 4);
        }
        draw(got, state, TexturedQuad{&texture, sampler, true}, indices, 4);
        int differ = 0;
        for (int y = 0; y < 77; ++y) {
          for (int x = 0; x < 131; ++x) differ += got.color_at(x, y) != want.color_at(x, y);
        }
        EXPECT_EQ(differ, 0) << simd_level_name(level) << " filter " << int(filter) << " blend "
                             << int(blend);
        EXPECT_NE(got.color_at(65, 38), got.color_at(0, 0));  // the quad is drawn
      }
    }
  }
}

// The built-in texture shader writes packed bytes only where the draw is opaque (f.opaque):
// against a twin that always writes f.color = sample(...), the same image opaque and alpha
// blended (the texture's own alpha blends), at every level.
struct FloatTextureTwin {
  static constexpr int kVaryings = 2;
  detail::TextureShader shader;
  bool reads_derivatives() const { return false; }
  glm::vec4 vertex(uint32_t i, float* v) const { return shader.vertex(i, v); }
  template <int N>
  void shade(Fragments<N>& f) const {
    f.color = sample<N>(shader.map.texture(), shader.map.sampler(), f.vec2(0));
  }
};

TEST(SimdShader, BuiltInTextureShaderWritesBytesOnlyWhenOpaque) {
  SimdLevelGuard guard;
  Texture texture = noise_texture(64, 32, 5);
  Mesh quad;
  quad.positions = {
      {-0.9f, -0.8f, 0.1f}, {0.9f, -0.8f, -0.1f}, {0.9f, 0.8f, 0.2f}, {-0.9f, 0.8f, 0.0f}};
  quad.uvs = {{-0.4f, -0.7f}, {2.1f, -0.7f}, {2.1f, 1.6f}, {-0.4f, 1.6f}};
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  detail::MeshInputs inputs;
  inputs.mesh = &quad;
  detail::TextureShader shader{
      inputs, SampledTexture(texture, {Filter::kBilinear, Wrap::kRepeat, Wrap::kRepeat, false})};
  for (BlendMode blend : {BlendMode::kOpaque, BlendMode::kAlpha}) {
    RenderState state;
    state.cull = CullMode::kNone;
    state.blend = blend;
    for (SimdLevel level : test::levels_of_this_cpu()) {
      set_simd_level(level);
      Framebuffer want(131, 77), got(131, 77);
      want.clear_color({0.2f, 0.4f, 0.6f, 1.0f});
      got.clear_color({0.2f, 0.4f, 0.6f, 1.0f});
      draw(want, state, FloatTextureTwin{shader}, indices, 4);
      draw(got, state, shader, indices, 4);
      int differ = 0;
      for (int y = 0; y < 77; ++y) {
        for (int x = 0; x < 131; ++x) differ += got.color_at(x, y) != want.color_at(x, y);
      }
      EXPECT_EQ(differ, 0) << simd_level_name(level) << " blend " << int(blend);
      EXPECT_NE(got.color_at(65, 38), got.color_at(0, 0));  // the quad is drawn
    }
  }
}

}  // namespace
}  // namespace softrast
