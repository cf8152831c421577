// tests/raster_watertight_test.cpp: meshes that share vertices leave no gap and hit no pixel twice
// (the property the fill rule exists for): a jittered grid filling the image, a fan of 1000 thin
// triangles, and a floor mesh whose shared edges are cut by the near plane. Both rasterizers.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "test_util.hpp"

namespace softrast {
namespace {

using test::ascii_map;
using test::count_hits;
using test::count_hits_window;
using test::counting_state;
using test::Expect;
using test::FloorOracle;
using test::WorldShader;

using test::algorithm_name;

class Watertight : public testing::TestWithParam<RasterAlgorithm> {};

// A grid of (nx + 1) x (ny + 1) vertices over a width x height image; each cell becomes two
// triangles along a random diagonal, listed in a random winding. Interior vertices are jittered,
// outer ones lie on the image border or outside it.
struct Grid {
  std::vector<glm::dvec2> points;
  std::vector<uint32_t> indices;
};

enum class Jitter { kContinuous, kSubpixelGrid, kNone };

// Strictly convex quadrilateral (a, b, c, d), either winding.
bool convex(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
  const glm::dvec2 q[4] = {a, b, c, d};
  int pos = 0, neg = 0;
  for (int k = 0; k < 4; ++k) {
    glm::dvec2 e0 = q[(k + 1) % 4] - q[k], e1 = q[(k + 2) % 4] - q[(k + 1) % 4];
    double turn = e0.x * e1.y - e0.y * e1.x;
    pos += turn > 0.0;
    neg += turn < 0.0;
  }
  return pos == 4 || neg == 4;
}

Grid jittered_grid(int width, int height, int nx, int ny, Jitter jitter, std::mt19937& rng) {
  double cw = double(width) / nx, ch = double(height) / ny;
  // In cells. A corner lies 0.707 cells from the diagonal through its two neighbours; when every
  // vertex moves at most 0.22 * sqrt(2) = 0.31 cells, the corner and that diagonal cannot meet,
  // so every cell stays convex (checked below).
  std::uniform_real_distribution<double> offset(-0.22, 0.22);
  std::uniform_real_distribution<double> outside(0.0, 0.2);  // in cells, outwards
  std::bernoulli_distribution coin(0.5);
  Grid g;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      glm::dvec2 p{i * cw, j * ch};
      bool border_x = i == 0 || i == nx, border_y = j == 0 || j == ny;
      if (!border_x) p.x += jitter == Jitter::kNone ? 0.0 : offset(rng) * cw;
      if (!border_y) p.y += jitter == Jitter::kNone ? 0.0 : offset(rng) * ch;
      // Border vertices: on the border, or pushed out of the image.
      if (border_x && coin(rng)) p.x += (i == 0 ? -1.0 : 1.0) * outside(rng) * cw;
      if (border_y && coin(rng)) p.y += (j == 0 ? -1.0 : 1.0) * outside(rng) * ch;
      if (jitter != Jitter::kContinuous) {
        p = glm::round(p * 256.0) / 256.0;  // on the 1/256 grid, often on pixel centres
      }
      g.points.push_back(p);
    }
  }
  auto at = [&](int i, int j) { return uint32_t(j * (nx + 1) + i); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (coin(rng)) std::swap(b, c);
    g.indices.insert(g.indices.end(), {a, b, c});
  };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      EXPECT_TRUE(convex(g.points[a], g.points[b], g.points[c], g.points[d])) << i << ", " << j;
      if (coin(rng)) {
        add(a, b, c), add(a, c, d);
      } else {
        add(a, b, d), add(b, c, d);
      }
    }
  }
  return g;
}

void expect_all_once(const std::vector<int>& hits, int width, int height) {
  int bad = int(std::count_if(hits.begin(), hits.end(), [](int h) { return h != 1; }));
  EXPECT_EQ(bad, 0) << ascii_map(hits, width, height);
}

TEST_P(Watertight, JitteredGridCoversEveryPixelOnce) {
  std::mt19937 rng(20240611);
  struct Config {
    int width, height, nx, ny;
    Jitter jitter;
  };
  // Power-of-two images for the cases on the 1/256 grid, so that the positions stay exact.
  const Config configs[] = {
      {200, 150, 20, 15, Jitter::kContinuous},   {97, 61, 9, 7, Jitter::kContinuous},
      {128, 128, 16, 16, Jitter::kSubpixelGrid}, {64, 32, 16, 8, Jitter::kSubpixelGrid},
      {128, 64, 16, 8, Jitter::kNone},  // 8x8 cells with vertices on pixel corners
  };
  for (const Config& c : configs) {
    for (int round = 0; round < 8; ++round) {
      SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) + " round " +
                   std::to_string(round));
      Grid g = jittered_grid(c.width, c.height, c.nx, c.ny, c.jitter, rng);
      if (c.jitter == Jitter::kNone && round % 2 == 1) {
        for (glm::dvec2& p : g.points) p += glm::dvec2(0.5, 0.5);  // edges through centres
        // Outer vertices stay on or outside the border: the first row and column move out.
        for (glm::dvec2& p : g.points) {
          if (p.x == 0.5) p.x = -1.0;
          if (p.y == 0.5) p.y = -1.0;
        }
      }
      auto hits =
          count_hits_window(c.width, c.height, counting_state(GetParam()), g.points, g.indices);
      expect_all_once(hits, c.width, c.height);
    }
  }
}

// A fan of 1000 triangles around a centre that is no sample point; the outer polygon is
// star-shaped around it. Exact classification of every sample against the snapped polygon.
TEST_P(Watertight, FanOfThousandTriangles) {
  constexpr int kSize = 128;
  constexpr int kN = 1000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(30.0, 62.0);
  for (int round = 0; round < 4; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    // All positions on the 1/256 grid, so the snapped polygon is known exactly.
    const glm::dvec2 centre{64.0 + 77.0 / 256.0 + round, 63.0 + 179.0 / 256.0 - round};
    std::vector<glm::dvec2> points{centre};
    for (int i = 0; i < kN; ++i) {
      double a = 2.0 * std::numbers::pi * i / kN;
      glm::dvec2 p = centre + radius(rng) * glm::dvec2(std::cos(a), std::sin(a));
      if (round == 0) p = centre + 60.0 * glm::dvec2(std::cos(a), std::sin(a));  // convex
      points.push_back(glm::round(p * 256.0) / 256.0);
    }
    std::vector<uint32_t> indices;
    std::bernoulli_distribution coin(0.5);
    for (uint32_t i = 0; i < kN; ++i) {
      uint32_t b = 1 + i, c = 1 + (i + 1) % kN;
      if (coin(rng)) std::swap(b, c);
      indices.insert(indices.end(), {0, b, c});
    }
    auto hits = count_hits_window(kSize, kSize, counting_state(GetParam()), points, indices);

    // Classify samples in exact 1/256 arithmetic: strictly inside the outer polygon, on it, or
    // outside. With the angle increasing, fan triangle (centre, p_i, p_i+1) has a positive
    // cross product (clockwise in the y-down image), so inside means every cross product >= 0.
    auto fx = [](double v) { return int64_t(std::llround(v * 256.0)); };
    std::vector<int64_t> px(kN + 1), py(kN + 1);
    for (int i = 0; i <= kN; ++i) px[i] = fx(points[i].x), py[i] = fx(points[i].y);
    auto cross = [](int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t sx, int64_t sy) {
      return (bx - ax) * (sy - ay) - (by - ay) * (sx - ax);
    };
    for (int i = 0; i < kN; ++i) {  // precondition: the polygon is star-shaped around the centre
      int j = 1 + (i + 1) % kN;
      ASSERT_GT(cross(px[0], py[0], px[1 + i], py[1 + i], px[j], py[j]), 0) << i;
    }
    int inside_count = 0;
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) {
        int64_t sx = int64_t(x) * 256 + 128, sy = int64_t(y) * 256 + 128;
        bool inside = false, on_boundary = false;
        for (int i = 0; i < kN && !inside; ++i) {
          int b = 1 + i, c = 1 + (i + 1) % kN;
          if (cross(px[0], py[0], px[b], py[b], sx, sy) < 0) continue;
          if (cross(px[c], py[c], px[0], py[0], sx, sy) < 0) continue;
          int64_t outer = cross(px[b], py[b], px[c], py[c], sx, sy);
          inside = outer > 0;
          on_boundary = on_boundary || outer == 0;
        }
        int h = hits[size_t(y) * kSize + x];
        if (inside) {
          ++inside_count;
          EXPECT_EQ(h, 1) << "pixel " << x << ", " << y << " inside the fan";
        } else if (on_boundary) {
          EXPECT_LE(h, 1) << "pixel " << x << ", " << y << " on the fan's outline";
        } else {
          EXPECT_EQ(h, 0) << "pixel " << x << ", " << y << " outside the fan";
        }
      }
    }
    EXPECT_GT(inside_count, 2500);  // the test really covered a large area
  }
}

// A floor mesh crossing the near plane, its interior vertices jittered within the floor plane:
// the near plane cuts many shared edges, and the clipper must cut them identically from both
// sides. Pixels clearly inside the visible part of the floor are hit once, none twice.
TEST_P(Watertight, MeshClippedByNearPlane) {
  constexpr int kW = 160, kH = 120;
  const glm::dvec3 eye{0.0, 0.3, 0.0};
  const glm::dvec3 forward{0.0, -std::sin(0.87), -std::cos(0.87)};  // about 50 degrees down
  const glm::dmat4 view = glm::lookAt(eye, eye + forward, glm::dvec3(0, 1, 0));
  const glm::dmat4 proj = glm::perspective(glm::radians(90.0), double(kW) / kH, 0.5, 100.0);
  const double x0 = -4.0, x1 = 4.0, z0 = -30.0, z1 = 2.0;  // the floor y = 0 reaches behind
  constexpr int kNx = 9, kNz = 13;
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> jitter(-0.35, 0.35);
  std::bernoulli_distribution coin(0.5);
  for (int round = 0; round < 4; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    std::vector<glm::dvec3> points;
    for (int j = 0; j <= kNz; ++j) {
      for (int i = 0; i <= kNx; ++i) {
        double u = double(i) / kNx, v = double(j) / kNz;
        double du = (i == 0 || i == kNx) ? 0.0 : jitter(rng) / kNx;
        double dv = (j == 0 || j == kNz) ? 0.0 : jitter(rng) / kNz;
        points.push_back({x0 + (u + du) * (x1 - x0), 0.0, z0 + (v + dv) * (z1 - z0)});
      }
    }
    std::vector<uint32_t> indices;
    auto at = [](int i, int j) { return uint32_t(j * (kNx + 1) + i); };
    for (int j = 0; j < kNz; ++j) {
      for (int i = 0; i < kNx; ++i) {
        uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
        uint32_t tris[2][3] = {{a, b, c}, {a, c, d}};
        if (coin(rng)) tris[0][2] = d, tris[1][0] = b;  // the other diagonal: (a,b,d), (b,c,d)
        for (auto& t : tris) {
          if (coin(rng)) std::swap(t[1], t[2]);
          indices.insert(indices.end(), {t[0], t[1], t[2]});
        }
      }
    }
    Framebuffer fb(kW, kH);
    fb.clear_color({0, 0, 0, 0});
    WorldShader shader;
    shader.positions = points.data();
    shader.view_proj = proj * view;
    draw(fb, counting_state(GetParam()), shader, indices, uint32_t(points.size()));
    auto hits = test::red_counts(fb);

    FloorOracle oracle(proj * view, kW, kH, 0.0, {{x0, z0}, {x1, z0}, {x1, z1}, {x0, z1}});
    int inside = 0, outside = 0, bad = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        int h = hits[size_t(y) * kW + x];
        Expect e = oracle.classify(x, y);
        bool ok = e == Expect::kIn ? h == 1 : e == Expect::kOut ? h == 0 : h <= 1;
        inside += e == Expect::kIn;
        outside += e == Expect::kOut;
        if (!ok) ++bad, ADD_FAILURE() << "pixel " << x << ", " << y << " hit " << h << " times";
        if (bad > 20) FAIL() << ascii_map(hits, kW, kH);
      }
    }
    // The near plane really cuts the floor across the image: both regions are large.
    EXPECT_GT(inside, kW * kH / 5);
    EXPECT_GT(outside, kW * kH / 10);
  }
}

// Two triangles sharing an edge from in front of the camera to behind it, given directly in clip
// space (w < 0 at one end): the cut points of the shared edge must coincide.
TEST_P(Watertight, SharedEdgeThroughTheCameraPlane) {
  constexpr int kW = 64, kH = 64;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-3.0f, 3.0f);
  std::uniform_real_distribution<float> w_front(0.2f, 4.0f), w_back(-4.0f, -0.2f);
  int drawn = 0;
  for (int round = 0; round < 300; ++round) {
    // p in front, q behind; r and s on both sides of the line pq.
    glm::vec4 p{coord(rng), coord(rng), 0.0f, w_front(rng)};
    glm::vec4 q{coord(rng), coord(rng), 0.0f, w_back(rng)};
    glm::vec4 r{coord(rng), coord(rng), 0.0f, w_front(rng)};
    // In the image, r and s must lie on opposite sides of the (projected) line through p and
    // q: with L = p x q in homogeneous (x, y, w), the side of a point v with w > 0 is the sign of
    // dot(L, v) (the same sign flip from w_p * w_q < 0 applies to both).
    glm::vec3 line = glm::cross(glm::vec3(p.x, p.y, p.w), glm::vec3(q.x, q.y, q.w));
    auto side = [&](glm::vec4 v) { return glm::dot(line, glm::vec3(v.x, v.y, v.w)); };
    glm::vec4 s;
    do {
      s = {coord(rng), coord(rng), 0.0f, w_front(rng)};
    } while (!(side(r) * side(s) < 0.0f && std::abs(side(s)) > 0.01f));
    p.z = 0.5f * p.w, q.z = 0.5f * q.w, r.z = 0.1f * r.w, s.z = 0.3f * s.w;
    std::vector<glm::vec4> pos{p, q, r, s};
    std::vector<uint32_t> idx{0, 1, 2, 1, 0, 3};
    auto hits = count_hits(kW, kH, counting_state(GetParam()), pos, idx);
    auto max = *std::max_element(hits.begin(), hits.end());
    ASSERT_LE(max, 1) << "round " << round << "\n" << ascii_map(hits, kW, kH);
    drawn += max > 0;
  }
  EXPECT_GT(drawn, 50);
}

INSTANTIATE_TEST_SUITE_P(BothRasterizers, Watertight,
                         testing::Values(RasterAlgorithm::kEdgeEquations,
                                         RasterAlgorithm::kScanline),
                         algorithm_name);

}  // namespace
}  // namespace softrast
