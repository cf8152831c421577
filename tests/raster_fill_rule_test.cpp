// tests/raster_fill_rule_test.cpp: the top-left fill rule (CONVENTIONS.md) through the public
// draw API. Vertices sit at exact window coordinates (power-of-two images, positions on the
// 1/256 grid), fragments are counted with additive blending, and every case runs with both
// triangle rasterizers. Expected pixel sets are derived by hand from the rule or computed by the
// independent rule in test_util.hpp, never by the library's setup code.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace softrast {
namespace {

using test::ascii_map;
using test::count_hits_window;
using test::counting_state;
using test::fx8_triangle;
using test::rule_map;
using test::window_to_clip_is_exact;

constexpr int kW = 32;
constexpr int kH = 32;
constexpr double kEps = 1.0 / 256.0;

using PixelPredicate = std::function<bool(int x, int y)>;

std::vector<int> map_of(const PixelPredicate& covered) {
  std::vector<int> m(size_t(kW) * kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) m[size_t(y) * kW + x] = covered(x, y) ? 1 : 0;
  }
  return m;
}

int total(const std::vector<int>& m) {
  int n = 0;
  for (int v : m) n += v;
  return n;
}

std::string pictures(const std::vector<int>& expected, const std::vector<int>& actual) {
  return "expected:\n" + ascii_map(expected, kW, kH) + "actual:\n" + ascii_map(actual, kW, kH);
}

using test::algorithm_name;

class FillRule : public testing::TestWithParam<RasterAlgorithm> {
 public:
  // Hit counts of triangles given by window positions (three per triangle, in order).
  std::vector<int> draw_triangles(const std::vector<glm::dvec2>& points) {
    for (glm::dvec2 p : points) {
      EXPECT_TRUE(window_to_clip_is_exact(p.x, p.y, kW, kH)) << p.x << ", " << p.y;
    }
    std::vector<uint32_t> indices(points.size());
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
    return count_hits_window(kW, kH, counting_state(GetParam()), points, indices);
  }
  std::vector<int> draw_triangle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    return draw_triangles({a, b, c});
  }
};

// The example of CONVENTIONS.md: (0.5,0.5),(5.5,0.5),(5.5,5.5) has a top edge (included), a
// right edge x = 5.5 (excluded) and a left edge on the diagonal (included): 0 <= y <= x <= 4.
// (0.5,5.5),(0.5,0.5),(5.5,5.5) has a left edge x = 0.5 (included), a bottom edge (excluded) and
// a right edge on the diagonal (excluded): 0 <= x < y <= 4.
const PixelPredicate kUpperTriangle = [](int x, int y) { return 0 <= y && y <= x && x <= 4; };
const PixelPredicate kLowerTriangle = [](int x, int y) { return 0 <= x && x < y && y <= 4; };

TEST(FillRuleOracle, ReproducesTheConventionsExample) {
  // The test's own rule must agree with the hand derivation before it is used as an oracle.
  auto upper = rule_map(fx8_triangle({0.5, 0.5}, {5.5, 0.5}, {5.5, 5.5}), kW, kH);
  auto lower = rule_map(fx8_triangle({0.5, 5.5}, {0.5, 0.5}, {5.5, 5.5}), kW, kH);
  EXPECT_EQ(upper, map_of(kUpperTriangle));
  EXPECT_EQ(lower, map_of(kLowerTriangle));
  EXPECT_EQ(total(upper), 15);
  EXPECT_EQ(total(lower), 10);
}

TEST_P(FillRule, ConventionsExamplePair) {
  const glm::dvec2 a{0.5, 0.5}, b{5.5, 0.5}, c{5.5, 5.5}, d{0.5, 5.5};
  for (bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "clockwise in the image" : "as given");
    auto upper = reversed ? draw_triangle(a, c, b) : draw_triangle(a, b, c);
    auto lower = reversed ? draw_triangle(d, c, a) : draw_triangle(d, a, c);
    EXPECT_EQ(upper, map_of(kUpperTriangle)) << pictures(map_of(kUpperTriangle), upper);
    EXPECT_EQ(lower, map_of(kLowerTriangle)) << pictures(map_of(kLowerTriangle), lower);
    EXPECT_EQ(total(upper), 15);
    EXPECT_EQ(total(lower), 10);
  }
  // Together: the 5x5 square, every pixel exactly once.
  auto both = draw_triangles({a, b, c, d, a, c});
  auto square = map_of([](int x, int y) { return x >= 0 && x < 5 && y >= 0 && y < 5; });
  EXPECT_EQ(both, square) << pictures(square, both);
}

// A rectangle whose edges pass through pixel centres keeps its top row and left column only.
TEST_P(FillRule, RectangleKeepsTopRowAndLeftColumn) {
  struct Rect {
    double x0, y0, x1, y1;
  };
  // The last two are one pixel wide and one pixel high.
  for (Rect r : {Rect{2.5, 3.5, 9.5, 7.5}, Rect{4.5, 2.5, 5.5, 9.5}, Rect{3.5, 6.5, 12.5, 7.5}}) {
    const glm::dvec2 tl{r.x0, r.y0}, tr{r.x1, r.y0}, br{r.x1, r.y1}, bl{r.x0, r.y1};
    // Pixels whose centre c satisfies x0 <= c.x < x1 and y0 <= c.y < y1.
    auto expected = map_of([&](int x, int y) {
      return x + 0.5 >= r.x0 && x + 0.5 < r.x1 && y + 0.5 >= r.y0 && y + 0.5 < r.y1;
    });
    const std::vector<std::vector<glm::dvec2>> triangulations = {
        {tl, tr, br, tl, br, bl},  // diagonal tl-br, clockwise in the image
        {tl, br, tr, tl, bl, br},  // the same, counter-clockwise
        {tr, br, bl, tr, bl, tl},  // diagonal tr-bl, clockwise
        {tr, bl, br, tr, tl, bl},  // diagonal tr-bl, counter-clockwise
    };
    for (size_t k = 0; k < triangulations.size(); ++k) {
      SCOPED_TRACE("rectangle " + std::to_string(r.x0) + "," + std::to_string(r.y0) +
                   " triangulation " + std::to_string(k));
      auto hits = draw_triangles(triangulations[k]);
      EXPECT_EQ(hits, expected) << pictures(expected, hits);
    }
  }
}

// The right triangle with legs (6, 0) and (0, 4) at the origin, and its partner completing the
// 6x4 rectangle, in one of 8 orientations (rotation by k * 90 degrees, then an optional mirror),
// placed at `origin`. All vertices are pixel centres and the hypotenuse passes through the
// pixel centre at its midpoint.
struct Orientation {
  int quarter_turns;
  bool mirror;
};

glm::dvec2 orient(glm::dvec2 p, Orientation o, glm::dvec2 origin) {
  for (int k = 0; k < o.quarter_turns; ++k) p = {-p.y, p.x};
  if (o.mirror) p.x = -p.x;
  return origin + p;
}

std::vector<Orientation> all_orientations() {
  std::vector<Orientation> out;
  for (int k = 0; k < 4; ++k) {
    for (bool m : {false, true}) out.push_back({k, m});
  }
  return out;
}

std::string describe(Orientation o) {
  return std::to_string(o.quarter_turns * 90) + " degrees" + (o.mirror ? ", mirrored" : "");
}

void check_right_triangles(FillRule& test, glm::dvec2 origin) {
  const glm::dvec2 base[3] = {{0, 0}, {6, 0}, {0, 4}};
  const glm::dvec2 partner[3] = {{6, 0}, {6, 4}, {0, 4}};
  for (Orientation o : all_orientations()) {
    SCOPED_TRACE(describe(o));
    glm::dvec2 t[3], p[3];
    for (int i = 0; i < 3; ++i)
      t[i] = orient(base[i], o, origin), p[i] = orient(partner[i], o, origin);
    auto expected_t = rule_map(fx8_triangle(t[0], t[1], t[2]), kW, kH);
    auto expected_p = rule_map(fx8_triangle(p[0], p[1], p[2]), kW, kH);
    for (bool reversed : {false, true}) {
      SCOPED_TRACE(reversed ? "reversed winding" : "listed winding");
      auto hits_t =
          reversed ? test.draw_triangle(t[0], t[2], t[1]) : test.draw_triangle(t[0], t[1], t[2]);
      auto hits_p =
          reversed ? test.draw_triangle(p[0], p[2], p[1]) : test.draw_triangle(p[0], p[1], p[2]);
      EXPECT_EQ(hits_t, expected_t) << pictures(expected_t, hits_t);
      EXPECT_EQ(hits_p, expected_p) << pictures(expected_p, hits_p);
    }
    // Independently of the rule's edge cases: the pair tiles the rectangle, whose pixels are
    // those with centres in [xmin, xmax) x [ymin, ymax).
    double xmin = std::min({t[0].x, t[1].x, t[2].x}), xmax = std::max({t[0].x, t[1].x, t[2].x});
    double ymin = std::min({t[0].y, t[1].y, t[2].y}), ymax = std::max({t[0].y, t[1].y, t[2].y});
    auto rect = map_of([&](int x, int y) {
      return x + 0.5 >= xmin && x + 0.5 < xmax && y + 0.5 >= ymin && y + 0.5 < ymax;
    });
    auto both = test.draw_triangles({t[0], t[1], t[2], p[0], p[1], p[2]});
    EXPECT_EQ(both, rect) << pictures(rect, both);
    EXPECT_EQ(total(rect), 24);
  }
}

TEST_P(FillRule, RightTriangleInAllEightOrientations) {
  check_right_triangles(*this, {16.5, 16.5});
}

// Shifting the example pair by 1/256 pixel moves exactly the samples the rule says it moves.
TEST_P(FillRule, ConventionsPairShiftedBySubpixelStep) {
  struct Case {
    double dx, dy;
    PixelPredicate upper, lower;
  };
  // Derived by hand: e.g. for +1/256 in x, the upper triangle's left (diagonal) edge leaves the
  // diagonal samples and its right edge x = 5.5 + 1/256 takes in column 5.
  const Case cases[] = {
      {kEps, 0, [](int x, int y) { return 0 <= y && y < x && x <= 5; },
       [](int x, int y) { return 1 <= x && x <= y && y <= 4; }},
      {-kEps, 0, [](int x, int y) { return 0 <= y && y <= x && x <= 4; },
       [](int x, int y) { return 0 <= x && x < y && y <= 4; }},
      {0, kEps, [](int x, int y) { return 1 <= y && y <= x && x <= 4; },
       [](int x, int y) { return 0 <= x && x < y && y <= 5; }},
      {0, -kEps, [](int x, int y) { return 0 <= y && y < x && x <= 4; },
       [](int x, int y) { return 0 <= x && x <= y && y <= 4; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("shift " + std::to_string(c.dx * 256) + ", " + std::to_string(c.dy * 256));
    const glm::dvec2 s{c.dx, c.dy};
    glm::dvec2 a = glm::dvec2{0.5, 0.5} + s, b = glm::dvec2{5.5, 0.5} + s;
    glm::dvec2 cc = glm::dvec2{5.5, 5.5} + s, d = glm::dvec2{0.5, 5.5} + s;
    auto upper = draw_triangle(a, b, cc), lower = draw_triangle(d, a, cc);
    EXPECT_EQ(upper, map_of(c.upper)) << pictures(map_of(c.upper), upper);
    EXPECT_EQ(lower, map_of(c.lower)) << pictures(map_of(c.lower), lower);
    EXPECT_EQ(upper, rule_map(fx8_triangle(a, b, cc), kW, kH));
    EXPECT_EQ(lower, rule_map(fx8_triangle(d, a, cc), kW, kH));
  }
  // All nine shifts (including diagonal ones): the pair still tiles its shifted square.
  for (int sx = -1; sx <= 1; ++sx) {
    for (int sy = -1; sy <= 1; ++sy) {
      const glm::dvec2 s{sx * kEps, sy * kEps};
      SCOPED_TRACE("shift " + std::to_string(sx) + ", " + std::to_string(sy));
      auto both = draw_triangles({glm::dvec2{0.5, 0.5} + s, glm::dvec2{5.5, 0.5} + s,
                                  glm::dvec2{5.5, 5.5} + s, glm::dvec2{0.5, 5.5} + s,
                                  glm::dvec2{0.5, 0.5} + s, glm::dvec2{5.5, 5.5} + s});
      auto square = map_of([&](int x, int y) {
        return x + 0.5 >= 0.5 + s.x && x + 0.5 < 5.5 + s.x && y + 0.5 >= 0.5 + s.y &&
               y + 0.5 < 5.5 + s.y;
      });
      EXPECT_EQ(both, square) << pictures(square, both);
    }
  }
}

TEST_P(FillRule, RightTrianglesShiftedBySubpixelSteps) {
  for (int sx = -1; sx <= 1; ++sx) {
    for (int sy = -1; sy <= 1; ++sy) {
      SCOPED_TRACE("shift " + std::to_string(sx) + "/256, " + std::to_string(sy) + "/256");
      check_right_triangles(*this, glm::dvec2{16.5 + sx * kEps, 16.5 + sy * kEps});
    }
  }
}

// Snapping rounds half to even: an edge half a step right of a pixel centre snaps onto it when
// the centre is an even multiple of 1/256 (2.5 = 640/256; 9.5 = 2432/256), three half steps right
// snaps one step past it. Left edges on a sample are in, right edges on a sample are out.
TEST_P(FillRule, SnappingRoundsHalfToEven) {
  struct Case {
    double x0, x1;
    int first_column, end_column;  // covered columns [first, end)
  };
  const double half = 1.0 / 512.0;
  const Case cases[] = {
      {2.5 + half, 9.5 + half, 2, 9},           // 640.5 -> 640, 2432.5 -> 2432
      {2.5 + 3 * half, 9.5 + 3 * half, 3, 10},  // 641.5 -> 642, 2433.5 -> 2434
      {2.5 - half, 9.5 - half, 2, 9},           // 639.5 -> 640, 2431.5 -> 2432
      {2.5 - 3 * half, 9.5 - 3 * half, 2, 9},   // 638.5 -> 638, 2430.5 -> 2430
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("x0 = " + std::to_string(c.x0 * 256) + "/256");
    const glm::dvec2 tl{c.x0, 3.5}, tr{c.x1, 3.5}, br{c.x1, 6.5}, bl{c.x0, 6.5};
    auto hits = draw_triangles({tl, tr, br, tl, br, bl});
    auto expected = map_of(
        [&](int x, int y) { return x >= c.first_column && x < c.end_column && y >= 3 && y < 6; });
    EXPECT_EQ(hits, expected) << pictures(expected, hits);
  }
}

INSTANTIATE_TEST_SUITE_P(BothRasterizers, FillRule,
                         testing::Values(RasterAlgorithm::kEdgeEquations,
                                         RasterAlgorithm::kScanline),
                         algorithm_name);

}  // namespace
}  // namespace softrast
