// tests/raster_reference_test.cpp: both triangle rasterizers against a brute-force rasterizer
// written in the test from the rule alone (every sample of the scissor tested against the three
// edges in exact integer arithmetic, the top-left rule judged geometrically, see test_util.hpp),
// and culling against an independently computed winding.
#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "raster/raster.hpp"
#include "raster/setup.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

using detail::PixelRect;
using detail::TriangleSetup;
using detail::WindowVertex;
using test::CoverageCollector;
using test::describe_triangle;
using test::Fx8Triangle;
using test::rule_covers_pixel;
using test::TriangleGenerator;

Fx8Triangle fx8_of(const WindowVertex (&v)[3]) {
  return {{v[0].x, v[1].x, v[2].x}, {v[0].y, v[1].y, v[2].y}};
}

// Every pixel of the scissor: the rule's answer against what `collector` received.
std::string diff_against_rule(const Fx8Triangle& t, const PixelRect& s,
                              const CoverageCollector& collector) {
  std::string out = collector.errors();
  for (int y = s.y0; y < s.y1; ++y) {
    for (int x = s.x0; x < s.x1; ++x) {
      bool want = rule_covers_pixel(t, x, y);
      if (want != (collector.count(x, y) == 1)) {
        out += (want ? "missing " : "extra ") + std::to_string(x) + ", " + std::to_string(y) + "\n";
      }
    }
  }
  return out;
}

void check_against_rule(uint32_t seed, const PixelRect& scissor, int count, int& compared) {
  TriangleGenerator gen(seed);
  CoverageCollector collector(scissor);
  int failures = 0;
  for (int n = 0; n < count && failures < 5; ++n) {
    WindowVertex v[3];
    gen.make(TriangleGenerator::Kind(n % TriangleGenerator::kCount), scissor, v);
    for (bool reversed : {false, true}) {
      if (reversed) std::swap(v[1], v[2]);
      Fx8Triangle t = fx8_of(v);
      TriangleSetup tri;
      bool set_up = detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone,
                                           FrontFace::kCounterClockwise, scissor, tri);
      if (!set_up) {
        // Allowed only when the rule covers no sample of the scissor either.
        collector.reset({0, 0, 0, 0});
        std::string diff = diff_against_rule(t, scissor, collector);
        if (!diff.empty()) ++failures;
        EXPECT_TRUE(diff.empty()) << "rejected by setup: " << describe_triangle(v, scissor) << "\n"
                                  << diff;
        continue;
      }
      for (bool scanline : {false, true}) {
        collector.reset(tri.bounds);
        if (scanline) {
          detail::rasterize_triangle_scanline(tri, scissor, collector.sink());
        } else {
          detail::rasterize_triangle_edge_equations(tri, scissor, collector.sink());
        }
        std::string diff = diff_against_rule(t, scissor, collector);
        if (!diff.empty()) ++failures;
        EXPECT_TRUE(diff.empty()) << (scanline ? "scanline: " : "edge equations: ")
                                  << describe_triangle(v, scissor) << "\n"
                                  << diff;
        ++compared;
      }
    }
  }
}

TEST(RasterReference, BothRasterizersMatchTheBruteForceRule) {
  int compared = 0;
  check_against_rule(101, {0, 0, 64, 64}, 4000, compared);
  check_against_rule(102, {12, 4, 12 + 37, 4 + 45}, 2000, compared);
  EXPECT_GT(compared, 15000);
}

// The rule oracle itself on the triangles the agreement test cannot judge: it must agree with a
// rasterizer-independent fact: the two halves of a random convex quad split along a diagonal
// cover each sample strictly inside the quad exactly once, and no sample twice.
TEST(RasterReference, RuleOracleTilesQuads) {
  TriangleGenerator gen(7);
  for (int n = 0; n < 300; ++n) {
    // A convex quad: four points at increasing angles around a centre.
    int64_t cx = gen.uniform(20 * 256, 44 * 256), cy = gen.uniform(20 * 256, 44 * 256);
    int64_t qx[4], qy[4];
    const int64_t dirs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    for (int k = 0; k < 4; ++k) {
      int64_t r = gen.uniform(4 * 256, 16 * 256);
      qx[k] = cx + dirs[k][0] * r + (n % 2 ? 0 : gen.uniform(-256, 256));
      qy[k] = cy + dirs[k][1] * r + (n % 2 ? 0 : gen.uniform(-256, 256));
    }
    Fx8Triangle a{{qx[0], qx[1], qx[2]}, {qy[0], qy[1], qy[2]}};
    Fx8Triangle b{{qx[0], qx[3], qx[2]}, {qy[0], qy[3], qy[2]}};  // other winding on purpose
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        int hits = rule_covers_pixel(a, x, y) + rule_covers_pixel(b, x, y);
        int64_t sx = int64_t(x) * 256 + 128, sy = int64_t(y) * 256 + 128;
        bool strictly_inside = true;  // the quad runs clockwise in the image: all crosses > 0
        for (int k = 0; k < 4; ++k) {
          int j = (k + 1) % 4;
          strictly_inside =
              strictly_inside && test::cross_fx(qx[k], qy[k], qx[j], qy[j], sx, sy) > 0;
        }
        if (strictly_inside) {
          ASSERT_EQ(hits, 1) << n << ": " << x << ", " << y;
        } else {
          ASSERT_LE(hits, 1) << n << ": " << x << ", " << y;
        }
      }
    }
  }
}

// Facing, from the shoelace area in y-up coordinates (Y = -y): positive is counter-clockwise as
// seen in the image.
int image_winding(const WindowVertex (&v)[3]) {
  int64_t twice = 0;
  for (int i = 0; i < 3; ++i) {
    const WindowVertex &p = v[i], &q = v[(i + 1) % 3];
    twice += int64_t(p.x) * (-int64_t(q.y)) - int64_t(q.x) * (-int64_t(p.y));
  }
  return twice > 0 ? 1 : twice < 0 ? -1 : 0;  // 1: counter-clockwise, -1: clockwise
}

TEST(RasterReference, CullingFollowsTheWindingInTheImage) {
  // A triangle that is counter-clockwise on screen: top, then bottom-left, then bottom-right.
  WindowVertex ccw[3] = {test::window_vertex(2048, 512), test::window_vertex(512, 3072),
                         test::window_vertex(3584, 3072)};
  ASSERT_EQ(image_winding(ccw), 1);  // the oracle agrees with the picture

  const PixelRect scissor{0, 0, 64, 64};
  TriangleGenerator gen(55);
  int counts[3] = {0, 0, 0};
  for (int n = 0; n < 20000; ++n) {
    WindowVertex v[3];
    gen.make(TriangleGenerator::Kind(n % TriangleGenerator::kCount), scissor, v);
    if (n == 0) std::copy(ccw, ccw + 3, v);
    int winding = image_winding(v);
    ++counts[winding + 1];
    TriangleSetup tri;
    bool any = detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone,
                                      FrontFace::kCounterClockwise, scissor, tri);
    if (winding == 0) {
      EXPECT_FALSE(any) << "zero area is never drawn: " << describe_triangle(v, scissor);
      for (CullMode cull : {CullMode::kBack, CullMode::kFront}) {
        EXPECT_FALSE(
            detail::setup_triangle(v[0], v[1], v[2], 0, cull, FrontFace::kClockwise, scissor, tri));
      }
      continue;
    }
    if (!any) continue;  // covers no sample of the scissor
    ASSERT_EQ(tri.interp.front_facing, winding == 1) << describe_triangle(v, scissor);
    for (FrontFace face : {FrontFace::kCounterClockwise, FrontFace::kClockwise}) {
      bool front = face == FrontFace::kCounterClockwise ? winding == 1 : winding == -1;
      for (CullMode cull : {CullMode::kNone, CullMode::kBack, CullMode::kFront}) {
        bool want = cull == CullMode::kNone || (cull == CullMode::kBack) == front;
        bool got = detail::setup_triangle(v[0], v[1], v[2], 0, cull, face, scissor, tri);
        ASSERT_EQ(got, want) << describe_triangle(v, scissor) << " cull " << int(cull)
                             << " front face " << int(face);
        if (got) {
          ASSERT_EQ(tri.interp.front_facing, front);
        }
      }
    }
  }
  EXPECT_GT(counts[0], 5000);  // both windings were tried
  EXPECT_GT(counts[2], 5000);
}

}  // namespace
}  // namespace softrast
