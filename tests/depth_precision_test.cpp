// The depth of steep slivers: every covered pixel's stored depth within one unit of 2^-24 of the
// exact depth (the plane through the three window-space vertices, in double), on every path that
// computes depth (deferred resolve with either rasterizer, immediate wide shading, the scalar
// fragment stage) and at every SIMD level the machine has. A sliver a few 1/256 pixel wide has
// depth gradients in the hundreds per pixel, so the terms of its plane equation are far larger
// than the depth itself: the set is checked to be one where a float evaluation of the same plane
// is off by more than one unit (the error this pins, up to 350 units before the plane went to
// double), independently of llvmpipe (conformance_test.cpp's depth class compares with it too).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "softrast/shader.hpp"
#include "softrast/simd_level.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

constexpr int kSize = 64;
constexpr double kUnit = 1.0 / 16777216.0;  // 2^-24

struct Tri {
  double x[3], y[3], z[3];  // window coordinates (pixels, y down) and depth in [0, 1]
};

// Clip-space position of a window-space vertex of a kSize x kSize image, w = 1 (every value is on
// a grid that float holds exactly, so the window vertices are exactly x, y, z).
glm::vec4 clip_of(double x, double y, double z) {
  return glm::vec4(float(2.0 * x / kSize - 1.0), float(1.0 - 2.0 * y / kSize), float(2.0 * z - 1.0),
                   1.0f);
}

struct WideShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions;
  glm::vec4 vertex(uint32_t i, float*) const { return positions[i]; }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    f.color = {simd::Float<N>(1.0f), simd::Float<N>(1.0f), simd::Float<N>(1.0f),
               simd::Float<N>(1.0f)};
  }
};

struct ScalarShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions;
  glm::vec4 vertex(uint32_t i, float*) const { return positions[i]; }
  bool fragment(FragmentInput&, glm::vec4& out) const {
    out = glm::vec4(1.0f);
    return true;
  }
};

// Slivers: a long edge between two grid points and a third vertex 1 to 12 / 256 pixel off it
// (on the 1/256 grid too), depths on a 2^-20 grid.
std::vector<Tri> slivers(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(4 * 256, 60 * 256), off(1, 12), depth(0, 1 << 20);
  std::uniform_real_distribution<double> t(0.1, 0.9);
  std::vector<Tri> out;
  while (int(out.size()) < count) {
    int x0 = coord(rng), y0 = coord(rng), x1 = coord(rng), y1 = coord(rng);
    double len = std::hypot(double(x1 - x0), double(y1 - y0));
    if (len < 20 * 256) continue;
    double s = t(rng);
    // A point on the edge, moved `off` grid steps along the edge's normal, rounded to the grid.
    double nx = -(y1 - y0) / len, ny = (x1 - x0) / len;
    int d = off(rng);
    long x2 = std::lround(x0 + s * (x1 - x0) + d * nx),
         y2 = std::lround(y0 + s * (y1 - y0) + d * ny);
    Tri tri;
    int xs[3] = {x0, x1, int(x2)}, ys[3] = {y0, y1, int(y2)};
    for (int k = 0; k < 3; ++k) {
      tri.x[k] = xs[k] / 256.0;
      tri.y[k] = ys[k] / 256.0;
      tri.z[k] = std::ldexp(double(depth(rng)), -20);
    }
    double area = (tri.x[1] - tri.x[0]) * (tri.y[2] - tri.y[0]) -
                  (tri.x[2] - tri.x[0]) * (tri.y[1] - tri.y[0]);
    if (area == 0.0) continue;
    out.push_back(tri);
  }
  return out;
}

// The exact depth plane at pixel centre (px + 0.5, py + 0.5): grid coordinates make every
// product below exact in double but the division (and the final sums round once each).
double exact_depth(const Tri& t, int px, int py) {
  double x = px + 0.5, y = py + 0.5;
  double a = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
  double b1 = ((x - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (y - t.y[0])) / a;
  double b2 = ((t.x[1] - t.x[0]) * (y - t.y[0]) - (x - t.x[0]) * (t.y[1] - t.y[0])) / a;
  return t.z[0] + b1 * (t.z[1] - t.z[0]) + b2 * (t.z[2] - t.z[0]);
}

// The same plane evaluated the way a float plane equation does it: gradients and a0 rounded to
// float, the sum in float, referenced at vertex 0.
float float_depth(const Tri& t, int px, int py) {
  double a = (t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
  double dz1 = t.z[1] - t.z[0], dz2 = t.z[2] - t.z[0];
  float dzdx = float((dz1 * (t.y[2] - t.y[0]) - dz2 * (t.y[1] - t.y[0])) / a);
  float dzdy = float((dz2 * (t.x[1] - t.x[0]) - dz1 * (t.x[2] - t.x[0])) / a);
  float dx = float(px) + 0.5f - float(t.x[0]), dy = float(py) + 0.5f - float(t.y[0]);
  return float(t.z[0]) + dzdx * dx + dzdy * dy;
}

struct Outcome {
  long pixels = 0;        // covered pixels checked
  long beyond_unit = 0;   // stored depth more than one unit from the exact one
  double worst = 0.0;     // the largest error, in units
  long float_beyond = 0;  // pixels where a float plane would be more than one unit off
};

// Draws each sliver alone into a cleared framebuffer and compares every pixel it wrote.
template <class Shader>
Outcome run(const std::vector<Tri>& tris, const RenderState& state) {
  Outcome o;
  Framebuffer fb(kSize, kSize);
  for (const Tri& t : tris) {
    fb.clear(glm::vec4(0.0f), 1.0f);
    glm::vec4 p[3];
    for (int k = 0; k < 3; ++k) p[k] = clip_of(t.x[k], t.y[k], t.z[k]);
    Shader shader{p};
    std::vector<uint32_t> indices = {0, 1, 2};
    draw(fb, state, shader, indices, 3);
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        if (fb.color_at(x, y) == 0) continue;  // not covered (cleared to transparent black)
        double exact = std::clamp(exact_depth(t, x, y), 0.0, 1.0);
        double error = std::abs(double(fb.depth_at(x, y)) - exact) / kUnit;
        o.pixels++;
        o.beyond_unit += error > 1.0;
        o.worst = std::max(o.worst, error);
        double float_error =
            std::abs(double(std::clamp(float_depth(t, x, y), 0.0f, 1.0f)) - exact) / kUnit;
        o.float_beyond += float_error > 1.0;
      }
    }
  }
  return o;
}

void expect_within_one_unit(const Outcome& o, const std::string& what) {
  SCOPED_TRACE(what);
  std::printf(
      "[ %s ] %ld covered pixels, largest error %.3f units, %ld beyond one unit (a float "
      "plane: %ld)\n",
      what.c_str(), o.pixels, o.worst, o.beyond_unit, o.float_beyond);
  EXPECT_GT(o.pixels, 1000);
  EXPECT_EQ(o.beyond_unit, 0);
  EXPECT_LE(o.worst, 1.0);
  // The set is steep enough to matter: a float evaluation of the same planes fails it.
  EXPECT_GT(o.float_beyond, 0);
}

TEST(DepthPrecision, SteepSliversWithinOneUnitOnEveryPathAndLevel) {
  std::vector<Tri> tris = slivers(3000, 7);
  SimdLevel saved = simd_level();
  for (SimdLevel level : test::levels_of_this_cpu()) {
    set_simd_level(level);
    std::string at = std::string(" at ") + simd_level_name(level);
    RenderState deferred;  // opaque, depth less with writes, a shader that may be deferred
    deferred.threads = 1;
    deferred.cull = CullMode::kNone;
    expect_within_one_unit(run<WideShader>(tris, deferred), "deferred, edge equations" + at);
    RenderState scanline = deferred;
    scanline.raster = RasterAlgorithm::kScanline;
    expect_within_one_unit(run<WideShader>(tris, scanline), "deferred, scanline" + at);
    RenderState immediate = deferred;
    immediate.blend = BlendMode::kAlpha;  // not deferrable: the wide fragment stage tests depth
    expect_within_one_unit(run<WideShader>(tris, immediate), "immediate, wide" + at);
    expect_within_one_unit(run<ScalarShader>(tris, deferred), "immediate, scalar" + at);
  }
  set_simd_level(saved);
}

}  // namespace
}  // namespace softrast
