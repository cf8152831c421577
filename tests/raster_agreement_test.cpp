// tests/raster_agreement_test.cpp: the two triangle rasterizers (edge equations over tiles, edge
// walking over scanlines) are independent implementations of one coverage rule, so they must
// emit exactly the same pixels for every triangle: 100,000+ random triangles of every awkward
// shape, each pixel at most once, always inside the triangle's bounds and the scissor.
#include <cstdint>
#include <string>
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
using test::TriangleGenerator;

// Rasterizes `tri` with both algorithms over `region`; returns a failure description or "".
std::string compare(const TriangleSetup& tri, const PixelRect& region, CoverageCollector& edge,
                    CoverageCollector& scan) {
  edge.reset(tri.bounds);
  scan.reset(tri.bounds);
  detail::rasterize_triangle_edge_equations(tri, region, edge.sink());
  detail::rasterize_triangle_scanline(tri, region, scan.sink());
  std::string out;
  if (!edge.errors().empty()) out += "edge equations:\n" + edge.errors();
  if (!scan.errors().empty()) out += "scanline:\n" + scan.errors();
  for (auto [x, y] : edge.pixels()) {
    if (!scan.count(x, y))
      out += "only edge equations cover " + std::to_string(x) + ", " + std::to_string(y) + "\n";
  }
  for (auto [x, y] : scan.pixels()) {
    if (!edge.count(x, y))
      out += "only the scanline rasterizer covers " + std::to_string(x) + ", " + std::to_string(y) +
             "\n";
  }
  return out;
}

struct Stats {
  int triangles = 0, set_up = 0, pixels = 0, failures = 0;
};

void run_random(uint32_t seed, const PixelRect& scissor, int count, const int weights[],
                Stats& stats) {
  TriangleGenerator gen(seed);
  CoverageCollector edge(scissor), scan(scissor);
  int total_weight = 0;
  for (int k = 0; k < TriangleGenerator::kCount; ++k) total_weight += weights[k];
  for (int n = 0; n < count && stats.failures < 10; ++n) {
    int pick = int(gen.uniform(0, total_weight - 1)), kind = 0;
    while (pick >= weights[kind]) pick -= weights[kind++];
    WindowVertex v[3];
    gen.make(TriangleGenerator::Kind(kind), scissor, v);
    ++stats.triangles;
    TriangleSetup tri;
    if (!detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone, FrontFace::kCounterClockwise,
                                scissor, tri)) {
      continue;
    }
    ++stats.set_up;
    std::string diff = compare(tri, scissor, edge, scan);
    stats.pixels += int(edge.pixels().size());
    if (!diff.empty()) {
      ++stats.failures;
      ADD_FAILURE() << "kind " << kind << " " << describe_triangle(v, scissor) << "\n" << diff;
    }
  }
}

// Weights of the triangle kinds: small, tiny, sliver, huge, pixel centres, 1/256 grid, axis.
constexpr int kMostlySmall[TriangleGenerator::kCount] = {20, 20, 20, 1, 15, 15, 10};
constexpr int kMostlyLarge[TriangleGenerator::kCount] = {5, 5, 20, 30, 10, 20, 10};

TEST(RasterAgreement, HundredThousandRandomTriangles) {
  Stats stats;
  run_random(1, {0, 0, 128, 128}, 80000, kMostlySmall, stats);
  run_random(2, {4, 8, 4 + 101, 8 + 77}, 16000, kMostlySmall, stats);  // ragged edges
  run_random(3, {0, 0, 256, 256}, 4000, kMostlyLarge, stats);
  run_random(4, {-64, -32, 64, 96}, 4000, kMostlySmall, stats);  // negative coordinates
  RecordProperty("triangles", stats.triangles);
  EXPECT_GE(stats.triangles, 100000);
  EXPECT_GT(stats.set_up, 60000);      // most of them really reached the rasterizers
  EXPECT_GT(stats.pixels, 5'000'000);  // and covered plenty of pixels
}

// Extreme coordinates: vertices near the limits of the fixed-point range (the guard band), where
// edge functions use most of their bit budget.
TEST(RasterAgreement, VerticesAtTheFixedPointLimits) {
  const PixelRect scissor{0, 0, 128, 128};
  const int64_t lim = detail::kMaxCoordFx8 - 1;
  TriangleGenerator gen(11);
  CoverageCollector edge(scissor), scan(scissor);
  int drawn = 0;
  for (int n = 0; n < 2000; ++n) {
    WindowVertex v[3];
    for (auto& p : v) {
      // Mostly at the extremes, sometimes in the image.
      auto coord = [&] {
        switch (gen.uniform(0, 3)) {
          case 0:
            return -lim + gen.uniform(0, 1000);
          case 1:
            return lim - gen.uniform(0, 1000);
          case 2:
            return gen.uniform(-lim, lim);
          default:
            return gen.uniform(0, 128 * 256);
        }
      };
      int64_t x = coord(), y = coord();
      p = test::window_vertex(x, y);
    }
    TriangleSetup tri;
    if (!detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone, FrontFace::kCounterClockwise,
                                scissor, tri)) {
      continue;
    }
    ++drawn;
    std::string diff = compare(tri, scissor, edge, scan);
    ASSERT_TRUE(diff.empty()) << describe_triangle(v, scissor) << "\n" << diff;
  }
  EXPECT_GT(drawn, 200);
}

// Rasterizing tile by tile (the region argument, as binning will use it) gives the same pixels
// as rasterizing the whole scissor at once, for both algorithms.
TEST(RasterAgreement, TileRegionsPartitionTheCoverage) {
  const PixelRect scissor{0, 0, 200, 136};
  TriangleGenerator gen(21);
  CoverageCollector whole(scissor), tiles(scissor);
  int checked = 0;
  for (int n = 0; n < 600; ++n) {
    WindowVertex v[3];
    gen.make(n % 3 == 0 ? TriangleGenerator::kHuge : TriangleGenerator::kSubpixelGrid, scissor, v);
    TriangleSetup tri;
    if (!detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone, FrontFace::kCounterClockwise,
                                scissor, tri)) {
      continue;
    }
    for (bool scanline : {false, true}) {
      auto raster = scanline ? &detail::rasterize_triangle_scanline
                             : &detail::rasterize_triangle_edge_equations;
      whole.reset(tri.bounds);
      tiles.reset(tri.bounds);
      raster(tri, scissor, whole.sink());
      for (int ty = 0; ty < scissor.y1; ty += detail::kTileSize) {
        for (int tx = 0; tx < scissor.x1; tx += detail::kTileSize) {
          PixelRect tile =
              detail::intersect(scissor, {tx, ty, tx + detail::kTileSize, ty + detail::kTileSize});
          raster(tri, tile, tiles.sink());  // a pixel emitted by two tiles is an error
        }
      }
      ASSERT_TRUE(whole.errors().empty() && tiles.errors().empty())
          << describe_triangle(v, scissor) << "\n"
          << whole.errors() << tiles.errors();
      ASSERT_EQ(whole.pixels().size(), tiles.pixels().size()) << describe_triangle(v, scissor);
      for (auto [x, y] : whole.pixels()) {
        ASSERT_EQ(tiles.count(x, y), 1) << x << ", " << y << " " << describe_triangle(v, scissor);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 600);
}

}  // namespace
}  // namespace softrast
