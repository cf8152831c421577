// tests/clip_test.cpp: clipping in homogeneous clip space. Through the public draw API with a
// perspective camera, against the analytic region a ray-cast of every pixel centre finds: a floor
// crossing the near plane, triangles partly or wholly behind the camera, enormous coordinates,
// NaN and Inf, the far plane. Then clip_triangle / clip_line themselves: shared edges cut into
// bit-identical vertices, every output vertex has w > 0 and lies in the volume, and the polygon
// never outgrows its buffer.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "geometry/clip.hpp"
#include "geometry/viewport.hpp"
#include "softrast/camera.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

using detail::ClipVertex;
using detail::ClipVolume;
using detail::kMaxClippedVertices;
using test::ascii_map;
using test::count_hits;
using test::counting_state;
using test::Expect;
using test::FloorOracle;
using test::WorldShader;

using test::algorithm_name;

int total(const std::vector<int>& hits) {
  int n = 0;
  for (int h : hits) n += h;
  return n;
}

// ---------------------------------------------------------------------------------------------
// Through draw(): a camera 0.3 above the floor y = 0, looking 50 degrees down, near plane at 0.5.
// The near plane cuts the floor in a line across the image.

constexpr int kW = 160, kH = 120;

glm::dmat4 floor_camera() {
  const glm::dvec3 eye{0.0, 0.3, 0.0};
  const glm::dvec3 forward{0.0, -std::sin(0.87), -std::cos(0.87)};
  return glm::perspective(glm::radians(90.0), double(kW) / kH, 0.5, 100.0) *
         glm::lookAt(eye, eye + forward, glm::dvec3(0, 1, 0));
}

struct OracleResult {
  int inside = 0, outside = 0, unsure = 0, wrong = 0;
};

// Draws the floor polygon (a convex fan, xz coordinates, y = 0) and compares every pixel with the
// ray-cast. Pixels within 0.01 px of the analytic boundary may go either way, but never twice.
OracleResult draw_floor_polygon(RasterAlgorithm raster, const std::vector<glm::dvec2>& xz) {
  std::vector<glm::dvec3> points;
  for (glm::dvec2 p : xz) points.push_back({p.x, 0.0, p.y});
  std::vector<uint32_t> indices;
  for (uint32_t k = 1; k + 1 < points.size(); ++k) indices.insert(indices.end(), {0, k, k + 1});
  Framebuffer fb(kW, kH);
  fb.clear_color({0, 0, 0, 0});
  WorldShader shader;
  shader.positions = points.data();
  shader.view_proj = floor_camera();
  draw(fb, counting_state(raster), shader, indices, uint32_t(points.size()));
  auto hits = test::red_counts(fb);

  FloorOracle oracle(floor_camera(), kW, kH, 0.0, xz);
  OracleResult r;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      int h = hits[size_t(y) * kW + x];
      Expect e = oracle.classify(x, y);
      r.inside += e == Expect::kIn;
      r.outside += e == Expect::kOut;
      r.unsure += e == Expect::kUnsure;
      bool ok = e == Expect::kIn ? h == 1 : e == Expect::kOut ? h == 0 : h <= 1;
      if (!ok && ++r.wrong <= 10) {
        ADD_FAILURE() << "pixel " << x << ", " << y << " hit " << h << " times, expected "
                      << (e == Expect::kIn    ? "once"
                          : e == Expect::kOut ? "never"
                                              : "at most once");
      }
    }
  }
  if (r.wrong) ADD_FAILURE() << r.wrong << " wrong pixels\n" << ascii_map(hits, kW, kH);
  return r;
}

// The clip-space w of a floor point: the sign says in front of (> 0) or behind the camera.
double clip_w(glm::dvec2 xz) {
  return (floor_camera() * glm::dvec4(xz.x, 0.0, xz.y, 1.0)).w;
}

class ClipDraw : public testing::TestWithParam<RasterAlgorithm> {};

TEST_P(ClipDraw, FloorQuadCrossingTheNearPlane) {
  // Reaches from 30 units ahead to 2 units behind the camera.
  std::vector<glm::dvec2> quad{{-4, -30}, {4, -30}, {4, 2}, {-4, 2}};
  ASSERT_LT(clip_w(quad[2]), 0.0);
  OracleResult r = draw_floor_polygon(GetParam(), quad);
  EXPECT_EQ(r.wrong, 0);
  EXPECT_GT(r.inside, kW * kH / 5);  // the floor fills a good part of the image
  EXPECT_GT(r.outside, kW * kH / 10);
  EXPECT_LT(r.unsure, kW * 3);  // boundary pixels only
}

TEST_P(ClipDraw, TrianglesWithVerticesBehindTheCamera) {
  struct Case {
    const char* name;
    std::vector<glm::dvec2> xz;
    int behind;
  };
  const Case cases[] = {
      {"one behind", {{-3, -6}, {3, -6}, {0, 3}}, 1},
      {"two behind", {{-3, 3}, {3, 3}, {0.5, -8}}, 2},
      {"three behind", {{-3, 2}, {3, 2}, {0, 4}}, 3},
      {"one behind, far off to the side", {{-40, 1}, {1, -2}, {2, -0.5}}, 1},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    int behind = 0;
    for (glm::dvec2 p : c.xz) behind += clip_w(p) < 0.0;
    ASSERT_EQ(behind, c.behind);
    OracleResult r = draw_floor_polygon(GetParam(), c.xz);
    EXPECT_EQ(r.wrong, 0);
    if (c.behind < 3) {
      EXPECT_GT(r.inside, 500);  // the visible part is drawn
    } else {
      EXPECT_EQ(r.inside, 0);
    }
  }
}

// Clip-space triangles with w < 0 everywhere, whose naive division would land on screen.
TEST_P(ClipDraw, TrianglesEntirelyBehindTheCameraDrawNothing) {
  const std::vector<std::vector<glm::vec4>> triangles = {
      {{0.5f, 0.5f, 0.0f, -1.0f}, {-0.5f, 0.5f, 0.0f, -1.0f}, {0.0f, -0.5f, 0.0f, -1.0f}},
      {{0.5f, 0.5f, 0.5f, -1.0f}, {-0.5f, 0.5f, 0.5f, -1.0f}, {0.0f, -0.5f, 0.9f, -1.0f}},
      {{3.0f, 3.0f, 3.0f, -3.0f}, {-3.0f, 3.0f, 3.0f, -3.0f}, {0.0f, -3.0f, -0.5f, -0.5f}},
      {{0.5f, 0.5f, 0.0f, 0.0f}, {-0.5f, 0.5f, 0.0f, 0.0f}, {0.0f, -0.5f, 0.0f, 0.0f}},  // w = 0
  };
  for (size_t k = 0; k < triangles.size(); ++k) {
    SCOPED_TRACE("triangle " + std::to_string(k));
    std::vector<uint32_t> idx{0, 1, 2};
    EXPECT_EQ(total(count_hits(64, 64, counting_state(GetParam()), triangles[k], idx)), 0);
  }
}

// Enormous coordinates are clipped to the guard band; what is left still covers the image
// exactly once.
TEST_P(ClipDraw, HugeTrianglesCoverEveryPixelOnce) {
  for (float k : {1.0e7f, 1.0e30f}) {
    for (auto [w, h] : {std::pair{100, 75}, std::pair{64, 64}}) {
      SCOPED_TRACE("+-" + std::to_string(k) + " in a " + std::to_string(w) + "x" +
                   std::to_string(h) + " image");
      std::vector<glm::vec4> tri{{-k, -k, 0, 1}, {k, -k, 0, 1}, {0, k, 0, 1}};
      std::vector<uint32_t> one{0, 1, 2};
      auto hits = count_hits(w, h, counting_state(GetParam()), tri, one);
      EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int c) { return c == 1; }))
          << "triangle\n"
          << ascii_map(hits, w, h);
      std::vector<glm::vec4> quad{{-k, -k, 0, 1}, {k, -k, 0, 1}, {k, k, 0, 1}, {-k, k, 0, 1}};
      std::vector<uint32_t> two{0, 1, 2, 0, 2, 3};
      hits = count_hits(w, h, counting_state(GetParam()), quad, two);
      EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](int c) { return c == 1; }))
          << "quad\n"
          << ascii_map(hits, w, h);
    }
  }
}

// A depth state in which a drawn pixel changes both colour and depth.
RenderState depth_writing_state(RasterAlgorithm raster, Primitive primitive) {
  RenderState s = counting_state(raster);
  s.primitive = primitive;
  s.depth_test = true;
  s.depth_func = DepthFunc::kAlways;
  s.depth_write = true;
  return s;
}

// Draws and returns whether any pixel's colour or depth changed.
bool draws_anything(const RenderState& state, const std::vector<glm::vec4>& pos,
                    const std::vector<uint32_t>& idx) {
  Framebuffer fb(32, 32);
  fb.clear_color({0, 0, 0, 0});
  fb.clear_depth(1.0f);
  test::ClipSpaceShader shader;
  shader.positions = pos.data();
  draw(fb, state, shader, idx, uint32_t(pos.size()));
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (fb.color_at(x, y) != 0 || fb.depth_at(x, y) != 1.0f) return true;
    }
  }
  return false;
}

TEST_P(ClipDraw, NonFinitePositionsDrawNothing) {
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                       std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  struct Prim {
    Primitive primitive;
    std::vector<glm::vec4> pos;
  };
  const Prim prims[] = {
      {Primitive::kTriangles, {{-3, -3, 0, 1}, {3, -3, 0, 1}, {0, 3, 0, 1}}},
      {Primitive::kTriangles, {{-0.5f, -0.5f, 0, 1}, {3, -3, 0, 1}, {0, 3, 0, -1}}},  // clipped
      {Primitive::kLines, {{-0.9f, -0.8f, 0, 1}, {0.9f, 0.7f, 0, 1}}},
      {Primitive::kLines, {{-0.9f, -0.8f, 0, 1}, {9.0f, 0.7f, 0, -1}}},  // clipped
      {Primitive::kPoints, {{0.1f, 0.2f, 0, 1}}},
  };
  for (const Prim& p : prims) {
    std::vector<uint32_t> idx(p.pos.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
    RenderState state = depth_writing_state(GetParam(), p.primitive);
    ASSERT_TRUE(draws_anything(state, p.pos, idx)) << "the finite control draws";
    for (size_t v = 0; v < p.pos.size(); ++v) {
      for (int c = 0; c < 4; ++c) {
        for (float value : bad) {
          SCOPED_TRACE("primitive " + std::to_string(int(p.primitive)) + " vertex " +
                       std::to_string(v) + " component " + std::to_string(c) + " = " +
                       std::to_string(value));
          std::vector<glm::vec4> pos = p.pos;
          pos[v][c] = value;
          EXPECT_FALSE(draws_anything(state, pos, idx));
        }
      }
    }
  }
}

TEST_P(ClipDraw, DepthPlanesCutTriangles) {
  std::vector<uint32_t> idx{0, 1, 2, 0, 2, 3};
  // Entirely beyond the far plane (z > w), or entirely in front of the near plane (z < -w).
  for (float z : {1.5f, 40.0f, -1.5f}) {
    std::vector<glm::vec4> quad{{-3, -3, z, 1}, {3, -3, z, 1}, {3, 3, z, 1}, {-3, 3, z, 1}};
    EXPECT_EQ(total(count_hits(64, 64, counting_state(GetParam()), quad, idx)), 0) << z;
  }
  // z_ndc = x_ndc + 0.5 crosses the far plane at x_ndc = 0.5, window x = 48 of 64: columns
  // 0..47 remain, each pixel once.
  std::vector<glm::vec4> quad{
      {-3, -3, -2.5f, 1}, {3, -3, 3.5f, 1}, {3, 3, 3.5f, 1}, {-3, 3, -2.5f, 1}};
  auto hits = count_hits(64, 64, counting_state(GetParam()), quad, idx);
  std::vector<int> expected(64 * 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 48; ++x) expected[size_t(y) * 64 + x] = 1;
  }
  EXPECT_EQ(hits, expected) << ascii_map(hits, 64, 64);
}

// Random triangles with extreme components: never a crash, and one triangle never hits a pixel
// twice (a broken clipper emits overlapping fan triangles).
TEST_P(ClipDraw, ExtremeCoordinatesNeverHitAPixelTwice) {
  const float values[] = {0.0f,
                          1e-30f,
                          -1e-30f,
                          1e-7f,
                          -1e-7f,
                          0.5f,
                          -0.5f,
                          1.0f,
                          -1.0f,
                          3.0f,
                          -3.0f,
                          1e7f,
                          -1e7f,
                          1e30f,
                          -1e30f,
                          std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max(),
                          std::numeric_limits<float>::denorm_min()};
  std::mt19937 rng(3);
  std::uniform_int_distribution<size_t> pick(0, std::size(values) - 1);
  std::uniform_real_distribution<float> any(-2.0f, 2.0f);
  std::bernoulli_distribution coin(0.5);
  std::vector<uint32_t> idx{0, 1, 2};
  int drawn = 0;
  for (int n = 0; n < 4000; ++n) {
    std::vector<glm::vec4> tri(3);
    for (auto& v : tri) {
      for (int c = 0; c < 4; ++c) v[c] = coin(rng) ? values[pick(rng)] : any(rng);
    }
    auto hits = count_hits(32, 32, counting_state(GetParam()), tri, idx);
    int max = *std::max_element(hits.begin(), hits.end());
    ASSERT_LE(max, 1) << n << ": (" << tri[0].x << " " << tri[0].y << " " << tri[0].z << " "
                      << tri[0].w << ") (" << tri[1].x << " " << tri[1].y << " " << tri[1].z << " "
                      << tri[1].w << ") (" << tri[2].x << " " << tri[2].y << " " << tri[2].z << " "
                      << tri[2].w << ")\n"
                      << ascii_map(hits, 32, 32);
    drawn += max;
  }
  EXPECT_GT(drawn, 100);
}

INSTANTIATE_TEST_SUITE_P(BothRasterizers, ClipDraw,
                         testing::Values(RasterAlgorithm::kEdgeEquations,
                                         RasterAlgorithm::kScanline),
                         algorithm_name);

// ---------------------------------------------------------------------------------------------
// clip_triangle and clip_line directly. A small guard band so that the x and y planes clip too.

constexpr ClipVolume kVolume{2.0, 1.5};
constexpr int kFloats = 4 + 3;  // position and three varyings

ClipVertex random_vertex(std::mt19937& rng) {
  std::uniform_real_distribution<float> xyz(-5.0f, 5.0f), w(-2.0f, 4.0f);
  ClipVertex v{};
  v.v[0] = xyz(rng), v.v[1] = xyz(rng), v.v[2] = xyz(rng), v.v[3] = w(rng);
  for (int i = 4; i < kFloats; ++i) v.v[i] = xyz(rng);
  return v;
}

std::string describe(const ClipVertex& v) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "  (%a, %a, %a, %a)\n", v.v[0], v.v[1], v.v[2], v.v[3]);
  return buf;
}

bool same_bits(const ClipVertex& a, const ClipVertex& b) {
  return std::memcmp(a.v, b.v, sizeof(float) * kFloats) == 0;
}

int clip(const ClipVertex& a, const ClipVertex& b, const ClipVertex& c,
         ClipVertex (&out)[kMaxClippedVertices]) {
  const ClipVertex* in[3] = {&a, &b, &c};
  return detail::clip_triangle(in, kFloats, kVolume, out);
}

TEST(ClipTriangle, InsideTriangleIsUnchanged) {
  ClipVertex a{{0.1f, 0.2f, 0.3f, 1.0f, 1, 2, 3}}, b{{-0.9f, 0.5f, -0.2f, 2.0f, 4, 5, 6}},
      c{{1.0f, -1.0f, 0.9f, 1.0f, 7, 8, 9}};
  ClipVertex out[kMaxClippedVertices];
  ASSERT_EQ(clip(a, b, c, out), 3);
  EXPECT_TRUE(same_bits(out[0], a) && same_bits(out[1], b) && same_bits(out[2], c));
}

// Two triangles sharing the edge pq, walking it in opposite directions (p->q in one, q->p in the
// other): the vertices created on pq are bit-identical, so the edge stays watertight. Varyings 0
// and 1 tag the edges: both are 0 at p and q, r has 1 in the first, s in the second, so exactly
// the points cut from pq keep both at 0. Some components get magnitudes up to 1e9, where the
// direction of interpolation changes the rounded result (beyond that, a cut within 1e-16 of an
// end point can no longer be told from it, and the tags would be ambiguous).
TEST(ClipTriangle, SharedEdgeCutsIntoBitIdenticalVertices) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> magnitude(3.0f, 9.0f);
  int shared_cuts = 0;
  for (int n = 0; n < 20000; ++n) {
    ClipVertex v[4] = {random_vertex(rng), random_vertex(rng), random_vertex(rng),
                       random_vertex(rng)};
    if (n % 2) v[n % 4].v[(n / 2) % 4] *= std::pow(10.0f, magnitude(rng));
    ClipVertex &p = v[0], &q = v[1], &r = v[2], &s = v[3];
    p.v[4] = p.v[5] = q.v[4] = q.v[5] = 0.0f;
    r.v[4] = 1.0f, r.v[5] = 0.0f;
    s.v[4] = 0.0f, s.v[5] = 1.0f;
    ClipVertex out_a[kMaxClippedVertices], out_b[kMaxClippedVertices];
    int na = n % 3 ? clip(p, q, r, out_a) : clip(r, p, q, out_a);  // p->q, rotated or not
    int nb = n % 5 ? clip(q, p, s, out_b) : clip(s, q, p, out_b);  // q->p
    auto cuts_on_pq = [&](const ClipVertex* out, int count) {
      std::vector<const ClipVertex*> found;
      for (int i = 0; i < count; ++i) {
        bool tagged = out[i].v[4] == 0.0f && out[i].v[5] == 0.0f;
        if (tagged && !same_bits(out[i], p) && !same_bits(out[i], q)) {
          found.push_back(&out[i]);
        }
      }
      return found;
    };
    // Both polygons contain the part of pq inside the volume, with the same end points.
    auto a = cuts_on_pq(out_a, na), b = cuts_on_pq(out_b, nb);
    ASSERT_EQ(a.size(), b.size()) << "triangle " << n;
    for (const ClipVertex* cut : a) {
      ASSERT_TRUE(
          std::any_of(b.begin(), b.end(), [&](const ClipVertex* u) { return same_bits(*u, *cut); }))
          << "triangle " << n << "\n"
          << describe(p) << describe(q) << describe(r) << describe(s);
      ++shared_cuts;
    }
  }
  EXPECT_GT(shared_cuts, 2000);
}

// Every output vertex has w > 0 and lies inside the volume (up to float rounding of the cut).
TEST(ClipTriangle, OutputHasPositiveWAndLiesInTheVolume) {
  std::mt19937 rng(13);
  const float extremes[] = {1e-30f, -1e-30f, 1e7f, -1e7f, 1e30f, -1e30f, 0.0f};
  std::uniform_int_distribution<size_t> pick(0, std::size(extremes) - 1);
  int clipped = 0;
  for (int n = 0; n < 50000; ++n) {
    ClipVertex v[3] = {random_vertex(rng), random_vertex(rng), random_vertex(rng)};
    if (n % 4 == 0) v[n % 3].v[(n / 4) % 4] = extremes[pick(rng)];  // a position component
    ClipVertex out[kMaxClippedVertices];
    int count = clip(v[0], v[1], v[2], out);
    ASSERT_TRUE(count == 0 || (count >= 3 && count <= kMaxClippedVertices)) << count;
    clipped += count > 3;
    for (int i = 0; i < count; ++i) {
      const float* o = out[i].v;
      double x = o[0], y = o[1], z = o[2], w = o[3];
      ASSERT_GT(w, 0.0) << "triangle " << n << " output vertex " << i << " of " << count
                        << "; input:\n"
                        << describe(v[0]) << describe(v[1]) << describe(v[2]);
      double tol = 1e-5 * std::max({std::abs(x), std::abs(y), std::abs(z), std::abs(w)});
      EXPECT_GE(z + w, -tol) << n;
      EXPECT_GE(w - z, -tol) << n;
      EXPECT_LE(std::abs(x), kVolume.guard_x * w + tol) << n;
      EXPECT_LE(std::abs(y), kVolume.guard_y * w + tol) << n;
    }
  }
  EXPECT_GT(clipped, 10000);
}

TEST(ClipLine, EitherDirectionGivesTheSameCut) {
  std::mt19937 rng(14);
  int cut = 0;
  for (int n = 0; n < 20000; ++n) {
    ClipVertex a = random_vertex(rng), b = random_vertex(rng), a1, b1, a2, b2;
    bool kept = detail::clip_line(a, b, kFloats, kVolume, a1, b1);
    ASSERT_EQ(kept, detail::clip_line(b, a, kFloats, kVolume, b2, a2));
    if (!kept) continue;
    EXPECT_TRUE(same_bits(a1, a2) && same_bits(b1, b2)) << n;
    EXPECT_GT(a1.v[3], 0.0f);
    EXPECT_GT(b1.v[3], 0.0f);
    cut += !same_bits(a1, a) || !same_bits(b1, b);
  }
  EXPECT_GT(cut, 2000);
}

// A triangle lying in the guard-band corner planes x = g_x w and y = g_y w (all of it projects
// onto one window point), cut by the w, near and far planes into a hexagon. Rounding of the cut
// vertices puts them randomly on either side of the x and y planes, so those passes can add more
// than one vertex each; the polygon must still fit kMaxClippedVertices. Run in a child process:
// an overflow corrupts the stack.
int clip_corner_triangles(int count) {
  const ClipVolume volume = detail::Viewport{100, 75}.clip_volume();
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> jitter(0.9f, 1.1f);
  int most = 0;
  for (int n = 0; n < count; ++n) {
    const float w[3] = {0.5e-6f * jitter(rng), 3.0f * jitter(rng), 3.0f * jitter(rng)};
    const float z[3] = {0.0f, -5.0f * jitter(rng), 5.0f * jitter(rng)};
    ClipVertex v[3];
    for (int k = 0; k < 3; ++k) {
      v[k].v[0] = float(volume.guard_x * w[k]);
      v[k].v[1] = float(volume.guard_y * w[k]);
      v[k].v[2] = z[k];
      v[k].v[3] = w[k];
    }
    const ClipVertex* in[3] = {&v[0], &v[1], &v[2]};
    ClipVertex out[kMaxClippedVertices];
    most = std::max(most, detail::clip_triangle(in, 4, volume, out));
    if (most > kMaxClippedVertices) break;
  }
  return most;
}

TEST(ClipTriangleDeathTest, PolygonNeverOutgrowsItsBuffer) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        int most = clip_corner_triangles(20000);
        std::fprintf(stderr, "largest polygon: %d vertices\n", most);
        std::exit(most <= kMaxClippedVertices ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

// The same kind of triangle through the public API; exits with 0 when no pixel is hit twice. (In
// a plain build only "does not crash"; under the address sanitizer "writes nothing out of bounds".)
[[noreturn]] void draw_corner_triangle_and_exit() {
  const glm::vec4 tri[3] = {{0x1.6103dap-12f, 0x1.d6de32p-12f, 0.0f, 0x1.16648ap-21f},
                            {0x1.0a956ep+11f, 0x1.6394f2p+11f, -0x1.4f456p+2f, 0x1.a476a8p+1f},
                            {0x1.088a5ap+11f, 0x1.60db3ep+11f, 0x1.58af22p+2f, 0x1.a13da4p+1f}};
  const uint32_t idx[3] = {0, 1, 2};
  auto hits = count_hits(100, 75, counting_state(), tri, idx);
  std::exit(*std::max_element(hits.begin(), hits.end()) <= 1 ? 0 : 1);
}

TEST(ClipTriangleDeathTest, CornerTriangleThroughDrawDoesNotCrash) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(draw_corner_triangle_and_exit(), testing::ExitedWithCode(0), "");
}

// A camera in units of 1e30 (eye, target, near and far all scaled) projects every point where the
// same camera in units of 1 projects it scaled the same: lengths, lookAt and the projection are
// computed in double, where the squares of such coordinates (1e60, past float's 3.4e38) and the
// projection's 2 far near do not overflow. Perspective and orthographic.
TEST(CameraScale, HugeUnitsProjectLikeUnitOnes) {
  for (bool ortho : {false, true}) {
    for (float scale : {1.0e20f, 1.0e30f}) {
      Camera unit, huge;
      unit.eye = {1.0f, 2.0f, 5.0f};
      unit.target = {0.5f, -0.25f, -1.0f};
      unit.near_plane = 0.5f;
      unit.far_plane = 40.0f;
      unit.orthographic = ortho;
      unit.ortho_left = -3.0f, unit.ortho_right = 2.0f, unit.ortho_bottom = -1.5f;
      unit.ortho_top = 2.5f;
      huge = unit;
      huge.eye *= scale, huge.target *= scale;
      huge.near_plane *= scale, huge.far_plane *= scale;
      huge.ortho_left *= scale, huge.ortho_right *= scale, huge.ortho_bottom *= scale;
      huge.ortho_top *= scale;
      ASSERT_TRUE(unit.validate().ok());
      ASSERT_TRUE(huge.validate().ok()) << huge.validate().message();
      glm::mat4 a = unit.view_projection(1.5f), b = huge.view_projection(1.5f);
      for (glm::vec3 p : {glm::vec3(0.0f), glm::vec3(1.0f, -2.0f, 3.0f),
                          glm::vec3(-4.0f, 1.0f, -8.0f), glm::vec3(0.5f, 0.5f, -20.0f)}) {
        glm::vec4 ca = a * glm::vec4(p, 1.0f), cb = b * glm::vec4(p * scale, 1.0f);
        ASSERT_TRUE(std::isfinite(cb.x) && std::isfinite(cb.y) && std::isfinite(cb.z) &&
                    std::isfinite(cb.w));
        glm::vec3 na = glm::vec3(ca) / ca.w, nb = glm::vec3(cb) / cb.w;  // normalised device
        for (int k = 0; k < 3; ++k) {
          EXPECT_NEAR(nb[k], na[k], 1e-4f * std::max(1.0f, std::abs(na[k])))
              << "ortho " << ortho << " scale " << scale << " point " << p.x << "," << p.y << ","
              << p.z << " axis " << k;
        }
      }
    }
  }
  // Up parallel to the view direction is still refused at that scale.
  Camera bad;
  bad.eye = {0.0f, 3.0e30f, 0.0f};
  bad.target = {0.0f, 0.0f, 0.0f};
  bad.near_plane = 1.0e29f, bad.far_plane = 1.0e31f;
  EXPECT_FALSE(bad.validate().ok());
}

// A scene in tiny units: the same clip-space primitives with every coordinate scaled by 2^-95
// (w near 5e-29) draw the same image bit for bit as at scale 1, triangles, lines and points, with
// varyings of 1e12 (colour = varying / 1e12). Setup scales each primitive's 1/w by a power of
// two, which leaves the perspective-correct quotient exact; without it var / w overflows float
// (1e12 * 2e28), and with the clipper's old smallest w of 1e-6 nothing was drawn at all.
struct ScaledClipShader {
  static constexpr int kVaryings = 3;
  const glm::vec4* clip = nullptr;
  const glm::vec3* varyings = nullptr;
  float scale = 1.0f;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = varyings[i].x, v[1] = varyings[i].y, v[2] = varyings[i].z;
    return clip[i] * scale;
  }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    out = {in.varyings[0] * 1.0e-12f, in.varyings[1] * 1.0e-12f, in.varyings[2] * 1.0e-12f, 1.0f};
    return true;
  }
};

TEST(ClipTinyW, PrimitivesInTinyUnitsDrawAsAtUnitScale) {
  // A perspective-looking triangle (w from 1 to 3) and a fan quad; corners in clip space.
  const std::vector<glm::vec4> clip = {{-0.9f, -0.8f, 0.2f, 1.0f},
                                       {2.4f, -1.5f, 1.0f, 3.0f},
                                       {0.1f, 1.6f, 0.5f, 2.0f},
                                       {-1.2f, 1.0f, 0.1f, 1.5f},
                                       {0.3f, -0.2f, 0.4f, 1.25f}};
  const std::vector<glm::vec3> varyings = {{1.0e12f, 0.0f, 0.2e12f},
                                           {0.0f, 1.0e12f, 0.5e12f},
                                           {0.3e12f, 0.2e12f, 1.0e12f},
                                           {0.8e12f, 0.8e12f, 0.0f},
                                           {0.5e12f, 0.1e12f, 0.9e12f}};
  struct Case {
    Primitive primitive;
    std::vector<uint32_t> indices;
  };
  const Case cases[] = {{Primitive::kTriangles, {0, 1, 2, 0, 2, 3}},
                        {Primitive::kLines, {0, 1, 1, 2, 2, 3, 3, 0, 0, 4}},
                        {Primitive::kPoints, {0, 1, 2, 3, 4}}};
  for (const Case& c : cases) {
    for (RasterAlgorithm raster : {RasterAlgorithm::kEdgeEquations, RasterAlgorithm::kScanline}) {
      SCOPED_TRACE("primitive " + std::to_string(int(c.primitive)) + ", raster " +
                   std::to_string(int(raster)));
      RenderState state;
      state.primitive = c.primitive;
      state.raster = raster;
      std::vector<uint32_t> images[2];
      for (int k = 0; k < 2; ++k) {
        Framebuffer fb(96, 64);
        fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
        ScaledClipShader shader{clip.data(), varyings.data(), k == 0 ? 1.0f : 0x1p-95f};
        draw(fb, state, shader, c.indices, uint32_t(clip.size()));
        for (int y = 0; y < fb.height(); ++y) {
          for (int x = 0; x < fb.width(); ++x) images[k].push_back(fb.color_at(x, y));
        }
      }
      size_t drawn = 0, differ = 0;
      for (size_t i = 0; i < images[0].size(); ++i) {
        drawn += images[0][i] != 0;
        differ += images[0][i] != images[1][i];
      }
      EXPECT_GT(drawn, c.primitive == Primitive::kTriangles ? 1000u : 4u);
      EXPECT_EQ(differ, 0u) << "of " << drawn << " drawn pixels";
    }
  }
}

}  // namespace
}  // namespace softrast
