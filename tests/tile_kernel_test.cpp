// The tile kernels (pipeline/tile_kernels.hpp) at every SIMD level this CPU has, against the
// edge-equation rasterizer: the same blocks with the same masks, tile by tile, for triangles on
// both sides of the 32-bit bound (fixed_point.hpp's kSmallTriangleFx8), tiny ones inside one
// block, huge ones, and the image's cut last row and column of tiles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <utility>

#include "counting_shader.hpp"
#include "fill_rule_oracle.hpp"
#include "pipeline/tile_kernels.hpp"
#include "raster/raster.hpp"
#include "softrast/shader.hpp"
#include "softrast/simd_level.hpp"
#include "test_util.hpp"

namespace softrast {
namespace {

using detail::PixelRect;
using Blocks = std::map<std::pair<int, int>, uint32_t>;

// A fragment program that records the blocks it is given (the shader pointer is the map).
void record_block(const void* shader, const detail::ShadeTarget&, const detail::Interpolants&,
                  int x, int y, uint32_t mask) {
  auto& blocks = *static_cast<Blocks*>(const_cast<void*>(shader));
  EXPECT_EQ(blocks.count({x, y}), 0u) << "block emitted twice";
  blocks[{x, y}] = mask;
}

void collect(void* context, int x, int y, uint32_t mask) {
  (*static_cast<Blocks*>(context))[{x, y}] = mask;
}

// One record in an arena, as the binned draw makes it; with `blocks`, a speck's coverage by block
// as the SIMD setup gives it (TriRecord::blocks), and no edges: the bytes before its header, where
// a record with edges has them, are garbage that no kernel may use.
struct OneRecord {
  static constexpr uint32_t kOffset = sizeof(detail::RecordEdges);  // the header's
  alignas(8) std::byte bytes[kOffset + detail::record_bytes(0)];
  detail::TriRecord* header() { return reinterpret_cast<detail::TriRecord*>(bytes + kOffset); }
  OneRecord(const detail::TriangleSetup& tri, uint64_t blocks) {
    auto* rec = new (bytes + kOffset) detail::TriRecord;
    if (blocks != 0) {
      std::memset(bytes, 0x5a, kOffset);
    } else {
      rec->set_edges(tri.edge);
    }
    rec->bounds = tri.bounds;
    rec->blocks = blocks;
    auto extent = [](const int32_t v[3]) {
      return int64_t(std::max({v[0], v[1], v[2]})) - std::min({v[0], v[1], v[2]});
    };
    rec->small =
        extent(tri.vx) <= detail::kSmallTriangleFx8 && extent(tri.vy) <= detail::kSmallTriangleFx8;
    std::memcpy(static_cast<void*>(&rec->interp()), &tri.interp, detail::interpolants_bytes(0));
  }
};

bool agrees(const detail::TriangleSetup& tri, const PixelRect& scissor, uint64_t blocks);
int specks_checked = 0;     // agrees() calls with a record's blocks
int five_pixel_specks = 0;  // of them, those with bounds 5 pixels wide or high

// Compares the kernels of every level with the edge-equation rasterizer on every tile the
// triangle touches, from the edges and (bounds of at most 5x5 pixels, the SIMD setup's specks)
// from the blocks' masks; returns false (with failures recorded) on a difference.
bool agrees(const detail::WindowVertex v[3], int width, int height) {
  const PixelRect scissor{0, 0, width, height};
  detail::TriangleSetup tri;
  if (!detail::setup_triangle(v[0], v[1], v[2], 0, CullMode::kNone, FrontFace::kCounterClockwise,
                              scissor, tri)) {
    return true;
  }
  if (!agrees(tri, scissor, 0)) return false;
  const PixelRect& b = tri.bounds;
  if (b.x1 - b.x0 > 5 || b.y1 - b.y0 > 5) return true;
  const test::Fx8Triangle rule{{tri.vx[0], tri.vx[1], tri.vx[2]},
                               {tri.vy[0], tri.vy[1], tri.vy[2]}};
  const uint64_t blocks = test::rule_block_masks(rule, b.x0, b.y0, b.x1, b.y1);
  if (blocks == 0) return true;  // the SIMD setup drops it
  ++specks_checked;
  five_pixel_specks += std::max(b.x1 - b.x0, b.y1 - b.y0) == 5;
  return agrees(tri, scissor, blocks);
}

bool agrees(const detail::TriangleSetup& tri, const PixelRect& scissor, uint64_t blocks) {
  OneRecord record(tri, blocks);
  uint32_t offset = OneRecord::kOffset;
  for (int level = 0; level <= int(cpu_simd_level()); ++level) {
    detail::TileKernels kernels = detail::tile_kernels(SimdLevel(level));
    for (int ty = tri.bounds.y0 / 64; ty <= (tri.bounds.y1 - 1) / 64; ++ty) {
      for (int tx = tri.bounds.x0 / 64; tx <= (tri.bounds.x1 - 1) / 64; ++tx) {
        PixelRect region =
            detail::intersect({tx * 64, ty * 64, tx * 64 + 64, ty * 64 + 64}, scissor);
        Blocks expected, got;
        detail::rasterize_triangle_edge_equations(tri, region, {&collect, &expected});
        detail::FragmentProgram program{&record_block, &got};
        detail::ShadeTarget target;
        detail::TileJob job;
        job.region = region;
        job.program = &program;
        job.target = &target;
        kernels.immediate(job, record.bytes, &offset, 1);
        if (got != expected) {
          ADD_FAILURE() << "level " << simd_level_name(SimdLevel(level)) << " tile " << tx << ","
                        << ty << " small " << record.header()->small << " blocks " << blocks
                        << " scissor " << scissor.x0 << "," << scissor.y0 << " vertices ("
                        << tri.vx[0] << "," << tri.vy[0] << ") (" << tri.vx[1] << "," << tri.vy[1]
                        << ") (" << tri.vx[2] << "," << tri.vy[2] << ")";
          return false;
        }
      }
    }
  }
  return true;
}

detail::WindowVertex vertex(int64_t x, int64_t y) {
  detail::WindowVertex w;
  w.x = int32_t(x);
  w.y = int32_t(y);
  return w;
}

TEST(TileKernel, CoverageEqualsTheEdgeEquationRasterizer) {
  std::mt19937 rng(1234);
  const int width = 300, height = 200;  // cut tiles on the right and at the bottom
  // Triangle sizes in 1/256 pixel: inside one block, around the 32-bit bound, large, huge (far
  // outside the image, inside the guard band).
  const int64_t sizes[] = {700,
                           1000,
                           3000,
                           detail::kSmallTriangleFx8 - 50,
                           detail::kSmallTriangleFx8 + 50,
                           80 * 256,
                           400 * 256,
                           20000 * 256};
  for (int64_t size : sizes) {
    std::uniform_int_distribution<int64_t> centre_x(-20 * 256, (width + 20) * 256),
        centre_y(-20 * 256, (height + 20) * 256), offset(-size / 2, size / 2);
    for (int i = 0; i < 400; ++i) {
      int64_t cx = centre_x(rng), cy = centre_y(rng);
      detail::WindowVertex v[3];
      for (auto& w : v) w = vertex(cx + offset(rng), cy + offset(rng));
      if (i % 4 == 0) v[1].y = v[0].y;  // horizontal edges: the fill rule's ties
      if (i % 5 == 0) v[2].x = v[1].x;  // vertical edges
      if (i % 7 == 0) {                 // vertices on sample points
        for (auto& w : v) w.x = (w.x & ~255) + 128, w.y = (w.y & ~255) + 128;
      }
      ASSERT_TRUE(agrees(v, width, height)) << "size " << size << " triangle " << i;
    }
  }
  EXPECT_GT(specks_checked, 200);    // the masks of specks, on both sides of tiles' edges
  EXPECT_GT(five_pixel_specks, 10);  // 23 with this seed
}

// Triangles whose vertices span exactly the 32-bit bound (kSmallTriangleFx8) in x and y, the
// largest that take the int32 path, in the shapes that give its edge functions their largest
// values over the blocks the kernels evaluate: right triangles with both legs at the bound, in
// all four orientations, and slivers along either diagonal, at sub-pixel offsets that put their
// corners on and off sample points and their bounds across tiles. Any value past int32 would
// change a block's mask.
TEST(TileKernel, TrianglesAtTheThirtyTwoBitBoundEqualTheEdgeEquationRasterizer) {
  const int64_t s = detail::kSmallTriangleFx8;
  const int width = 400, height = 300;
  int checked = 0;
  for (int64_t ox : {0, 1, 128, 255, 37 * 256 + 77}) {
    for (int64_t oy : {0, 1, 128, 255, 21 * 256 + 200}) {
      const int64_t x0 = 40 * 256 + ox, y0 = 30 * 256 + oy, x1 = x0 + s, y1 = y0 + s;
      const detail::WindowVertex shapes[][3] = {
          {vertex(x0, y0), vertex(x1, y0), vertex(x0, y1)},
          {vertex(x1, y0), vertex(x1, y1), vertex(x0, y0)},
          {vertex(x1, y1), vertex(x0, y1), vertex(x1, y0)},
          {vertex(x0, y1), vertex(x0, y0), vertex(x1, y1)},
          {vertex(x0, y0), vertex(x1, y1), vertex(x0 + 300, y0)},
          {vertex(x0, y1), vertex(x1, y0), vertex(x1, y0 + 300)},
      };
      for (const auto& v : shapes) {
        ASSERT_TRUE(agrees(v, width, height)) << "offset " << ox << "," << oy;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 150);
}

// The resolve kernels' depth is the fragment stage's (shade_block.hpp) to the bit, including
// the clamp of values outside [0, 1], NaN and large gradients, and the test is LESS or LEQUAL.
TEST(TileKernel, ResolveComputesTheFragmentStagesDepth) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> value(-2.0f, 3.0f), gradient(-0.3f, 0.3f),
      ref(-100.0f, 400.0f);
  for (int level = 0; level <= int(cpu_simd_level()); ++level) {
    detail::ResolveBlockFn resolve = detail::tile_kernels(SimdLevel(level)).resolve_block;
    for (int i = 0; i < 2000; ++i) {
      detail::DepthPlaneRef p{ref(rng), ref(rng), {value(rng), gradient(rng), gradient(rng)}};
      if (i % 10 == 0) p.z.a0 = std::numeric_limits<float>::quiet_NaN();
      if (i % 10 == 1) p.z.dadx = 1e30f;
      if (i % 10 == 2) p.z = {0.5f, 0.0f, 0.0f};  // ties with the stored 0.5 below
      // Planes of constant depth take the resolve's shortcut (z = float(a0) everywhere); planes
      // flat in one direction only must not, nor a0 = 0 (there the sum's zero sign depends on the
      // gradients' and dx's signs). (Not a0 = -0: the kernels broadcast a coefficient by adding
      // it to a vector of +0, which makes -0 +0, so the wide stages store +0 where the scalar
      // eval_plane stores -0; both compare equal in every depth test.)
      if (i % 10 == 3) p.z.dadx = 0.0;
      if (i % 10 == 4) p.z.dady = 0.0;
      if (i % 10 == 5) {
        const double a0[] = {0.0, 0.25, -0.5, 1.5, 0.7071067811865476};
        const double zero[] = {0.0, -0.0};
        p.z = {a0[(i / 10) % 5], zero[(i / 50) % 2], zero[(i / 100) % 2]};
      }
      int x = 4 * int(rng() % 4000), y = 4 * int(rng() % 4000);
      uint32_t mask = rng() & 0xffffu;
      bool less_equal = i % 2 == 0;
      alignas(64) float depth[16];
      alignas(64) int32_t ids[16];
      for (int l = 0; l < 16; ++l) depth[l] = l % 3 == 0 ? 0.5f : value(rng), ids[l] = -1;
      float expected_depth[16];
      int32_t expected_ids[16];
      for (int l = 0; l < 16; ++l) {
        float dx = float(x + (l & 3)) + 0.5f - p.x_ref, dy = float(y + (l >> 2)) + 0.5f - p.y_ref;
        float z = std::clamp(detail::eval_plane(p.z, dx, dy), 0.0f, 1.0f);
        bool pass = (mask >> l & 1) &&
                    detail::depth_passes(less_equal ? DepthFunc::kLessEqual : DepthFunc::kLess, z,
                                         depth[l]);
        expected_depth[l] = pass ? z : depth[l];
        expected_ids[l] = pass ? 7 : -1;
      }
      resolve(p, x, y, mask, 7, less_equal, depth, ids);
      ASSERT_EQ(std::memcmp(depth, expected_depth, sizeof(depth)), 0)
          << simd_level_name(SimdLevel(level)) << " case " << i;
      ASSERT_EQ(std::memcmp(ids, expected_ids, sizeof(ids)), 0)
          << simd_level_name(SimdLevel(level)) << " case " << i;
    }
  }
}

// A framebuffer stores the blocks cut by the image's right and bottom edges whole, but only the
// image's pixels are shaded: a mesh that covers more than the image shades each pixel once (the
// fill rule gives a pixel to one triangle), for images whose size is not a multiple of 4 and one
// that is, with small triangles (each block's coverage directly) and large ones (16x16 areas
// classified), immediate (additive) and deferrable (opaque, depth less), at every level, with 1
// and 2 threads.
TEST(TileKernel, ShadesOnlyTheImagesPixels) {
  SimdLevel cap = simd_level();
  for (auto [width, height] : {std::pair{61, 37}, std::pair{130, 67}, std::pair{64, 48}}) {
    for (int cells : {1, 3, 24}) {
      std::vector<glm::vec4> clip;
      std::vector<uint32_t> indices;
      for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
          clip.push_back({-1.25f + 2.5f * float(i) / float(cells),
                          -1.25f + 2.5f * float(j) / float(cells), 0.5f, 1.0f});
        }
      }
      for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
          uint32_t a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + uint32_t(cells + 1),
                   d = c + 1;
          indices.insert(indices.end(), {a, b, d, a, d, c});
        }
      }
      for (bool opaque : {false, true}) {
        RenderState state = test::counting_state();
        if (opaque) {
          state.blend = BlendMode::kOpaque;
          state.depth_test = true;
          state.depth_func = DepthFunc::kLess;
          state.depth_write = true;
        }
        for (int level = 0; level <= int(cap); ++level) {
          set_simd_level(SimdLevel(level));
          for (int threads : {1, 2}) {
            state.threads = threads;
            Framebuffer fb(width, height);
            fb.clear({0.0f, 0.0f, 0.0f, 0.0f});
            test::CountingShader shader;
            shader.positions = clip.data();
            draw(fb, state, shader, indices, uint32_t(clip.size()));
            EXPECT_EQ(shader.shaded.load(), int64_t(width) * height)
                << width << "x" << height << ", " << cells << " cells, "
                << (opaque ? "opaque" : "additive") << ", " << simd_level_name(SimdLevel(level))
                << ", threads " << threads;
          }
        }
      }
    }
  }
  set_simd_level(cap);
}

}  // namespace
}  // namespace softrast
