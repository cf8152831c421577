// tests/pipeline_test.cpp: the fixed-function pipeline behind softrast::draw, case by case:
// perspective-correct varyings against a ray-cast, depth functions and depth writes, blending to
// the conventions' rounding, culling and facing, lines in every octant, points, discard,
// wireframe and depth bias. Expected values come from the conventions, computed in the test.
#include "softrast/shader.hpp"  // first: the custom-shader header must compile on its own

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "test_util.hpp"

namespace softrast {
namespace {

using test::ascii_map;
using test::ClipSpaceShader;
using test::count_hits;
using test::counting_state;
using test::window_to_clip;

// ---------------------------------------------------------------------------------------------
// Perspective-correct interpolation.

// A floor quad seen at a grazing angle, with u along its length and v across it; the fragment
// shader records what it receives per pixel.
struct RecordingShader {
  static constexpr int kVaryings = 2;
  const glm::dvec3* positions = nullptr;
  const glm::vec2* uv = nullptr;
  glm::dmat4 view_proj{1.0};
  int width = 0;
  std::vector<glm::vec2>* seen = nullptr;
  std::vector<int>* calls = nullptr;

  glm::vec4 vertex(uint32_t i, float* out) const {
    out[0] = uv[i].x;
    out[1] = uv[i].y;
    return glm::vec4(view_proj * glm::dvec4(positions[i], 1.0));
  }
  bool fragment(FragmentInput& in, glm::vec4& color) const {
    int x = int(in.position.x), y = int(in.position.y);
    (*seen)[size_t(y) * width + x] = in.vec2(0);
    ++(*calls)[size_t(y) * width + x];
    color = {1, 1, 1, 1};
    return true;
  }
};

class Pipeline : public testing::TestWithParam<RasterAlgorithm> {
 protected:
  RenderState state() const {
    RenderState s;
    s.raster = GetParam();
    return s;
  }
};

TEST_P(Pipeline, VaryingsArePerspectiveCorrect) {
  constexpr int kW = 128, kH = 128;
  const double z_near = -1.0, z_far = -60.0;
  // The quad: x in [-2, 2] on the floor y = 0, from z = -1 to z = -60; u = 0 at the near end.
  const glm::dvec3 pos[4] = {{-2, 0, z_near}, {2, 0, z_near}, {2, 0, z_far}, {-2, 0, z_far}};
  const glm::vec2 uv[4] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  const glm::dvec3 eye{0.0, 0.4, 0.0};
  const glm::dmat4 view_proj = glm::perspective(glm::radians(60.0), 1.0, 0.1, 100.0) *
                               glm::lookAt(eye, glm::dvec3(0, 0, -10), glm::dvec3(0, 1, 0));
  const glm::dmat4 inverse = glm::inverse(view_proj);

  std::vector<glm::vec2> seen(kW * kH);
  std::vector<int> calls(kW * kH);
  RecordingShader shader{pos, uv, view_proj, kW, &seen, &calls};
  Framebuffer fb(kW, kH);
  RenderState s = state();
  s.cull = CullMode::kNone;
  const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
  draw(fb, s, shader, idx, 4);

  int covered = 0;
  double worst = 0.0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      int c = calls[size_t(y) * kW + x];
      ASSERT_LE(c, 1) << x << ", " << y;
      if (c == 0) continue;
      ++covered;
      // The ray through the pixel centre meets the floor at p; u and v are affine in p.
      double nx = 2.0 * (x + 0.5) / kW - 1.0, ny = 1.0 - 2.0 * (y + 0.5) / kH;
      glm::dvec4 a = inverse * glm::dvec4(nx, ny, -1, 1), b = inverse * glm::dvec4(nx, ny, 1, 1);
      glm::dvec3 n = glm::dvec3(a) / a.w, f = glm::dvec3(b) / b.w;
      glm::dvec3 p = n + (f - n) * (-n.y / (f.y - n.y));
      double u = (p.z - z_near) / (z_far - z_near), v = (p.x + 2.0) / 4.0;
      glm::vec2 got = seen[size_t(y) * kW + x];
      worst = std::max({worst, std::abs(got.x - u), std::abs(got.y - v)});
      EXPECT_NEAR(got.x, u, 1.0 / 255.0) << "u at " << x << ", " << y;
      EXPECT_NEAR(got.y, v, 1.0 / 255.0) << "v at " << x << ", " << y;
    }
  }
  EXPECT_GT(covered, kW * kH / 8);
  RecordProperty("worst_error", std::to_string(worst));
}

// ---------------------------------------------------------------------------------------------
// Depth.

constexpr int kS = 16;  // framebuffer size of the small cases

// A full-screen quad at constant clip z (w = 1): window depth (z + 1) / 2, exact for z = 0.
std::vector<glm::vec4> screen_quad(float z) {
  return {{-1, -1, z, 1}, {1, -1, z, 1}, {1, 1, z, 1}, {-1, 1, z, 1}};
}
const std::vector<uint32_t> kQuad = {0, 1, 2, 0, 2, 3};

// Depth stored per row: 0.25, 0.5, 0.75, repeating.
float stored_depth(int y) {
  return 0.25f * float(y % 3 + 1);
}

void fill_depth_rows(Framebuffer& fb) {
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) fb.set_depth(x, y, stored_depth(y));
  }
}

// The comparison by its definition: incoming z against the stored value.
bool passes(DepthFunc f, float z, float stored) {
  switch (f) {
    case DepthFunc::kNever:
      return false;
    case DepthFunc::kLess:
      return z < stored;
    case DepthFunc::kEqual:
      return z == stored;
    case DepthFunc::kLessEqual:
      return !(z > stored);
    case DepthFunc::kGreater:
      return z > stored;
    case DepthFunc::kNotEqual:
      return !(z == stored);
    case DepthFunc::kGreaterEqual:
      return !(z < stored);
    case DepthFunc::kAlways:
      return true;
  }
  return false;
}

const uint32_t kRed = 0xff0000ffu;      // RGBA8 (255, 0, 0, 255)
const uint32_t kCleared = 0x00000000u;  // the clear colour of these tests

TEST_P(Pipeline, DepthFunctionsAndDepthWrites) {
  const DepthFunc funcs[] = {DepthFunc::kNever,        DepthFunc::kLess,    DepthFunc::kEqual,
                             DepthFunc::kLessEqual,    DepthFunc::kGreater, DepthFunc::kNotEqual,
                             DepthFunc::kGreaterEqual, DepthFunc::kAlways};
  auto quad = screen_quad(0.0f);  // depth exactly 0.5
  ClipSpaceShader shader;
  shader.positions = quad.data();
  shader.color = {1, 0, 0, 1};
  for (DepthFunc f : funcs) {
    for (bool write : {true, false}) {
      SCOPED_TRACE("depth func " + std::to_string(int(f)) + (write ? " with" : " without") +
                   " depth writes");
      Framebuffer fb(kS, kS);
      fb.clear_color({0, 0, 0, 0});
      fill_depth_rows(fb);
      RenderState s = state();
      s.depth_func = f;
      s.depth_write = write;
      draw(fb, s, shader, kQuad, 4);
      int drawn = 0;
      for (int y = 0; y < kS; ++y) {
        bool pass = passes(f, 0.5f, stored_depth(y));
        for (int x = 0; x < kS; ++x) {
          ASSERT_EQ(fb.color_at(x, y), pass ? kRed : kCleared) << x << ", " << y;
          ASSERT_EQ(fb.depth_at(x, y), pass && write ? 0.5f : stored_depth(y)) << x << ", " << y;
          drawn += pass;
        }
      }
      if (f == DepthFunc::kEqual) {
        EXPECT_EQ(drawn, kS * ((kS + 1) / 3));  // the 0.5 rows
      }
    }
  }
}

TEST_P(Pipeline, WithoutDepthTestEverythingIsDrawnAndNoDepthWritten) {
  auto quad = screen_quad(0.5f);  // depth 0.75, behind some stored values
  ClipSpaceShader shader;
  shader.positions = quad.data();
  shader.color = {1, 0, 0, 1};
  Framebuffer fb(kS, kS);
  fb.clear_color({0, 0, 0, 0});
  fill_depth_rows(fb);
  RenderState s = state();
  s.depth_test = false;
  s.depth_write = true;
  s.depth_func = DepthFunc::kNever;
  draw(fb, s, shader, kQuad, 4);
  for (int y = 0; y < kS; ++y) {
    for (int x = 0; x < kS; ++x) {
      ASSERT_EQ(fb.color_at(x, y), kRed);
      ASSERT_EQ(fb.depth_at(x, y), stored_depth(y));
    }
  }
}

// Window depth is linear in window space: z_ndc = x_ndc / 2 gives depth (x_ndc / 2 + 1) / 2 at
// each pixel centre.
TEST_P(Pipeline, DepthIsInterpolatedLinearlyInWindowSpace) {
  std::vector<glm::vec4> quad{
      {-1, -1, -0.5f, 1}, {1, -1, 0.5f, 1}, {1, 1, 0.5f, 1}, {-1, 1, -0.5f, 1}};
  ClipSpaceShader shader;
  shader.positions = quad.data();
  Framebuffer fb(kS, kS);
  RenderState s = state();
  s.depth_func = DepthFunc::kAlways;
  draw(fb, s, shader, kQuad, 4);
  for (int y = 0; y < kS; ++y) {
    for (int x = 0; x < kS; ++x) {
      double x_ndc = 2.0 * (x + 0.5) / kS - 1.0;
      EXPECT_NEAR(fb.depth_at(x, y), (x_ndc / 2.0 + 1.0) / 2.0, 1e-6) << x << ", " << y;
    }
  }
}

// A shader that writes its own depth: the depth test happens after it, with its value.
struct DepthWritingShader {
  static constexpr int kVaryings = 0;
  static constexpr bool kWritesDepth = true;
  const glm::vec4* positions = nullptr;
  glm::vec4 vertex(uint32_t i, float*) const { return positions[i]; }
  bool fragment(FragmentInput& in, glm::vec4& color) const {
    in.depth = 0.375f;
    color = {1, 0, 0, 1};
    return true;
  }
};

TEST_P(Pipeline, ShaderWrittenDepthIsTestedAndStored) {
  auto quad = screen_quad(0.0f);  // interpolated depth 0.5, replaced by 0.375
  DepthWritingShader shader{quad.data()};
  Framebuffer fb(kS, kS);
  fb.clear_color({0, 0, 0, 0});
  fill_depth_rows(fb);
  RenderState s = state();
  s.depth_func = DepthFunc::kLess;
  draw(fb, s, shader, kQuad, 4);
  for (int y = 0; y < kS; ++y) {
    bool pass = 0.375f < stored_depth(y);  // rows at 0.5 and 0.75, not 0.25
    for (int x = 0; x < kS; ++x) {
      ASSERT_EQ(fb.color_at(x, y), pass ? kRed : kCleared) << x << ", " << y;
      ASSERT_EQ(fb.depth_at(x, y), pass ? 0.375f : stored_depth(y)) << x << ", " << y;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Blending, with the conventions' rounding: clamp to [0, 1], x * 255 + 0.5 truncated.

int unorm8(double x) {
  return int(std::floor(std::clamp(x, 0.0, 1.0) * 255.0 + 0.5));
}

uint32_t pack(int r, int g, int b, int a) {
  return uint32_t(r) | uint32_t(g) << 8 | uint32_t(b) << 16 | uint32_t(a) << 24;
}

TEST_P(Pipeline, BlendModesGiveExactResults) {
  const int dst[4] = {51, 102, 153, 204};  // stored bytes
  // Chosen so that no expected value lies within 0.05 of a rounding boundary.
  const glm::vec4 sources[] = {{0.123f, 0.77f, 0.35f, 0.0f},
                               {0.31f, 0.47f, 0.83f, 1.0f},
                               {0.37f, 0.62f, 0.13f, 0.29f},
                               {1.5f, -0.5f, 0.17f, 0.81f}};  // clamped
  for (BlendMode mode : {BlendMode::kOpaque, BlendMode::kAlpha, BlendMode::kAdditive}) {
    for (glm::vec4 src : sources) {
      SCOPED_TRACE("mode " + std::to_string(int(mode)) + " source " + std::to_string(src.r) + " " +
                   std::to_string(src.g) + " " + std::to_string(src.b) + " " +
                   std::to_string(src.a));
      double s[4], d[4], out[4] = {};
      for (int c = 0; c < 4; ++c)
        s[c] = std::clamp(double(src[c]), 0.0, 1.0), d[c] = dst[c] / 255.0;
      for (int c = 0; c < 4; ++c) {
        switch (mode) {
          case BlendMode::kOpaque:
            out[c] = s[c];
            break;
          case BlendMode::kAdditive:
            out[c] = s[c] + d[c];
            break;
          case BlendMode::kAlpha:
            out[c] = c < 3 ? s[c] * s[3] + d[c] * (1.0 - s[3]) : s[3] + d[3] * (1.0 - s[3]);
            break;
        }
        // The expectation must not sit on a rounding boundary (float vs double).
        double frac = std::clamp(out[c], 0.0, 1.0) * 255.0 + 0.5;
        frac -= std::floor(frac);
        ASSERT_TRUE(out[c] >= 1.0 || out[c] <= 0.0 || (frac > 0.01 && frac < 0.99))
            << "test values too close to a rounding boundary: " << out[c] * 255.0;
      }
      std::vector<glm::vec4> quad = screen_quad(0.0f);
      ClipSpaceShader shader;
      shader.positions = quad.data();
      shader.color = src;
      Framebuffer fb(4, 4);
      fb.clear_color({dst[0] / 255.0f, dst[1] / 255.0f, dst[2] / 255.0f, dst[3] / 255.0f});
      ASSERT_EQ(fb.color_at(0, 0), pack(dst[0], dst[1], dst[2], dst[3]));
      RenderState st = state();
      st.blend = mode;
      draw(fb, st, shader, kQuad, 4);
      uint32_t want = pack(unorm8(out[0]), unorm8(out[1]), unorm8(out[2]), unorm8(out[3]));
      for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) ASSERT_EQ(fb.color_at(x, y), want) << std::hex << want;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Culling and facing.

// Green where the fragment is front-facing, blue where back-facing.
struct FacingShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions = nullptr;
  glm::vec4 vertex(uint32_t i, float*) const { return positions[i]; }
  bool fragment(FragmentInput& in, glm::vec4& color) const {
    color = in.front_facing ? glm::vec4(0, 1, 0, 1) : glm::vec4(0, 0, 1, 1);
    return true;
  }
};

TEST_P(Pipeline, CullingAndFacing) {
  constexpr int kN = 32;
  auto at = [](double x, double y) { return window_to_clip(x, y, kN, kN); };
  // Left half: counter-clockwise in the image (top, bottom-left, bottom-right); right half:
  // clockwise (top, bottom-right, bottom-left).
  const std::vector<glm::vec4> pos{at(8, 4),  at(2, 28),  at(14, 28),
                                   at(24, 4), at(30, 28), at(18, 28)};
  const std::vector<uint32_t> idx{0, 1, 2, 3, 4, 5};
  const uint32_t green = pack(0, 255, 0, 255), blue = pack(0, 0, 255, 255);
  for (FrontFace face : {FrontFace::kCounterClockwise, FrontFace::kClockwise}) {
    for (CullMode cull : {CullMode::kNone, CullMode::kBack, CullMode::kFront}) {
      SCOPED_TRACE("front face " + std::to_string(int(face)) + " cull " +
                   std::to_string(int(cull)));
      FacingShader shader{pos.data()};
      Framebuffer fb(kN, kN);
      fb.clear_color({0, 0, 0, 0});
      RenderState s = state();
      s.front_face = face;
      s.cull = cull;
      draw(fb, s, shader, idx, uint32_t(pos.size()));
      bool ccw_front = face == FrontFace::kCounterClockwise;
      // (ccw triangle front?, drawn?) and the same for the cw triangle.
      const bool ccw_drawn = cull == CullMode::kNone || (cull == CullMode::kBack) == ccw_front;
      const bool cw_drawn = cull == CullMode::kNone || (cull == CullMode::kBack) == !ccw_front;
      uint32_t ccw_pixel = fb.color_at(8, 20), cw_pixel = fb.color_at(24, 20);
      EXPECT_EQ(ccw_pixel, !ccw_drawn ? kCleared : ccw_front ? green : blue);
      EXPECT_EQ(cw_pixel, !cw_drawn ? kCleared : !ccw_front ? green : blue);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Lines: the diamond-exit rule by its definition (OpenGL 3.4.1, D3D "aliased lines"): pixel f
// is drawn when the segment intersects its diamond |x - cx| + |y - cy| < 1/2, unless the
// segment's end lies inside that diamond; the endpoints are first perturbed by (e, e^2) in GL's
// y-up window coordinates, (e, -e^2) in these y-down ones, so that no tie remains. Brute force over
// pixels: f(p) = |px - cx| + |py - cy| is convex and piecewise linear along the segment, so its
// minimum is at an end or where the segment crosses x = cx or y = cy.

using Pixel = std::pair<int, int>;

double diamond_distance(glm::dvec2 p, glm::dvec2 centre) {
  return std::abs(p.x - centre.x) + std::abs(p.y - centre.y);
}

bool segment_meets_diamond(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  double best = std::min(diamond_distance(a, c), diamond_distance(b, c));
  for (int axis = 0; axis < 2; ++axis) {
    if (a[axis] == b[axis]) continue;
    double t = (c[axis] - a[axis]) / (b[axis] - a[axis]);
    if (t > 0.0 && t < 1.0) best = std::min(best, diamond_distance(a + t * (b - a), c));
  }
  return best < 0.5;
}

std::vector<Pixel> expected_line(glm::dvec2 a, glm::dvec2 b) {
  bool x_major = std::abs(b.x - a.x) >= std::abs(b.y - a.y);
  const glm::dvec2 perturbation(1.0e-5, -1.0e-10);
  a += perturbation;
  b += perturbation;
  std::vector<Pixel> out;
  for (int j = -8; j < 64; ++j) {
    for (int i = -8; i < 64; ++i) {
      glm::dvec2 c(i + 0.5, j + 0.5);
      if (segment_meets_diamond(a, b, c) && !(diamond_distance(b, c) < 0.5)) out.push_back({i, j});
    }
  }
  // Along the major axis, so that consecutive pixels are neighbours.
  std::sort(out.begin(), out.end(), [&](Pixel p, Pixel q) {
    double dp = x_major ? p.first : p.second, dq = x_major ? q.first : q.second;
    double dir = x_major ? b.x - a.x : b.y - a.y;
    return dir > 0 ? dp < dq : dp > dq;
  });
  return out;
}

std::vector<int> draw_lines(int size, const RenderState& s, const std::vector<glm::dvec2>& pts) {
  std::vector<glm::vec4> clip;
  for (glm::dvec2 p : pts) {
    EXPECT_TRUE(test::window_to_clip_is_exact(p.x, p.y, size, size));
    clip.push_back(window_to_clip(p.x, p.y, size, size));
  }
  std::vector<uint32_t> idx(pts.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
  return count_hits(size, size, s, clip, idx);
}

// The same definition in 80-bit long double for random short segments on the 1/256 grid, many
// of them with exact ties (endpoints on pixel centres, pixel edges and diamond corners). The
// perturbation (1e-9, -1e-15) is far below the smallest non-tie distance of such segments (about
// 2e-6 px), yet its e^2 term is far above long double's resolution.
using LPoint = std::array<long double, 2>;

long double ldiamond(LPoint p, LPoint c) {
  return std::fabs(p[0] - c[0]) + std::fabs(p[1] - c[1]);
}

std::set<Pixel> exact_line(LPoint a, LPoint b) {
  const long double e = 1.0e-9L, e2 = 1.0e-15L;
  a = {a[0] + e, a[1] - e2};
  b = {b[0] + e, b[1] - e2};
  std::set<Pixel> out;
  for (int j = -2; j < 20; ++j) {
    for (int i = -2; i < 20; ++i) {
      LPoint c{i + 0.5L, j + 0.5L};
      long double best = std::min(ldiamond(a, c), ldiamond(b, c));
      for (int axis = 0; axis < 2; ++axis) {
        if (a[axis] == b[axis]) continue;
        long double t = (c[axis] - a[axis]) / (b[axis] - a[axis]);
        if (t > 0 && t < 1) {
          best = std::min(best, ldiamond({a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])}, c));
        }
      }
      if (best < 0.5L && !(ldiamond(b, c) < 0.5L)) out.insert({i, j});
    }
  }
  return out;
}

TEST_P(Pipeline, RandomShortLinesFollowTheDiamondExitDefinition) {
  constexpr int kN = 16;
  RenderState s = counting_state(GetParam());
  s.primitive = Primitive::kLines;
  std::mt19937 rng(11);
  // Coordinates in 1/256 px; half of them snapped to a 1/2-pixel lattice to make ties common.
  std::uniform_int_distribution<int> coord(2 * 256, 14 * 256), coarse(4, 28);
  for (int n = 0; n < 3000; ++n) {
    auto pick = [&] { return n % 2 ? coarse(rng) * 128 : coord(rng); };
    int ax = pick(), ay = pick(), bx = pick(), by = pick();
    if (ax == bx && ay == by) continue;
    glm::dvec2 a(ax / 256.0, ay / 256.0), b(bx / 256.0, by / 256.0);
    auto hits = draw_lines(kN, s, {a, b});
    std::set<Pixel> want = exact_line({ax / 256.0L, ay / 256.0L}, {bx / 256.0L, by / 256.0L});
    std::set<Pixel> got;
    for (int y = 0; y < kN; ++y) {
      for (int x = 0; x < kN; ++x) {
        if (hits[size_t(y) * kN + x]) got.insert({x, y});
        EXPECT_LE(hits[size_t(y) * kN + x], 1);
      }
    }
    ASSERT_EQ(got, want) << "line " << ax << "," << ay << " -> " << bx << "," << by
                         << " (1/256 px)";
  }
}

TEST_P(Pipeline, LinesInAllEightOctants) {
  constexpr int kN = 32;
  RenderState s = counting_state(GetParam());
  s.primitive = Primitive::kLines;
  const glm::dvec2 ends[] = {{11, 4},  {4, 11},  {-4, 11}, {-11, 4}, {-11, -4}, {-4, -11},
                             {4, -11}, {11, -4}, {9, 9},   {-9, 9},  {-9, -9},  {9, -9},
                             {13, 0},  {0, 13},  {-13, 0}, {0, -13}};
  const double e = 1.0 / 256.0;
  for (bool on_centres : {true, false}) {
    for (glm::dvec2 d : ends) {
      glm::dvec2 a{16.5, 16.5}, b = a + d;
      if (!on_centres) a += glm::dvec2(3 * e, -5 * e), b += glm::dvec2(-7 * e, 9 * e);
      SCOPED_TRACE("line from " + std::to_string(a.x) + ", " + std::to_string(a.y) + " to " +
                   std::to_string(b.x) + ", " + std::to_string(b.y));
      auto hits = draw_lines(kN, s, {a, b});
      auto want = expected_line(a, b);
      std::vector<int> want_map(kN * kN);
      for (auto [x, y] : want) want_map[size_t(y) * kN + x] = 1;
      EXPECT_EQ(hits, want_map) << "expected:\n"
                                << ascii_map(want_map, kN, kN) << "actual:\n"
                                << ascii_map(hits, kN, kN);
      // Properties of the expectation itself: one pixel per major-axis step, connected, and for
      // endpoints on pixel centres the start pixel is in and the end pixel out.
      double major = std::max(std::abs(b.x - a.x), std::abs(b.y - a.y));
      EXPECT_NEAR(double(want.size()), major, 1.0);
      for (size_t k = 1; k < want.size(); ++k) {
        EXPECT_LE(std::abs(want[k].first - want[k - 1].first), 1);
        EXPECT_LE(std::abs(want[k].second - want[k - 1].second), 1);
      }
      if (on_centres) {
        EXPECT_EQ(hits[16 * kN + 16], 1) << "start pixel";
        EXPECT_EQ(hits[size_t(b.y) * kN + size_t(b.x)], 0) << "end pixel";
        EXPECT_EQ(int(want.size()), int(major));
      }
    }
  }
}

// Consecutive segments of a strip share their end and start pixel exactly once.
TEST_P(Pipeline, ConnectedLinesDrawTheSharedPixelOnce) {
  RenderState s = counting_state(GetParam());
  s.primitive = Primitive::kLines;
  const glm::dvec2 p0{3.5, 4.5}, p1{20.5, 9.5}, p2{12.5, 27.5}, p3{2.5, 20.5};
  auto hits = draw_lines(32, s, {p0, p1, p1, p2, p2, p3, p3, p0});
  EXPECT_LE(*std::max_element(hits.begin(), hits.end()), 1) << ascii_map(hits, 32, 32);
  for (glm::dvec2 p : {p0, p1, p2, p3}) EXPECT_EQ(hits[size_t(p.y) * 32 + size_t(p.x)], 1);
}

TEST_P(Pipeline, PointsDrawExactlyTheirPixel) {
  constexpr int kN = 32;
  RenderState s = counting_state(GetParam());
  s.primitive = Primitive::kPoints;
  struct Case {
    glm::dvec2 p;
    int x, y;  // -1: nothing
  };
  const Case cases[] = {{{3.0, 5.0}, 3, 5},
                        {{12.5, 9.5}, 12, 9},
                        {{7 + 255.0 / 256, 2.0}, 7, 2},
                        {{0.0, 0.0}, 0, 0},
                        {{31 + 255.0 / 256, 31 + 255.0 / 256}, 31, 31},
                        {{32.0, 5.0}, -1, -1}};  // on the right border: outside the image
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.p.x) + ", " + std::to_string(c.p.y));
    auto hits = draw_lines(kN, s, {c.p});
    for (int y = 0; y < kN; ++y) {
      for (int x = 0; x < kN; ++x) {
        EXPECT_EQ(hits[size_t(y) * kN + x], x == c.x && y == c.y ? 1 : 0) << x << ", " << y;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Discard.

struct CheckerDiscardShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions = nullptr;
  glm::vec4 vertex(uint32_t i, float*) const { return positions[i]; }
  bool fragment(FragmentInput& in, glm::vec4& color) const {
    color = {1, 0, 0, 1};
    return (int(in.position.x) + int(in.position.y)) % 2 == 0;
  }
};

TEST_P(Pipeline, DiscardLeavesColourAndDepthUntouched) {
  auto quad = screen_quad(0.0f);
  CheckerDiscardShader shader{quad.data()};
  Framebuffer fb(kS, kS);
  fb.clear_color({0, 0, 0, 0});
  fb.clear_depth(1.0f);
  draw(fb, state(), shader, kQuad, 4);
  for (int y = 0; y < kS; ++y) {
    for (int x = 0; x < kS; ++x) {
      bool kept = (x + y) % 2 == 0;
      EXPECT_EQ(fb.color_at(x, y), kept ? kRed : kCleared) << x << ", " << y;
      EXPECT_EQ(fb.depth_at(x, y), kept ? 0.5f : 1.0f) << x << ", " << y;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Wireframe: the three edges as lines (v0->v1, v1->v2, v2->v0), after culling.

TEST_P(Pipeline, WireframeDrawsTheEdgesOnly) {
  constexpr int kN = 32;
  // Clockwise in the image: back-facing by default.
  const glm::dvec2 v0{2.5, 2.5}, v1{25.5, 6.5}, v2{9.5, 28.5};
  for (bool reversed : {false, true}) {
    for (CullMode cull : {CullMode::kNone, CullMode::kBack}) {
      SCOPED_TRACE(std::string(reversed ? "counter-clockwise" : "clockwise") + " cull " +
                   std::to_string(int(cull)));
      RenderState s = counting_state(GetParam());
      s.wireframe = true;
      s.cull = cull;
      std::vector<glm::dvec2> tri = reversed ? std::vector{v0, v2, v1} : std::vector{v0, v1, v2};
      auto hits = draw_lines(kN, s, tri);
      std::set<Pixel> want;
      bool culled = cull == CullMode::kBack && !reversed;
      if (!culled) {
        for (int k = 0; k < 3; ++k) {
          for (Pixel p : expected_line(tri[k], tri[(k + 1) % 3])) want.insert(p);
        }
      }
      for (int y = 0; y < kN; ++y) {
        for (int x = 0; x < kN; ++x) {
          EXPECT_EQ(hits[size_t(y) * kN + x] > 0, want.count({x, y}) == 1) << x << ", " << y;
        }
      }
      if (!culled) {
        EXPECT_EQ(hits[13 * kN + 12], 0) << "interior pixel";
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Depth bias: added to every window depth before the depth test, for every primitive type.

TEST_P(Pipeline, DepthBiasAppliesToAllPrimitives) {
  constexpr int kN = 16;
  struct Case {
    Primitive primitive;
    std::vector<glm::dvec2> points;
    int x, y;  // a pixel the primitive covers
  };
  const Case cases[] = {
      {Primitive::kTriangles, {{0, 0}, {16, 0}, {0, 16}}, 2, 2},
      {Primitive::kLines, {{1.5, 5.5}, {12.5, 5.5}}, 3, 5},
      {Primitive::kPoints, {{7.5, 9.5}}, 7, 9},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("primitive " + std::to_string(int(c.primitive)));
    std::vector<glm::vec4> clip;
    for (glm::dvec2 p : c.points) clip.push_back(window_to_clip(p.x, p.y, kN, kN));  // depth 0.5
    std::vector<uint32_t> idx(clip.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
    ClipSpaceShader shader;
    shader.positions = clip.data();
    shader.color = {1, 0, 0, 1};
    Framebuffer fb(kN, kN);
    fb.clear_color({0, 0, 0, 0});
    fb.clear_depth(0.375f);  // in front of 0.5, behind 0.5 - 0.25
    RenderState s = state();
    s.primitive = c.primitive;
    s.cull = CullMode::kNone;
    s.depth_bias = -0.25f;
    draw(fb, s, shader, idx, uint32_t(clip.size()));
    EXPECT_EQ(fb.color_at(c.x, c.y), kRed);
    EXPECT_EQ(fb.depth_at(c.x, c.y), 0.25f);
  }
}

using test::algorithm_name;

INSTANTIATE_TEST_SUITE_P(BothRasterizers, Pipeline,
                         testing::Values(RasterAlgorithm::kEdgeEquations,
                                         RasterAlgorithm::kScanline),
                         algorithm_name);

}  // namespace
}  // namespace softrast

namespace softrast {
namespace {

// pack_rgba8 (vectorised where SSE2 exists) against to_unorm8 per channel, the conventions'
// x * 255 + 0.5 truncated after clamping, on every tie, both clamps, NaN and infinities.
// ---------------------------------------------------------------------------------------------
// The vertex stage of a draw that names few of its vertices.

// Counts its calls per vertex; colours each vertex by its own varyings.
struct NamedVerticesShader {
  static constexpr int kVaryings = 3;
  const glm::vec4* positions = nullptr;
  const glm::vec3* colours = nullptr;
  std::atomic<int>* calls = nullptr;  // per vertex
  glm::vec4 vertex(uint32_t i, float* out) const {
    ++calls[i];
    out[0] = colours[i].r, out[1] = colours[i].g, out[2] = colours[i].b;
    return positions[i];
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    f.color = {f.varying(0), f.varying(1), f.varying(2), simd::Float<N>(1.0f)};
  }
};

// One draw of a few triangles over a large vertex array (an OBJ material run, a glTF primitive)
// runs the vertex shader once for each vertex it names and for no other (shading all of them
// made many small draws quadratic), and draws what the same triangles draw when every vertex is
// shaded: colour and depth bit for bit, with perspective (w from 0.5 to 4), the array's last
// vertex and an out-of-range index among them, for two draws in a row.
TEST(VertexStage, ADrawOfFewIndicesShadesOnlyTheVerticesItNames) {
  constexpr int kWidth = 96, kHeight = 64;
  constexpr uint32_t kVertices = 1000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<glm::vec4> positions;
  std::vector<glm::vec3> colours;
  for (uint32_t i = 0; i < kVertices; ++i) {
    float w = 0.5f + 3.5f * unit(rng);
    positions.push_back(
        glm::vec4(2.0f * unit(rng) - 1.0f, 2.0f * unit(rng) - 1.0f, unit(rng), 1.0f) * w);
    colours.push_back({unit(rng), unit(rng), unit(rng)});
  }
  std::uniform_int_distribution<uint32_t> any_vertex(0, kVertices - 1);
  RenderState state;
  state.cull = CullMode::kNone;
  state.threads = 2;
  auto render = [&](std::span<const uint32_t> draw_indices, std::vector<std::atomic<int>>& calls) {
    Framebuffer fb(kWidth, kHeight);
    fb.clear();
    NamedVerticesShader shader{positions.data(), colours.data(), calls.data()};
    draw(fb, state, shader, draw_indices, kVertices);
    return std::make_pair(fb.to_image(), fb.depth_values());
  };

  // Two draws one after the other (the second's vertices partly the first's), each against the
  // same triangles padded with zero-area ones (which draw nothing) to as many indices as
  // vertices, so that every vertex is shaded.
  for (int pass = 0; pass < 2; ++pass) {
    SCOPED_TRACE(pass == 0 ? "first draw" : "second draw");
    std::vector<uint32_t> indices;
    for (int t = 0; t < 20; ++t) {
      for (int k = 0; k < 3; ++k) indices.push_back(any_vertex(rng));
    }
    indices.insert(indices.end(), {kVertices - 1, 3, 500});  // the last vertex
    indices.insert(indices.end(), {kVertices + 5, 10, 20});  // out of range: skipped
    ASSERT_LT(indices.size(), size_t(kVertices));

    std::vector<std::atomic<int>> calls(kVertices);
    auto [image, depth] = render(indices, calls);
    std::set<uint32_t> named(indices.begin(), indices.end());
    for (uint32_t i = 0; i < kVertices; ++i) {
      ASSERT_EQ(calls[i].load(), named.count(i) ? 1 : 0) << "vertex " << i;
    }

    std::vector<uint32_t> padded = indices;
    padded.resize(kVertices, 0u);
    std::vector<std::atomic<int>> all_calls(kVertices);
    auto [reference_image, reference_depth] = render(padded, all_calls);
    for (uint32_t i = 0; i < kVertices; ++i) ASSERT_EQ(all_calls[i].load(), 1) << "vertex " << i;
    int drawn = 0;
    for (float z : depth) drawn += z < 1.0f;
    EXPECT_GT(drawn, kWidth * kHeight / 10);  // the triangles cover a good part of the image
    EXPECT_EQ(image.rgba, reference_image.rgba);
    EXPECT_EQ(depth, reference_depth);
  }
}

TEST(ColourPacking, PackMatchesTheScalarConversionEverywhere) {
  std::vector<float> values = {0.0f,  1.0f,   -0.0f,         -1.0f,        2.0f,
                               1e30f, -1e30f, std::nanf(""), INFINITY,     -INFINITY,
                               0.3f,  0.7f,   0.5f,          1.0f / 255.0f};
  for (int k = 0; k <= 510; ++k) values.push_back(float(k) / 510.0f);  // every tie and step
  for (float r : values) {
    glm::vec4 c(r, 1.0f - r, r * 0.5f, r);
    uint32_t want = uint32_t(to_unorm8(c.r)) | uint32_t(to_unorm8(c.g)) << 8 |
                    uint32_t(to_unorm8(c.b)) << 16 | uint32_t(to_unorm8(c.a)) << 24;
    ASSERT_EQ(pack_rgba8(c), want) << r;
  }
  EXPECT_EQ(to_unorm8(0.3f), 77);  // 76.5 rounds up (CONVENTIONS.md)
  EXPECT_EQ(to_unorm8(std::nanf("")), 0);
}

}  // namespace
}  // namespace softrast
