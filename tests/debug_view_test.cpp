// tests/debug_view_test.cpp: the debug views of softrast/debug_view.hpp (shared by
// `softrast render --debug` and the viewer): overdraw counts, one colour per triangle, the tile
// grid at the pipeline's tile size, and the per-tile timing hook behind the cost view.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "softrast/debug_view.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

constexpr int kSize = 64;

// Looks at z = 0 from +z through a glOrtho box of [-1, 1]^2: world (x, y) lands on pixel
// ((x + 1) * 32, (1 - y) * 32) of a 64 x 64 image.
Camera ortho_camera() {
  Camera c;
  c.eye = {0.0f, 0.0f, 2.0f};
  c.orthographic = true;
  c.near_plane = 0.5f;
  c.far_plane = 4.0f;
  return c;
}

// An axis-aligned square facing +z (two counter-clockwise triangles) at depth z.
void add_quad(Mesh& mesh, float x0, float y0, float x1, float y1, float z) {
  uint32_t base = uint32_t(mesh.positions.size());
  for (glm::vec3 p :
       {glm::vec3(x0, y0, z), glm::vec3(x1, y0, z), glm::vec3(x1, y1, z), glm::vec3(x0, y1, z)}) {
    mesh.positions.push_back(p);
    mesh.normals.push_back({0.0f, 0.0f, 1.0f});
    mesh.uvs.push_back({0.0f, 0.0f});
  }
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

std::string view_name(const testing::TestParamInfo<std::pair<RasterAlgorithm, int>>& info) {
  return std::string(info.param.first == RasterAlgorithm::kScanline ? "Scanline" : "Edge") +
         std::to_string(info.param.second) + "Threads";
}

class DebugViewTest : public testing::TestWithParam<std::pair<RasterAlgorithm, int>> {
 protected:
  RenderOptions options(DebugView view) const {
    RenderOptions o;
    o.debug_view = view;
    o.state.raster = GetParam().first;
    o.state.threads = GetParam().second;
    return o;
  }
};

// Two opaque squares overlapping in a 16 x 16 pixel square: 2 fragments there, 1 elsewhere on
// them, 0 outside. Their edges lie on pixel borders, so no centre is on an edge.
TEST_P(DebugViewTest, OverdrawCountsFragmentsPerPixel) {
  Mesh mesh;
  add_quad(mesh, -0.75f, -0.75f, 0.25f, 0.25f, 0.0f);  // pixels x 8..39, y 24..55
  add_quad(mesh, -0.25f, -0.25f, 0.75f, 0.75f, 0.5f);  // pixels x 24..55, y 8..39, in front
  Framebuffer fb(kSize, kSize);
  fb.clear();
  render_mesh(fb, mesh, ortho_camera(), options(DebugView::kOverdraw));
  auto inside = [](int v, int lo, int hi) { return v >= lo && v < hi; };
  int mismatches = 0, overlap = 0;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      int want =
          int(inside(x, 8, 40) && inside(y, 24, 56)) + int(inside(x, 24, 56) && inside(y, 8, 40));
      overlap += want == 2;
      if (fb.color_at(x, y) != overdraw_color(want)) {
        ++mismatches;
        ADD_FAILURE_AT(__FILE__, __LINE__) << "pixel " << x << "," << y << " want " << want;
        if (mismatches > 5) return;
      }
    }
  }
  EXPECT_EQ(overlap, 16 * 16);
}

// A 4 x 4 grid of squares, 32 triangles: the pixel at each triangle's centroid has that
// triangle's colour exactly (constant over the triangle), and every two triangles sharing an
// edge have different colours.
TEST_P(DebugViewTest, TrianglesGetTheirOwnColourDistinctFromNeighbours) {
  Mesh mesh;
  constexpr int kCells = 4;
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      float x0 = -1.0f + 0.5f * float(i), y0 = -1.0f + 0.5f * float(j);
      add_quad(mesh, x0, y0, x0 + 0.5f, y0 + 0.5f, 0.0f);
    }
  }
  Framebuffer fb(kSize, kSize);
  fb.clear();
  render_mesh(fb, mesh, ortho_camera(), options(DebugView::kTriangles));
  size_t triangles = mesh.triangle_count();
  std::vector<uint32_t> seen(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    glm::vec3 c(0.0f);
    for (int k = 0; k < 3; ++k) c += mesh.positions[mesh.indices[3 * t + k]] / 3.0f;
    int x = int((c.x + 1.0f) * 32.0f), y = int((1.0f - c.y) * 32.0f);
    seen[t] = fb.color_at(x, y);
    EXPECT_EQ(seen[t], triangle_color(uint32_t(t))) << "triangle " << t;
  }
  // Neighbours: the two halves of a square, and the squares left/right and above/below.
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      size_t a = 2 * size_t(j * kCells + i);  // lower-right half; a + 1 the upper-left half
      EXPECT_NE(seen[a], seen[a + 1]);
      if (i + 1 < kCells) {
        EXPECT_NE(seen[a], seen[a + 2 + 1]);  // the right square's upper-left half
      }
      if (j + 1 < kCells) {
        EXPECT_NE(seen[a + 1], seen[a + 2 * kCells]);  // the lower-right half of the square above
      }
    }
  }
  EXPECT_EQ(std::set<uint32_t>(seen.begin(), seen.end()).size(), triangles);
}

// The tiles view: grid lines exactly on the columns and rows that are multiples of the tile
// size (the pipeline's 64), the shaded image everywhere else.
TEST_P(DebugViewTest, TilesViewDrawsTheGridAtTheTileSize) {
  static_assert(kDebugTileSize == 64);
  Mesh mesh;
  add_quad(mesh, -2.0f, -2.0f, 2.0f, 2.0f, 0.0f);  // covers the whole image
  RenderOptions o = options(DebugView::kTiles);
  o.shader = ShaderKind::kFlat;
  o.color = {0.2f, 0.4f, 0.6f};
  Framebuffer fb(200, 150);
  fb.clear();
  render_mesh(fb, mesh, ortho_camera(), o);
  uint32_t flat = pack_rgba8({0.2f, 0.4f, 0.6f, 1.0f});
  int lines = 0;
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) {
      bool on_grid = x % 64 == 0 || y % 64 == 0;
      lines += on_grid;
      ASSERT_EQ(fb.color_at(x, y), on_grid ? kTileGridColor : flat) << x << "," << y;
    }
  }
  EXPECT_EQ(lines, 4 * 150 + 3 * 200 - 4 * 3);  // columns 0, 64, 128, 192; rows 0, 64, 128
}

// The timing hook of the cost view: 400 blended squares inside tile (0, 0) of a 4 x 4 grid make
// that tile the slowest, and the cost view paints it red (the top of the heat scale).
TEST_P(DebugViewTest, CostTimesEachTileAndPaintsTheSlowestRed) {
  Mesh mesh;
  for (int i = 0; i < 400; ++i) add_quad(mesh, -0.99f, 0.55f, -0.55f, 0.99f, -0.001f * i);
  RenderOptions o = options(DebugView::kNone);
  o.state.blend = BlendMode::kAlpha;  // immediate shading of every fragment
  o.alpha = 0.5f;
  TileTimes times;
  o.state.tile_times = &times;
  Framebuffer fb(256, 256);
  fb.clear();
  Camera camera = ortho_camera();
  render_mesh(fb, mesh, camera, o);
  ASSERT_EQ(times.tiles_x, 4);
  ASSERT_EQ(times.tiles_y, 4);
  ASSERT_EQ(times.seconds.size(), 16u);
  for (size_t t = 1; t < times.seconds.size(); ++t) EXPECT_GT(times.seconds[0], times.seconds[t]);

  o.state.tile_times = nullptr;
  o.debug_view = DebugView::kCost;
  fb.clear();
  render_mesh(fb, mesh, camera, o);
  glm::vec4 hot = unpack_rgba8(fb.color_at(32, 32)), cold = unpack_rgba8(fb.color_at(200, 200));
  // 65% heat over 35% of the image's grey: red dominates the slowest tile, blue an empty one.
  EXPECT_GT(hot.r, 0.6f);
  EXPECT_GT(hot.r - hot.b, 0.4f);
  EXPECT_GT(cold.b - cold.r, 0.4f);
  EXPECT_EQ(fb.color_at(64, 10), kTileGridColor);
}

INSTANTIATE_TEST_SUITE_P(Paths, DebugViewTest,
                         testing::Values(std::pair{RasterAlgorithm::kEdgeEquations, 1},
                                         std::pair{RasterAlgorithm::kEdgeEquations, 2},
                                         std::pair{RasterAlgorithm::kScanline, 2}),
                         view_name);

TEST(DebugView, NamesRoundTripAndOverdrawScaleIsDistinct) {
  for (DebugView v : {DebugView::kNone, DebugView::kTiles, DebugView::kOverdraw, DebugView::kCost,
                      DebugView::kTriangles}) {
    EXPECT_EQ(parse_debug_view(debug_view_name(v)), v);
  }
  EXPECT_FALSE(parse_debug_view("heat"));
  std::set<uint32_t> colours;
  for (int n = 0; n <= 9; ++n) colours.insert(overdraw_color(n));
  EXPECT_EQ(colours.size(), 10u);
  EXPECT_EQ(overdraw_color(9), overdraw_color(200));
}

}  // namespace
}  // namespace softrast
