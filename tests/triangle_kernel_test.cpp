// The SIMD triangle kernels (pipeline/triangle_kernels.hpp) at every level this CPU has, against
// the scalar front end they replace: for every triangle of a group, the same decision (nothing,
// the scalar path, or set up) as WindowVertices::triangle, culling and setup_triangle_coverage
// make, and for a set-up triangle the same coverage, bit for bit: clockwise vertices, edge
// functions with the fill rule, bounds inside the scissor, the 32-bit flag and the signed area,
// and the plane equations of setup_triangle_interpolants (or, where 1/w needs rescaling, the
// scalar setup's); except that the kernel drops the tiny triangles that cover no pixel, exactly
// those, and gives the coverage of the others by block (the fill rule's, pixel by pixel).
// Then whole draws with culling through the binned path at every level against the reference
// path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "fill_rule_oracle.hpp"
#include "pipeline/draw_internal.hpp"
#include "pipeline/record_transpose.hpp"
#include "pipeline/triangle_kernels.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

// The largest bounds, in pixels, of a triangle whose coverage the SIMD setup finds (a speck, when
// its vertices also span at most 6 pixels): it drops those that cover no pixel and gives the
// others' blocks (TriRecord::blocks).
constexpr int kSpeckPixels = 5;

// Clip-space vertices (x, y, z, w, kKernelVaryings varyings): mostly inside the view, and some of
// each kind the front end treats apart: beyond the guard band, behind the eye, NaN and Inf,
// exactly on planes, snapped onto the same point (zero area), triangles larger than the 32-bit
// path's, 1/w outside [2^-20, 2^20] (planes rescaled by the scalar setup), and edges through
// pixel centres.
constexpr int kKernelVaryings = 6;  // one group of four and a partial one
std::vector<float> kernel_vertices(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> v;
  for (int i = 0; i < count; ++i) {
    float w = 0.2f + 2.0f * std::abs(unit(rng));
    // Clustered: neighbouring vertices are near each other, so most triangles are small.
    float cx = 0.9f * std::sin(float(i / 16)), cy = 0.9f * std::cos(float(i / 16) * 1.7f);
    float spread = (i / 64) % 3 == 0 ? 0.9f : 0.01f;
    float p[4 + kKernelVaryings] = {(cx + spread * unit(rng)) * w, (cy + spread * unit(rng)) * w,
                                    unit(rng) * w, w};
    for (int i = 0; i < kKernelVaryings; ++i) p[4 + i] = unit(rng) * float(1 << (4 * i));
    switch (i % 29) {
      case 1:
        p[0] *= 5000.0f;  // beyond the guard band
        break;
      case 2:
        p[3] = -p[3];  // behind the eye
        break;
      case 3:
        p[1] = nan;
        break;
      case 4:
        p[2] = p[3];  // on the far plane: inside
        break;
      case 5:
        p[0] = p[1] = 0.0f;  // the image centre: shared by every vertex of this kind
        break;
      case 6:
        p[1] = std::numeric_limits<float>::infinity();
        break;
      case 7:
      case 8:  // the same point in tiny or huge units: 1/w above 2^20 or below 2^-20
        for (int k = 0; k < 4; ++k) p[k] *= i % 29 == 7 ? 1e-7f : 4e6f;
        break;
      case 9:
      case 10:
      case 11:
      case 12: {
        // On columns of pixel centres of the 64-pixel-wide image (w = 1, so exactly): 9 on one,
        // 10 and 11 on the next, 12 on the one after. Their triangles' vertical edges pass
        // through samples, on the left (covered) or the right (not): the fill rule decides, in
        // the tiny-triangle test too.
        const int k = i % 29;
        const int column = 20 + (i / 29) % 7 + (k == 9 ? 0 : k == 12 ? 2 : 1);
        p[0] = float(2 * column + 1) / 64.0f - 1.0f;
        p[1] = 0.3f * unit(rng);
        p[2] = unit(rng);
        p[3] = 1.0f;
        break;
      }
      default:
        break;
    }
    v.insert(v.end(), p, p + 4 + kKernelVaryings);
  }
  return v;
}

// Whether any pixel of the coverage's bounds has its sample inside all three edges (what the tile
// kernels and the edge-equation rasterizer test), pixel by pixel.
bool covers_a_pixel(const detail::TriangleCoverage& c) {
  for (int y = c.bounds.y0; y < c.bounds.y1; ++y) {
    for (int x = c.bounds.x0; x < c.bounds.x1; ++x) {
      bool inside = true;
      for (const detail::EdgeFunction& e : c.edge) {
        inside = inside && e.at(detail::sample_fx8(x), detail::sample_fx8(y)) >= 0;
      }
      if (inside) return true;
    }
  }
  return false;
}

// Whether a sample of the coverage's bounds lies exactly on an edge's line (E = 0 before the fill
// rule's bias, E = 0 or -1 after it), inside the other two edges.
bool sample_on_an_edge(const detail::TriangleCoverage& c) {
  for (int y = c.bounds.y0; y < c.bounds.y1; ++y) {
    for (int x = c.bounds.x0; x < c.bounds.x1; ++x) {
      int on = 0, inside = 0;
      for (const detail::EdgeFunction& e : c.edge) {
        int64_t v = e.at(detail::sample_fx8(x), detail::sample_fx8(y));
        on += v == 0 || v == -1;
        inside += v >= 0;
      }
      if (on == 1 && inside >= 2) return true;
    }
  }
  return false;
}

TEST(TriangleKernel, EqualsTheScalarFrontEnd) {
  const int kVertices = 3000;
  std::vector<float> data = kernel_vertices(kVertices, 11);
  detail::ClipVertices clip{data.data(), size_t(kVertices), 4 + kKernelVaryings, kKernelVaryings};
  // Triangles of nearby vertices, a few far apart, and indices out of range.
  std::mt19937 rng(5);
  std::vector<uint32_t> indices;
  const int kTriangles = 20000;
  for (int t = 0; t < kTriangles; ++t) {
    uint32_t base = uint32_t(rng() % (kVertices - 8));
    for (int k = 0; k < 3; ++k) {
      uint32_t i = base + uint32_t(rng() % 8);
      if (t % 41 == 7 && k == 1) i = uint32_t(rng() % kVertices);
      if (t % 97 == 3 && k == 2) i = kVertices + uint32_t(rng() % 3);  // out of range
      if (t % 89 == 5) i = base;                                       // all three the same
      indices.push_back(i);
    }
  }
  int checked_ready = 0, checked_scalar = 0, checked_none = 0, checked_dropped = 0,
      checked_rescaled = 0, checked_on_edge = 0, checked_blocks = 0, checked_blocks5 = 0;
  int levels = 0;  // levels checked: the counts below are sums over them
  for (SimdLevel level : {SimdLevel::kAvx2, SimdLevel::kAvx512}) {
    if (cpu_simd_level() < level) continue;
    ++levels;
    const detail::TriangleKernel kernel = detail::triangle_kernel(level);
    ASSERT_NE(kernel.fn, nullptr);
    for (int size : {64, 1920}) {
      RenderState state;
      detail::GeometryStage geometry(size, size * 9 / 16 + 1, state, clip);
      detail::WindowVertices vertices;
      vertices.transform(geometry, 1);
      for (CullMode cull : {CullMode::kNone, CullMode::kBack, CullMode::kFront}) {
        for (FrontFace face : {FrontFace::kCounterClockwise, FrontFace::kClockwise}) {
          for (detail::PixelRect scissor :
               {geometry.scissor(), detail::PixelRect{5, 3, size / 2, size / 3}}) {
            detail::TriangleBatch batch;
            batch.indices = indices.data();
            batch.vertex_count = vertices.size();
            batch.window = vertices.window();
            batch.cull = cull;
            batch.front_face = face;
            batch.scissor = scissor;
            batch.varyings = geometry.varyings(0);
            batch.stride = geometry.stride();
            batch.num_varyings = geometry.num_varyings();
            // Groups at every offset modulo the width, and short ones.
            for (size_t first = 0; first < size_t(kTriangles);) {
              int count = int(std::min<size_t>(kernel.lanes - (first % 3 == 0 ? first % 5 : 0),
                                               kTriangles - first));
              detail::TriangleLanes lanes;
              kernel.fn(batch, first, count, lanes);
              for (int l = 0; l < kernel.lanes; ++l) {
                const bool ready = (lanes.ready >> l) & 1u, scalar = (lanes.scalar >> l) & 1u;
                SCOPED_TRACE(::testing::Message()
                             << "level " << int(level) << " triangle " << first + size_t(l)
                             << " cull " << int(cull) << " face " << int(face));
                if (l >= count) {
                  EXPECT_FALSE(ready || scalar);
                  continue;
                }
                const uint32_t* tri = indices.data() + 3 * (first + size_t(l));
                if (!geometry.valid(tri[0]) || !geometry.valid(tri[1]) || !geometry.valid(tri[2])) {
                  EXPECT_FALSE(ready || scalar);
                  ++checked_none;
                  continue;
                }
                if ((geometry.vertex_code(tri[0]) | geometry.vertex_code(tri[1]) |
                     geometry.vertex_code(tri[2])) != 0) {
                  EXPECT_TRUE(scalar && !ready);
                  ++checked_scalar;
                  continue;
                }
                EXPECT_FALSE(scalar);
                detail::WindowVertex v[3] = {vertices.vertex(geometry, tri[0]),
                                             vertices.vertex(geometry, tri[1]),
                                             vertices.vertex(geometry, tri[2])};
                int64_t area = detail::signed_area_fx16(v[0], v[1], v[2]);
                detail::TriangleCoverage want;
                const detail::WindowVertex* ordered[3];
                bool set_up =
                    area != 0 && !detail::is_culled(area, cull, face) &&
                    detail::setup_triangle_coverage(v[0], v[1], v[2], area, scissor, want, ordered);
                if (!set_up) {
                  ASSERT_FALSE(ready);
                  ++checked_none;
                  continue;
                }
                if (want.bounds.x1 - want.bounds.x0 <= kSpeckPixels &&
                    want.bounds.y1 - want.bounds.y0 <= kSpeckPixels && sample_on_an_edge(want)) {
                  ++checked_on_edge;  // kept or dropped below by the fill rule's decision
                }
                if (!ready) {
                  // Dropped by the kernel: bounds of at most 5x5 pixels, no sample covered.
                  EXPECT_LE(want.bounds.x1 - want.bounds.x0, kSpeckPixels);
                  EXPECT_LE(want.bounds.y1 - want.bounds.y0, kSpeckPixels);
                  ASSERT_FALSE(covers_a_pixel(want));
                  ++checked_dropped;
                  continue;
                }
                // Kept: only triangles that cover a pixel, wherever the test applies.
                const bool speck = want.bounds.x1 - want.bounds.x0 <= kSpeckPixels &&
                                   want.bounds.y1 - want.bounds.y0 <= kSpeckPixels &&
                                   std::max({want.vx[0], want.vx[1], want.vx[2]}) -
                                           std::min({want.vx[0], want.vx[1], want.vx[2]}) <=
                                       6 * detail::kSubpixelOne &&
                                   std::max({want.vy[0], want.vy[1], want.vy[2]}) -
                                           std::min({want.vy[0], want.vy[1], want.vy[2]}) <=
                                       6 * detail::kSubpixelOne;
                if (speck) {
                  ASSERT_TRUE(covers_a_pixel(want));
                }
                ++checked_ready;
                EXPECT_EQ(lanes.area[l], area);
                for (int k = 0; k < 3; ++k) {
                  EXPECT_EQ(lanes.x[k][l], want.vx[k]);
                  EXPECT_EQ(lanes.y[k][l], want.vy[k]);
                  EXPECT_EQ(vertices.vertex(geometry, lanes.vertex[k][l]).x, ordered[k]->x);
                  EXPECT_EQ(vertices.vertex(geometry, lanes.vertex[k][l]).y, ordered[k]->y);
                  EXPECT_EQ(lanes.edge_a[k][l], want.edge[k].a);
                  EXPECT_EQ(lanes.edge_b[k][l], want.edge[k].b);
                  EXPECT_EQ(lanes.edge_c[k][l], want.edge[k].c);
                }
                EXPECT_EQ(lanes.bounds[0][l], want.bounds.x0);
                EXPECT_EQ(lanes.bounds[1][l], want.bounds.y0);
                EXPECT_EQ(lanes.bounds[2][l], want.bounds.x1);
                EXPECT_EQ(lanes.bounds[3][l], want.bounds.y1);
                // A speck's coverage by block (the fill rule's, pixel by pixel); none for a
                // larger triangle.
                const uint64_t blocks = lanes.blocks[0][l] | uint64_t(lanes.blocks[1][l]) << 32;
                if (speck) {
                  const test::Fx8Triangle rule{{want.vx[0], want.vx[1], want.vx[2]},
                                               {want.vy[0], want.vy[1], want.vy[2]}};
                  const detail::PixelRect& b = want.bounds;
                  EXPECT_EQ(blocks, test::rule_block_masks(rule, b.x0, b.y0, b.x1, b.y1));
                  ++checked_blocks;
                  // (Bounds of 5 pixels: the fifth row or column of the speck test.)
                  if (std::max(b.x1 - b.x0, b.y1 - b.y0) == kSpeckPixels) ++checked_blocks5;
                } else {
                  EXPECT_EQ(blocks, 0u);
                }
                auto extent = [](const int32_t c[3]) {
                  return int64_t(std::max({c[0], c[1], c[2]})) - std::min({c[0], c[1], c[2]});
                };
                bool small = extent(want.vx) <= detail::kSmallTriangleFx8 &&
                             extent(want.vy) <= detail::kSmallTriangleFx8;
                EXPECT_EQ(bool((lanes.small >> l) & 1u), small);
                // The planes, bit for bit, except where setup rescales 1/w: the scalar setup's.
                float largest = std::max({ordered[0]->inv_w, ordered[1]->inv_w, ordered[2]->inv_w});
                const bool rescaled = !(largest <= 0x1p20f && largest >= 0x1p-20f);
                EXPECT_EQ(bool((lanes.scalar_planes >> l) & 1u), rescaled);
                if (rescaled) {
                  ++checked_rescaled;
                } else {
                  detail::Interpolants in;
                  detail::setup_triangle_interpolants(ordered, kKernelVaryings, area, face, in);
                  auto same = [](auto a, auto b) {
                    static_assert(sizeof a == sizeof b);
                    return std::memcmp(&a, &b, sizeof a) == 0;
                  };
                  EXPECT_TRUE(same(lanes.x_ref[l], in.x_ref) && same(lanes.y_ref[l], in.y_ref));
                  const double z[3] = {in.z.a0, in.z.dadx, in.z.dady};
                  const float inv_w[3] = {in.inv_w.a0, in.inv_w.dadx, in.inv_w.dady};
                  for (int c = 0; c < 3; ++c) {
                    EXPECT_TRUE(same(lanes.z[c][l], z[c])) << lanes.z[c][l] << " " << z[c];
                    EXPECT_TRUE(same(lanes.inv_w[c][l], inv_w[c]))
                        << lanes.inv_w[c][l] << " " << inv_w[c];
                  }
                  for (int i = 0; i < kKernelVaryings; ++i) {
                    const float var[3] = {in.var[i].a0, in.var[i].dadx, in.var[i].dady};
                    for (int c = 0; c < 3; ++c) {
                      EXPECT_TRUE(same(lanes.var[i][c][l], var[c]))
                          << "varying " << i << ": " << lanes.var[i][c][l] << " " << var[c];
                    }
                  }
                }
                if (::testing::Test::HasFailure()) return;
              }
              first += size_t(count);
            }
          }
        }
      }
    }
  }
  if (cpu_simd_level() < SimdLevel::kAvx2) GTEST_SKIP() << "no AVX2 on this CPU";
  // Every outcome was reached, many times at each level (an AVX2-only CPU checks one level: 772
  // dropped triangles there, where the thresholds were first set for the sum of two levels).
  EXPECT_GT(checked_ready, 5000 * levels);
  EXPECT_GT(checked_scalar, 500 * levels);
  EXPECT_GT(checked_none, 5000 * levels);
  EXPECT_GT(checked_dropped, 500 * levels);
  EXPECT_GT(checked_rescaled, 50 * levels);
  EXPECT_GT(checked_on_edge, 50 * levels);
  EXPECT_GT(checked_blocks, 1000 * levels);
  EXPECT_GT(checked_blocks5, 100 * levels);
}

// The kernel in the steps the binned draw gathers with (AVX-512): each group's select, its ready
// lanes appended to a gathering group (at any offset, in pieces when they do not fit, into a
// group that starts as another group's selection), then that group's finish; a group with a lane
// for the scalar path ends the gathering. Every ready lane must equal its lane of the one-step
// kernel (fn), field for field and bit for bit, planes included, in submission order.
TEST(TriangleKernel, GatheredGroupsEqualTheWholeGroups) {
  const int kVertices = 3000;
  std::vector<float> data = kernel_vertices(kVertices, 23);
  detail::ClipVertices clip{data.data(), size_t(kVertices), 4 + kKernelVaryings, kKernelVaryings};
  RenderState state;
  detail::GeometryStage geometry(1920, 1080, state, clip);
  // Triangles of nearby vertices inside the clip volume, and one in 300 with a vertex outside it
  // (the scalar path's, which ends a gathering).
  std::vector<uint32_t> inside, outside;
  for (uint32_t i = 0; i < uint32_t(kVertices); ++i) {
    (geometry.vertex_code(i) == 0 ? inside : outside).push_back(i);
  }
  ASSERT_GT(inside.size(), 1000u);
  ASSERT_GT(outside.size(), 10u);
  std::mt19937 rng(9);
  std::vector<uint32_t> indices;
  const int kTriangles = 6000;
  for (int t = 0; t < kTriangles; ++t) {
    size_t base = rng() % (inside.size() - 8);
    for (int k = 0; k < 3; ++k) indices.push_back(inside[base + rng() % 8]);
    if (t % 300 == 7) indices.back() = outside[rng() % outside.size()];
  }
  auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  int gathered_groups = 0, compared = 0, scalar_groups = 0, lower_blocks = 0, levels = 0;
  for (SimdLevel level : {SimdLevel::kAvx2, SimdLevel::kAvx512}) {
    if (cpu_simd_level() < level) continue;
    const detail::TriangleKernel kernel = detail::triangle_kernel(level);
    if (kernel.append == nullptr) continue;  // no gathering at this level
    ++levels;
    detail::WindowVertices vertices;
    vertices.transform(geometry, 1);
    for (CullMode cull : {CullMode::kBack, CullMode::kNone}) {
      detail::TriangleBatch batch;
      batch.indices = indices.data();
      batch.vertex_count = vertices.size();
      batch.window = vertices.window();
      batch.cull = cull;
      batch.scissor = geometry.scissor();
      batch.varyings = geometry.varyings(0);
      batch.stride = geometry.stride();
      batch.num_varyings = geometry.num_varyings();
      const int width = kernel.lanes;
      // The one-step kernel's ready lanes, in submission order, and the gathered ones.
      std::vector<std::pair<const detail::TriangleLanes*, int>> want, got;
      std::vector<std::unique_ptr<detail::TriangleLanes>> keep;
      // A gathering group starts as another group's selection (other triangles' values, each in
      // its field's range, as finish computes on every lane), so that a field append does not
      // copy cannot match by chance.
      int decoys = 0;
      auto fresh = [&] {
        auto g = std::make_unique<detail::TriangleLanes>();
        const size_t groups = size_t(kTriangles) / size_t(width);
        kernel.select(batch, (size_t(decoys++) * 7 % groups) * size_t(width), width, *g);
        g->ready = 0;
        return g;
      };
      auto gathering = fresh();
      int filled = 0;
      auto flush = [&] {
        if (filled == 0) return;
        EXPECT_EQ(gathering->ready, (1u << filled) - 1u);
        kernel.finish(batch, *gathering);
        for (int l = 0; l < filled; ++l) got.emplace_back(gathering.get(), l);
        keep.push_back(std::move(gathering));
        gathering = fresh();
        filled = 0;
        ++gathered_groups;
      };
      for (size_t first = 0; first < size_t(kTriangles); first += size_t(width)) {
        const int count = int(std::min<size_t>(size_t(width), kTriangles - first));
        auto whole = std::make_unique<detail::TriangleLanes>();
        kernel.fn(batch, first, count, *whole);
        for (uint32_t m = whole->ready; m != 0; m &= m - 1) {
          want.emplace_back(whole.get(), __builtin_ctz(m));
        }
        keep.push_back(std::move(whole));
        auto part_owner = std::make_unique<detail::TriangleLanes>();
        detail::TriangleLanes& part = *part_owner;
        kernel.select(batch, first, count, part);
        if (part.scalar != 0) {
          // A lane for the scalar path (a vertex outside the volume) ends the gathering, as in
          // the draw: what is gathered goes first, then this group whole.
          flush();
          kernel.finish(batch, part);
          for (uint32_t m = part.ready; m != 0; m &= m - 1)
            got.emplace_back(&part, __builtin_ctz(m));
          keep.push_back(std::move(part_owner));
          ++scalar_groups;
          continue;
        }
        // Into the gathering group in two pieces where they fit, else as many as fit, a flush
        // and the rest: offsets 0 to width - 1 all occur.
        uint32_t todo = part.ready;
        while (todo != 0) {
          const int room = width - filled;
          const int take = std::min({room, 1 + int(first % 3), __builtin_popcount(todo)});
          uint32_t piece = 0;  // the first `take` lanes of todo
          for (uint32_t m = todo; __builtin_popcount(piece) < take; m &= m - 1)
            piece |= m & (~m + 1);
          const int taken = take;
          kernel.append(part, piece, *gathering, filled);
          filled += taken;
          todo &= ~piece;
          if (filled == width) flush();
        }
      }
      flush();
      ASSERT_EQ(got.size(), want.size());
      for (size_t i = 0; i < got.size(); ++i) {
        const detail::TriangleLanes& g = *got[i].first;
        const detail::TriangleLanes& w = *want[i].first;
        const int a = got[i].second, b = want[i].second;
        SCOPED_TRACE(::testing::Message() << "level " << int(level) << " ready lane " << i);
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(g.vertex[k][a], w.vertex[k][b]);
          EXPECT_EQ(g.x[k][a], w.x[k][b]);
          EXPECT_EQ(g.y[k][a], w.y[k][b]);
          EXPECT_EQ(g.edge_a[k][a], w.edge_a[k][b]);
          EXPECT_EQ(g.edge_b[k][a], w.edge_b[k][b]);
          EXPECT_EQ(g.edge_c[k][a], w.edge_c[k][b]);
          EXPECT_TRUE(same(g.z[k][a], w.z[k][b]));
          EXPECT_TRUE(same(g.inv_w[k][a], w.inv_w[k][b]));
          for (int v = 0; v < kKernelVaryings; ++v) {
            EXPECT_TRUE(same(g.var[v][k][a], w.var[v][k][b]));
          }
        }
        for (int k = 0; k < 4; ++k) EXPECT_EQ(g.bounds[k][a], w.bounds[k][b]);
        for (int k = 0; k < 2; ++k) EXPECT_EQ(g.blocks[k][a], w.blocks[k][b]);
        EXPECT_EQ(g.area[a], w.area[b]);
        EXPECT_EQ((g.small >> a) & 1u, (w.small >> b) & 1u);
        EXPECT_EQ((g.scalar_planes >> a) & 1u, (w.scalar_planes >> b) & 1u);
        EXPECT_TRUE(same(g.x_ref[a], w.x_ref[b]) && same(g.y_ref[a], w.y_ref[b]));
        if (::testing::Test::HasFailure()) return;
        ++compared;
        if (w.blocks[1][b] != 0) ++lower_blocks;
      }
    }
  }
  if (levels == 0) GTEST_SKIP() << "no level with gathering on this CPU (AVX-512)";
  // (One level, AVX-512: 5941 lanes, 367 gathered groups, 40 ended by the scalar path, 32 lanes
  // of specks reaching the lower blocks of their area.)
  EXPECT_GT(compared, 3000 * levels);
  EXPECT_GT(gathered_groups, 200 * levels);
  EXPECT_GT(scalar_groups, 20 * levels);
  EXPECT_GT(lower_blocks, 15 * levels);
}

// write_records against the field-by-field writers, for lanes of random bits (every field's
// value range, negative and zero areas, both signs of the 32-bit edge coefficients), every number
// of varyings it takes, both windings as front and both group widths: the same bytes in every
// field of every ready lane, zeros in the padding, records back to back whole (each record's
// excess block is overwritten by the next), and nothing written past kRecordSlack.
TEST(TriangleKernel, TransposedRecordsEqualTheFieldByFieldRecords) {
  if (cpu_simd_level() < SimdLevel::kAvx2) GTEST_SKIP() << "no AVX2 on this CPU";
  std::mt19937 rng(29);
  auto fill = [&](void* p, size_t bytes) {
    auto* b = static_cast<unsigned char*>(p);
    for (size_t i = 0; i < bytes; ++i) b[i] = static_cast<unsigned char>(rng());
  };
  constexpr int kLanes = detail::TriangleLanes::kMaxLanes;
  constexpr size_t kRoom = sizeof(detail::TriRecord) + sizeof(detail::Interpolants) + 64;
  constexpr unsigned char kGuard = 0xa5;
  int compared = 0, front = 0, back = 0, binned = 0, spanning = 0, with_edge_bytes = 0;
  for (int round = 0; round < 40; ++round) {
    auto lanes = std::make_unique<detail::TriangleLanes>();
    fill(lanes.get(), sizeof(detail::TriangleLanes));
    // Bounds as set-up triangles have them (inside an image of up to 4096 pixels a side), some
    // inside one tile, some across tiles.
    for (int l = 0; l < kLanes; ++l) {
      const int x0 = int(rng() % 4000), y0 = int(rng() % 4000);
      const int w = l % 2 == 0 ? 1 + int(rng() % 6) : 1 + int(rng() % 200);
      const int h = l % 3 == 0 ? 1 + int(rng() % 6) : 1 + int(rng() % 200);
      lanes->bounds[0][l] = x0, lanes->bounds[1][l] = y0;
      lanes->bounds[2][l] = x0 + w, lanes->bounds[3][l] = y0 + h;
    }
    for (int l = 0; l < kLanes; ++l) {
      if (l % 5 == round % 5) lanes->area[l] = 0;
      if (l % 7 == round % 7) lanes->area[l] = -int64_t(rng() % 1000) - 1;
      if (l % 3 == round % 3) lanes->area[l] = int64_t(rng() % 1000) + 1;
    }
    // Specks with blocks (records without edges) and other triangles (blocks 0: with edges).
    for (int l = 0; l < kLanes; ++l) {
      if (l % 3 != round % 3) lanes->blocks[0][l] = lanes->blocks[1][l] = 0;
    }
    lanes->ready = uint32_t(rng()) | 1u;
    lanes->scalar_planes = 0;
    for (int count : {8, 16}) {
      for (int num_varyings = 0; num_varyings <= detail::kMaxTransposedVaryings; ++num_varyings) {
        const size_t bytes = detail::record_bytes(num_varyings);
        for (FrontFace face : {FrontFace::kCounterClockwise, FrontFace::kClockwise}) {
          // The ready lanes' records back to back in lane order, as the binned draw places them
          // (from an offset of 8 bytes in odd rounds), the others in scratch room; guard bytes
          // around both.
          // A ready lane without blocks has its edges just before its header.
          std::vector<unsigned char> room(kLanes * kRoom, kGuard), scratch(2 * kRoom, kGuard);
          unsigned char* const base = room.data() + 64 + 8 * (round % 2);
          unsigned char* const scratch_at = scratch.data() + 64;
          constexpr size_t kEdgeBytes = sizeof(detail::RecordEdges);
          std::byte* dest[kLanes];
          std::byte* edges[kLanes];
          bool with_edges[kLanes];
          size_t used = 0;
          for (int l = 0; l < kLanes; ++l) {
            const bool ready = (lanes->ready >> l) & 1u;
            with_edges[l] = ready && (lanes->blocks[0][l] | lanes->blocks[1][l]) == 0;
            edges[l] = reinterpret_cast<std::byte*>(with_edges[l] ? base + used : scratch_at);
            used += with_edges[l] ? kEdgeBytes : 0;
            dest[l] = reinterpret_cast<std::byte*>(ready ? base + used : scratch_at);
            used += ready ? bytes : 0;
          }
          detail::GroupTiles tiles;
          const int tiles_x = 1 + round % 31;
          detail::write_records(*lanes, count, num_varyings, face, dest, edges, tiles_x, tiles);
          // Nothing written before the first record, or past kRecordSlack after the last, or
          // around the scratch room.
          size_t last_end = 0;
          for (int l = 0; l < count; ++l) {
            if ((lanes->ready >> l) & 1u) {
              last_end = size_t(reinterpret_cast<unsigned char*>(dest[l]) - base) + bytes;
            }
          }
          auto guarded = [](const unsigned char* from, const unsigned char* to) {
            return std::all_of(from, to, [](unsigned char c) { return c == kGuard; });
          };
          ASSERT_TRUE(guarded(room.data(), base));
          ASSERT_TRUE(guarded(base + last_end + detail::kRecordSlack, room.data() + room.size()));
          ASSERT_TRUE(guarded(scratch.data(), scratch_at));
          ASSERT_TRUE(
              guarded(scratch_at + detail::kMaxTransposedBytes, scratch.data() + scratch.size()));
          for (int l = 0; l < count; ++l) {
            if (!((lanes->ready >> l) & 1u)) continue;
            SCOPED_TRACE(::testing::Message() << "lane " << l << " of " << count << ", "
                                              << num_varyings << " varyings, face " << int(face));
            alignas(64) unsigned char expected[kRoom] = {};
            auto* rec = reinterpret_cast<detail::TriRecord*>(expected + kEdgeBytes);
            detail::write_coverage(*lanes, l, rec);
            detail::write_planes(*lanes, l, num_varyings, face, rec->interp());
            (rec->interp().front_facing ? front : back) += 1;
            // The padding bytes of `expected` are zeros: its fields were written into zeros.
            ASSERT_EQ(std::memcmp(expected + kEdgeBytes, dest[l], bytes), 0);
            if (with_edges[l]) {
              ASSERT_EQ(std::memcmp(expected, edges[l], kEdgeBytes), 0);
              ++with_edge_bytes;
            }
            // The bins: the tile of the top-left pixel, and whether the bounds leave it (bounds of
            // ready lanes lie inside the image: no negative coordinate).
            const detail::PixelRect& b = rec->bounds;
            const int t = detail::kTileSize;
            if (b.x0 >= 0 && b.y0 >= 0 && b.x1 > b.x0 && b.y1 > b.y0) {
              EXPECT_EQ(tiles.tile[l], uint32_t(b.y0 / t * tiles_x + b.x0 / t));
              EXPECT_EQ((tiles.spans >> l) & 1u,
                        uint32_t(b.x0 / t != (b.x1 - 1) / t || b.y0 / t != (b.y1 - 1) / t));
              ++binned;
              spanning += (tiles.spans >> l) & 1u;
            }
            ++compared;
          }
        }
      }
    }
  }
  EXPECT_GT(compared, 3000);
  EXPECT_GT(with_edge_bytes, 1000);
  EXPECT_LT(with_edge_bytes, compared - 500);
  EXPECT_EQ(binned, compared);
  EXPECT_GT(spanning, 500);
  EXPECT_GT(binned - spanning, 500);
  EXPECT_GT(front, 500);
  EXPECT_GT(back, 500);
}

// Flat-coloured triangles of both facings, some crossing the near plane and the image border,
// through the binned path at every level, against the reference path: culling of either facing
// with either winding as front, the same image bit for bit.
struct FacingShader {
  static constexpr int kVaryings = 3;
  const glm::vec4* positions;
  const glm::vec3* colors;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = colors[i].r, v[1] = colors[i].g, v[2] = colors[i].b;
    return positions[i];
  }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    out = glm::vec4(in.vec3(0), 1.0f);
    return true;
  }
};

TEST(TriangleKernel, CulledDrawsMatchTheReferencePathAtEveryLevel) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> pos(-1.3f, 1.3f), unit(0.0f, 1.0f), size(0.005f, 0.3f);
  std::vector<glm::vec4> positions;
  std::vector<glm::vec3> colors;
  std::vector<uint32_t> indices;
  for (int t = 0; t < 30000; ++t) {
    glm::vec2 centre(pos(rng), pos(rng));
    float s = size(rng);
    glm::vec3 color(unit(rng), unit(rng), unit(rng));
    for (int k = 0; k < 3; ++k) {
      float w = t % 53 == 0 ? -0.2f + unit(rng) : 0.5f + unit(rng);  // some cross w = 0
      glm::vec2 p = centre + s * glm::vec2(unit(rng) - 0.5f, unit(rng) - 0.5f);
      positions.push_back(glm::vec4(p * w, (unit(rng) * 1.8f - 0.9f) * w, w));
      colors.push_back(color);
      indices.push_back(uint32_t(indices.size()));
    }
  }
  FacingShader shader{positions.data(), colors.data()};
  const SimdLevel cpu = cpu_simd_level();
  for (CullMode cull : {CullMode::kBack, CullMode::kFront, CullMode::kNone}) {
    for (FrontFace face : {FrontFace::kCounterClockwise, FrontFace::kClockwise}) {
      RenderState state;
      state.cull = cull;
      state.front_face = face;
      auto render = [&](SimdLevel level, bool reference, int threads) {
        set_simd_level(level);
        Framebuffer fb(317, 203);
        RenderState s = state;
        s.reference_path = reference;
        s.threads = threads;
        draw(fb, s, shader, indices, uint32_t(positions.size()));
        return fb.to_image().rgba;
      };
      for (SimdLevel level : {SimdLevel::kSse2, SimdLevel::kAvx2, SimdLevel::kAvx512}) {
        if (cpu < level) continue;
        const std::vector<uint8_t> reference = render(level, true, 1);
        for (int threads : {1, 2}) {
          EXPECT_TRUE(render(level, false, threads) == reference)
              << "cull " << int(cull) << " face " << int(face) << " level " << int(level)
              << " threads " << threads;
        }
      }
      set_simd_level(cpu);
    }
  }
}

}  // namespace
}  // namespace softrast
