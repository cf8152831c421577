// tests/msaa_test.cpp: multisampling (RenderState::samples). The per-sample coverage kernel
// against the fill-rule oracle at every sample of the standard patterns; watertight meshes hit
// every sample exactly once through the whole pipeline; the edge of a rotated square resolves to
// its analytic area; the fragment shader runs once per pixel and covered triangle; 1 sample is
// the single-sampled path.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "counting_shader.hpp"
#include "raster/raster.hpp"
#include "raster/sample_coverage.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"
#include "softrast/simd_level.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

using detail::SamplePattern;
using detail::standard_sample_pattern;

// The Vulkan specification's standard sample locations (Multisampling), in pixels from the
// pixel's top-left corner, typed in from the specification's table.
TEST(Msaa, StandardSamplePositions) {
  const double k2[][2] = {{0.75, 0.75}, {0.25, 0.25}};
  const double k4[][2] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
  const double k8[][2] = {{0.5625, 0.3125}, {0.4375, 0.6875}, {0.8125, 0.5625}, {0.3125, 0.1875},
                          {0.1875, 0.8125}, {0.0625, 0.4375}, {0.6875, 0.9375}, {0.9375, 0.0625}};
  auto check = [](int n, const double(*table)[2]) {
    const SamplePattern* p = standard_sample_pattern(n);
    ASSERT_NE(p, nullptr);
    ASSERT_EQ(p->count, n);
    for (int s = 0; s < n; ++s) {
      EXPECT_EQ(p->x[s], int32_t(table[s][0] * 256)) << n << "x sample " << s;
      EXPECT_EQ(p->y[s], int32_t(table[s][1] * 256)) << n << "x sample " << s;
    }
  };
  check(2, k2);
  check(4, k4);
  check(8, k8);
  EXPECT_EQ(standard_sample_pattern(1)->x[0], 128);
  EXPECT_EQ(standard_sample_pattern(3), nullptr);
  EXPECT_EQ(standard_sample_pattern(16), nullptr);
}

detail::WindowVertex wv(int64_t x, int64_t y) {
  detail::WindowVertex v;
  v.x = int32_t(x);
  v.y = int32_t(y);
  return v;
}

// Every sample of every pixel of random triangles whose vertices lie on the 1/16 pixel grid (so
// that edges run exactly through sample points very often) is covered exactly when the oracle
// of fill_rule_oracle.hpp, written from CONVENTIONS.md alone, says so; for both windings, small
// triangles (the 32-bit path) and large ones (int64).
TEST(Msaa, PerSampleCoverageFollowsTheFillRule) {
  std::mt19937 rng(61);
  std::uniform_int_distribution<int> coord(-8 * 16, 24 * 16);  // in 1/16 pixel, around a 16x16 area
  const detail::PixelRect scissor{0, 0, 16, 16};
  int64_t on_edge = 0, checked = 0;
  for (int n : {1, 2, 4, 8}) {
    const SamplePattern& p = *standard_sample_pattern(n);
    for (int round = 0; round < 1500; ++round) {
      detail::WindowVertex v[3];
      // Every other triangle is up to 190 pixels across, about half of them past the 120-pixel
      // bound of the 32-bit path, so both paths of the kernel are checked.
      const int scale = round % 2 == 0 ? 1 : 6;
      for (auto& w : v)
        w = wv((coord(rng) * scale - 40 * (scale - 1)) * 16,
               (coord(rng) * scale - 40 * (scale - 1)) * 16);
      if (round % 3 == 0) v[2] = wv(v[0].x, v[1].y);  // axis-aligned edges: top edges
      int64_t area = detail::signed_area_fx16(v[0], v[1], v[2]);
      if (area == 0) continue;
      detail::SampleTriangle tri;
      const detail::WindowVertex* ordered[3];
      test::Fx8Triangle oracle{{v[0].x, v[1].x, v[2].x}, {v[0].y, v[1].y, v[2].y}};
      bool any = detail::setup_sample_triangle(v[0], v[1], v[2], area, scissor, tri, ordered);
      for (int by = 0; by < 16; by += 4) {
        for (int bx = 0; bx < 16; bx += 4) {
          uint8_t cov[16] = {};
          uint32_t mask = any ? detail::block_sample_coverage(tri, p, tri.bounds, bx, by, cov) : 0;
          // The kernel of every SIMD level this CPU has gives the same coverage.
          for (int level = 0; any && level <= int(simd_level()); ++level) {
            uint8_t level_cov[16] = {};
            uint32_t level_mask = detail::block_sample_coverage_kernel(SimdLevel(level))(
                tri, p, tri.bounds, bx, by, level_cov);
            ASSERT_EQ(level_mask, mask) << simd_level_name(SimdLevel(level));
            for (int i = 0; i < 16; ++i) {
              if (mask >> i & 1) {
                ASSERT_EQ(level_cov[i], cov[i]) << simd_level_name(SimdLevel(level));
              }
            }
          }
          for (int i = 0; i < 16; ++i) {
            int px = bx + (i & 3), py = by + (i >> 2);
            uint8_t expect = 0;
            for (int s = 0; s < n; ++s) {
              int64_t sx = int64_t(px) * 256 + p.x[s], sy = int64_t(py) * 256 + p.y[s];
              expect |= uint8_t(test::rule_covers(oracle, sx, sy)) << s;
              for (int k = 0; k < 3; ++k) {
                int j = (k + 1) % 3;
                on_edge +=
                    test::cross_fx(oracle.x[k], oracle.y[k], oracle.x[j], oracle.y[j], sx, sy) == 0;
              }
            }
            uint8_t got = (mask >> i & 1) ? cov[i] : 0;
            ASSERT_EQ(got, expect)
                << n << "x, pixel " << px << "," << py << ", triangle (" << v[0].x << "," << v[0].y
                << ") (" << v[1].x << "," << v[1].y << ") (" << v[2].x << "," << v[2].y << ")";
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GT(on_edge, 1000) << "too few samples exactly on an edge to test the tie rule";
  EXPECT_GT(checked, 100000);
}

// With the single sample at the pixel centre, the kernel covers exactly the pixels the
// single-sampled edge-equation rasterizer emits.
TEST(Msaa, OneCentreSampleEqualsThePixelRasterizer) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(-10 * 256, 42 * 256);
  const detail::PixelRect scissor{0, 0, 32, 32};
  for (int round = 0; round < 2000; ++round) {
    detail::WindowVertex v[3];
    for (auto& w : v) w = wv(coord(rng), coord(rng));
    int64_t area = detail::signed_area_fx16(v[0], v[1], v[2]);
    if (area == 0) continue;
    std::vector<uint32_t> pixel(32 * 32 / 16, 0), sample(32 * 32 / 16, 0);
    detail::TriangleSetup setup;
    if (detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone, FrontFace::kCounterClockwise,
                               scissor, setup)) {
      auto emit = [](void* c, int x, int y, uint32_t m) {
        (*static_cast<std::vector<uint32_t>*>(c))[size_t(y / 4 * 8 + x / 4)] |= m;
      };
      detail::rasterize_triangle_edge_equations(setup, scissor, detail::BlockSink{emit, &pixel});
    }
    detail::SampleTriangle tri;
    const detail::WindowVertex* ordered[3];
    if (detail::setup_sample_triangle(v[0], v[1], v[2], area, scissor, tri, ordered)) {
      for (int by = 0; by < 32; by += 4) {
        for (int bx = 0; bx < 32; bx += 4) {
          uint8_t cov[16];
          sample[size_t(by / 4 * 8 + bx / 4)] = detail::block_sample_coverage(
              tri, *standard_sample_pattern(1), tri.bounds, bx, by, cov);
        }
      }
    }
    ASSERT_EQ(pixel, sample) << "round " << round;
  }
}

// A 128x128 grid mesh (vertices on the 1/16 pixel grid, random diagonals and windings) drawn with
// additive blending of 1/255 and no depth test: every sample of every pixel is hit exactly once,
// so no shared edge leaves a gap or is drawn twice at any sample.
TEST(Msaa, SharedEdgesHitEverySampleOnce) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> jitter(-3, 3);  // half pixels
  std::bernoulli_distribution coin(0.5);
  const int size = 128, cells = 16;
  const double cell = double(size) / cells;
  std::vector<glm::vec4> clip;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      double x = i * cell, y = j * cell;
      if (i > 0 && i < cells) x += jitter(rng) * 0.5;  // multiples of 1/2 pixel: on sample rows
      if (j > 0 && j < cells) y += jitter(rng) * 0.5 + 0.0625 * (i % 3);
      ASSERT_TRUE(test::window_to_clip_is_exact(x, y, size, size));
      clip.push_back(test::window_to_clip(x, y, size, size));
    }
  }
  std::vector<uint32_t> indices;
  auto at = [&](int i, int j) { return uint32_t(j * (cells + 1) + i); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (coin(rng)) std::swap(b, c);
    indices.insert(indices.end(), {a, b, c});
  };
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (coin(rng)) {
        add(a, b, c), add(a, c, d);
      } else {
        add(a, b, d), add(b, c, d);
      }
    }
  }
  for (int n : {2, 4, 8}) {
    for (int threads : {1, 2}) {
      SCOPED_TRACE(std::to_string(n) + " samples, " + std::to_string(threads) + " threads");
      RenderState state = test::counting_state();
      state.samples = n;
      state.threads = threads;
      Framebuffer fb(size, size);
      fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
      test::ClipSpaceShader shader;
      shader.positions = clip.data();
      draw(fb, state, shader, indices, uint32_t(clip.size()));
      const Framebuffer::Multisample& ms = fb.multisample();
      ASSERT_TRUE(ms.valid);
      ASSERT_EQ(ms.count, n);
      std::vector<int> wrong(size_t(size) * size, 0);
      int bad = 0;
      for (size_t i = 0; i < ms.color.size(); ++i) {
        if ((ms.color[i] & 0xff) != 1) ++bad, ++wrong[i / size_t(n)];
      }
      EXPECT_EQ(bad, 0) << test::ascii_map(wrong, size, size);
      EXPECT_EQ(test::red_counts(fb), std::vector<int>(size_t(size) * size, 1));
    }
  }
}

// Area of the part of pixel (px, py) inside the convex polygon `poly` (counter-clockwise in
// y-down coordinates does not matter: the absolute area), by clipping the pixel's square against
// each edge of the polygon.
double pixel_area_inside(const std::vector<glm::dvec2>& poly, int px, int py) {
  std::vector<glm::dvec2> cell = {{double(px), double(py)},
                                  {px + 1.0, double(py)},
                                  {px + 1.0, py + 1.0},
                                  {double(px), py + 1.0}};
  double orient = 0.0;
  for (size_t k = 0; k < poly.size(); ++k) {
    glm::dvec2 a = poly[k], b = poly[(k + 1) % poly.size()];
    orient += a.x * b.y - b.x * a.y;
  }
  for (size_t k = 0; k < poly.size() && !cell.empty(); ++k) {
    glm::dvec2 a = poly[k], b = poly[(k + 1) % poly.size()];
    auto side = [&](glm::dvec2 p) {
      return ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) * (orient > 0 ? 1 : -1);
    };
    std::vector<glm::dvec2> out;
    for (size_t i = 0; i < cell.size(); ++i) {
      glm::dvec2 p = cell[i], q = cell[(i + 1) % cell.size()];
      double sp = side(p), sq = side(q);
      if (sp >= 0) out.push_back(p);
      if ((sp >= 0) != (sq >= 0)) out.push_back(p + (q - p) * (sp / (sp - sq)));
    }
    cell = out;
  }
  double area = 0.0;
  for (size_t i = 0; i < cell.size(); ++i) {
    glm::dvec2 p = cell[i], q = cell[(i + 1) % cell.size()];
    area += p.x * q.y - q.x * p.y;
  }
  return std::abs(area) * 0.5;
}

struct EdgeError {
  double mean_abs = 0.0;  // per pixel cut by the edge, in pixels of area
  double total = 0.0;     // summed coverage minus the square's area, in pixels
  int edge_pixels = 0;
};

// A white square of side 40 turned by `degrees` on black, drawn with `samples`, compared pixel
// by pixel with the analytic area of the square inside each pixel.
EdgeError rotated_square_error(int samples, double degrees) {
  const int size = 64;
  const double t = degrees * std::numbers::pi / 180.0, h = 20.0;
  std::vector<glm::dvec2> corners;
  for (int k = 0; k < 4; ++k) {
    double a = t + k * std::numbers::pi / 2;
    glm::dvec2 d{std::cos(a) - std::sin(a), std::sin(a) + std::cos(a)};
    corners.push_back(glm::dvec2(32.3, 31.7) + d * h);
  }
  std::vector<glm::vec4> clip;
  for (glm::dvec2 c : corners) clip.push_back(test::window_to_clip(c.x, c.y, size, size));
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  RenderState state;
  state.cull = CullMode::kNone;
  state.samples = samples;
  Framebuffer fb(size, size);
  fb.clear_color({0.0f, 0.0f, 0.0f, 1.0f});
  test::ClipSpaceShader shader;
  shader.positions = clip.data();
  shader.color = glm::vec4(1.0f);
  draw(fb, state, shader, indices, uint32_t(clip.size()));
  EdgeError e;
  double total_area = 0.0, total_cov = 0.0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      double area = pixel_area_inside(corners, x, y);
      double cov = double(fb.color_at(x, y) & 0xff) / 255.0;
      total_area += area;
      total_cov += cov;
      if (area > 0.0 && area < 1.0) {
        e.mean_abs += std::abs(cov - area);
        ++e.edge_pixels;
      }
    }
  }
  e.mean_abs /= std::max(1, e.edge_pixels);
  e.total = total_cov - total_area;
  return e;
}

// At 4x the resolved coverage of the pixels along the edge of a rotated square is within 1/8
// pixel of the analytic area on average, and the whole square's within 1/8 pixel per 10 pixels
// of edge; single-sampled it is not (which shows the test can fail).
TEST(Msaa, RotatedSquareEdgeMatchesAnalyticArea) {
  for (double degrees : {7.0, 19.0, 30.0, 41.0}) {
    SCOPED_TRACE(std::to_string(degrees) + " degrees");
    EdgeError e4 = rotated_square_error(4, degrees);
    EdgeError e1 = rotated_square_error(1, degrees);
    EXPECT_GT(e4.edge_pixels, 100);
    EXPECT_LE(e4.mean_abs, 1.0 / 8.0);
    EXPECT_LE(std::abs(e4.total), 160.0 / 10.0 / 8.0);
    EXPECT_GT(e1.mean_abs, 1.0 / 8.0);
    EdgeError e8 = rotated_square_error(8, degrees);
    EXPECT_LT(e8.mean_abs, e4.mean_abs);
  }
}

using test::CountingShader;

// The fragment shader runs once per pixel with at least one covered sample, per triangle, not
// once per sample: two triangles sharing an edge shade the pixels along it once each.
TEST(Msaa, ShadesOncePerPixelAndTriangle) {
  const int size = 32;
  std::vector<glm::dvec2> window = {{2.3, 3.1}, {29.6, 5.2}, {7.4, 28.9}, {30.2, 27.7}};
  std::vector<glm::vec4> clip;
  for (glm::dvec2 p : window) clip.push_back(test::window_to_clip(p.x, p.y, size, size));
  std::vector<uint32_t> indices = {0, 1, 2, 1, 3, 2};
  for (int n : {2, 4, 8}) {
    RenderState state = test::counting_state();
    state.samples = n;
    state.threads = 1;
    Framebuffer fb(size, size);
    CountingShader shader;
    shader.positions = clip.data();
    draw(fb, state, shader, indices, uint32_t(clip.size()));
    // The oracle: pixels with a sample inside each triangle.
    const SamplePattern& p = *standard_sample_pattern(n);
    int64_t expect = 0;
    for (size_t t = 0; t < indices.size(); t += 3) {
      test::Fx8Triangle tri;
      for (int k = 0; k < 3; ++k) {
        glm::dvec2 w = window[indices[t + size_t(k)]];
        tri.x[size_t(k)] = int64_t(std::nearbyint(w.x * 256));
        tri.y[size_t(k)] = int64_t(std::nearbyint(w.y * 256));
      }
      for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
          bool any = false;
          for (int s = 0; s < n; ++s) {
            any |= test::rule_covers(tri, int64_t(x) * 256 + p.x[s], int64_t(y) * 256 + p.y[s]);
          }
          expect += any;
        }
      }
    }
    EXPECT_EQ(shader.shaded.load(), expect) << n << " samples";
  }
}

// A scalar shader with a colour per vertex: the same arithmetic at every SIMD level, so that only
// the multisampled depth test, sample writes and resolve can differ between levels.
struct VertexColourShader {
  static constexpr int kVaryings = 3;
  const glm::vec4* positions = nullptr;
  const glm::vec3* colours = nullptr;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = colours[i].r, v[1] = colours[i].g, v[2] = colours[i].b;
    return positions[i];
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    out = {f.varyings[0], f.varyings[1], f.varyings[2], 1.0f};
    return true;
  }
};

// Four samples per pixel have a vector form at AVX-512 (a block row's 16 samples at once) beside
// the scalar one, and a tile's samples are filled from its pixels when a draw first touches it.
// Overlapping depth-tested triangles on an image whose size is no multiple of the tile size, two
// frames (clear, draw), drawn in one call or in three (the tiles of the right part first touched
// by a later call): colour and depth bit for bit the same at every level and for every split.
TEST(Msaa, EveryLevelAndEverySplitOfTheDrawsGiveTheSameImage) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-1.2f, 1.2f), depth(-0.9f, 0.9f), unit(0.0f, 1.0f);
  std::vector<glm::vec4> clip;
  std::vector<glm::vec3> colours;
  for (int i = 0; i < 3 * 80; ++i) {
    clip.push_back({pos(rng), pos(rng), depth(rng), 1.0f});
    colours.push_back({unit(rng), unit(rng), unit(rng)});
  }
  std::vector<uint32_t> indices(clip.size());
  for (uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
  // Triangles in order of their leftmost vertex, so that the first of three calls stays left.
  std::vector<uint32_t> order(clip.size() / 3);
  for (uint32_t t = 0; t < order.size(); ++t) order[t] = t;
  auto left = [&](uint32_t t) {
    return std::min({clip[3 * t].x, clip[3 * t + 1].x, clip[3 * t + 2].x});
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return left(a) < left(b); });
  std::vector<uint32_t> sorted;
  for (uint32_t t : order) sorted.insert(sorted.end(), {3 * t, 3 * t + 1, 3 * t + 2});

  VertexColourShader shader;
  shader.positions = clip.data();
  shader.colours = colours.data();
  RenderState state;
  state.cull = CullMode::kNone;
  state.samples = 4;
  auto render = [&](SimdLevel level, int calls, int threads) {
    set_simd_level(level);
    state.threads = threads;
    Framebuffer fb(200, 150);
    for (int frame = 0; frame < 2; ++frame) {
      fb.clear({0.2f, 0.3f, 0.4f, 1.0f}, 1.0f);
      size_t per_call = (sorted.size() / 3 + size_t(calls) - 1) / size_t(calls) * 3;
      for (size_t first = 0; first < sorted.size(); first += per_call) {
        size_t count = std::min(per_call, sorted.size() - first);
        draw(fb, state, shader, std::span<const uint32_t>(sorted.data() + first, count),
             uint32_t(clip.size()));
      }
    }
    return std::pair{fb.to_image().rgba, fb.depth_values()};
  };
  const SimdLevel widest = cpu_simd_level();
  auto want = render(SimdLevel::kSse2, 1, 1);
  for (SimdLevel level : {SimdLevel::kSse2, SimdLevel::kAvx2, SimdLevel::kAvx512}) {
    if (level > widest) continue;
    for (int calls : {1, 3}) {
      for (int threads : {1, 2}) {
        SCOPED_TRACE(std::string(simd_level_name(level)) + ", " + std::to_string(calls) +
                     " calls, " + std::to_string(threads) + " threads");
        auto got = render(level, calls, threads);
        EXPECT_TRUE(got.first == want.first);
        EXPECT_TRUE(got.second == want.second);
      }
    }
  }
  set_simd_level(widest);
  // The scene is not trivial: several colours and depths survive.
  std::vector<uint8_t> reds;
  for (size_t i = 0; i < want.first.size(); i += 4) reds.push_back(want.first[i]);
  std::sort(reds.begin(), reds.end());
  EXPECT_GT(std::unique(reds.begin(), reds.end()) - reds.begin(), 50);
}

// One sample is the single-sampled path: the demo scene is bit for bit the same with samples = 1
// as with the default state, and a 4x render differs only along edges.
// The first multisampled draw after a clear fills each tile's samples from the pending clear (or,
// once the clear is written, from the pixels): a triangle behind the cleared depth stays hidden,
// one in front shows, and every other pixel of the tiles they touch resolves to the clear colour
// and depth exactly. For 2, 4 and 8 samples, at every level, on 1 and 2 threads.
TEST(Msaa, FirstDrawAfterAClearTestsAgainstTheClear) {
  // Window depth (z + 1) / 2: the large triangle at 0.6, behind the clear's 0.5; the small one at
  // 0.4, in front. Colours per vertex all the same, so each triangle is one colour.
  std::vector<glm::vec4> clip = {{-1.0f, -1.0f, 0.2f, 1.0f}, {0.9f, -1.0f, 0.2f, 1.0f},
                                 {-1.0f, 0.9f, 0.2f, 1.0f},  {0.1f, 0.1f, -0.2f, 1.0f},
                                 {0.5f, 0.1f, -0.2f, 1.0f},  {0.1f, 0.6f, -0.2f, 1.0f}};
  std::vector<glm::vec3> colours = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0},
                                    {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  std::vector<uint32_t> indices = {0, 1, 2, 3, 4, 5};
  const glm::vec4 clear(0.2f, 0.4f, 0.6f, 1.0f);
  const uint32_t clear_packed = pack_rgba8(clear), green = pack_rgba8({0, 1, 0, 1});
  SimdLevel cap = simd_level();
  for (int level = 0; level <= int(cap); ++level) {
    set_simd_level(SimdLevel(level));
    for (int n : {2, 4, 8}) {
      for (int round = 0; round < 4; ++round) {
        const int threads = 1 + round / 2;
        const bool pixels_first = round % 2 == 1;
        SCOPED_TRACE(std::to_string(n) + " samples, " + std::to_string(threads) + " threads, " +
                     simd_level_name(SimdLevel(level)) +
                     (pixels_first ? ", clear written first" : ", clear pending"));
        RenderState state;
        state.cull = CullMode::kNone;
        state.samples = n;
        state.threads = threads;
        Framebuffer fb(150, 100);  // three tiles across, two down, the last ones cut
        fb.clear(clear, 0.5f);
        // Odd rounds write the clear into the pixels first: the samples are then filled from the
        // pixels, not from the pending clear.
        if (pixels_first) fb.write_pending_clears(1);
        VertexColourShader shader;
        shader.positions = clip.data();
        shader.colours = colours.data();
        draw(fb, state, shader, indices, uint32_t(clip.size()));
        int shown = 0;
        for (int y = 0; y < fb.height(); ++y) {
          for (int x = 0; x < fb.width(); ++x) {
            uint32_t c = fb.color_at(x, y);
            float d = fb.depth_at(x, y);
            if (c == green) {
              ++shown;
              ASSERT_EQ(d, 0.4f) << x << "," << y;
            } else if (d == 0.5f) {
              ASSERT_EQ(c, clear_packed) << x << "," << y;  // the large triangle stays hidden
            } else {
              // A pixel on the small triangle's edge: some samples green at 0.4, the rest clear.
              ASSERT_EQ(d, 0.4f) << x << "," << y;
            }
          }
        }
        EXPECT_GT(shown, 200);
      }
    }
  }
  set_simd_level(cap);
}

TEST(Msaa, OneSampleIsTheSingleSampledPath) {
  DemoScene scene = make_demo_scene();
  auto render = [&](int samples) {
    Framebuffer fb(160, 120);
    fb.clear();
    RenderOptions options;
    options.state.samples = samples;
    render_mesh(fb, scene.mesh, scene.camera, options);
    return fb.to_image();
  };
  Image plain = [&] {
    Framebuffer fb(160, 120);
    fb.clear();
    render_mesh(fb, scene.mesh, scene.camera, RenderOptions{});
    return fb.to_image();
  }();
  EXPECT_EQ(render(1).rgba, plain.rgba);
  Image four = render(4);
  int differing = 0;
  for (size_t i = 0; i < plain.rgba.size(); ++i) differing += plain.rgba[i] != four.rgba[i];
  EXPECT_GT(differing, 0);
}

}  // namespace
}  // namespace softrast
