// Deferred shading in tiles (pipeline/tile_visibility.hpp) against the immediate single-threaded
// reference path: colour and depth buffers bit for bit, on scenes built to break it (heavy
// overdraw in both orders, exactly equal depths under LESS and LEQUAL, several draws into one
// framebuffer, near-plane clipping), for one and two threads; and a counting shader that shows
// deferral is really taken (each visible pixel shaded once) and really refused where it must be.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "core/store_mode.hpp"
#include "pipeline/tile_visibility.hpp"
#include "softrast/shader.hpp"
#include "softrast/simd_level.hpp"

namespace softrast {
namespace {

// Clip-space positions with a colour per vertex; counts the pixels it shades when `shaded` is
// set. Varying colours make every pixel's colour depend on which triangle won it.
struct ColorShader {
  static constexpr int kVaryings = 4;
  const glm::vec4* positions;
  const glm::vec4* colors;
  std::atomic<long>* shaded = nullptr;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = colors[i].r, v[1] = colors[i].g, v[2] = colors[i].b, v[3] = colors[i].a;
    return positions[i];
  }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    if (shaded) shaded->fetch_add(1, std::memory_order_relaxed);
    out = in.vec4(0);
    return true;
  }
};

// The same, declaring that it writes depth (it writes the depth it was given): never deferrable.
struct DepthWritingShader : ColorShader {
  static constexpr bool kWritesDepth = true;
};

// Runs a scalar shader's fragment stage under the resolved contract: visibility is decided and
// depth written, so it shades the mask with the depth test off (no test, no depth write), opaque.
template <class S>
void resolved_aware_shade_block(const void* shader, const detail::ShadeTarget& target,
                                const detail::Interpolants& in, int x, int y, uint32_t mask) {
  if (!target.resolved) return detail::shade_block<S>(shader, target, in, x, y, mask);
  RenderState state = *target.state;
  state.depth_test = false;
  state.blend = BlendMode::kOpaque;
  detail::ShadeTarget plain{target.framebuffer, &state, false};
  detail::shade_block<S>(shader, plain, in, x, y, mask);
}

// draw<S>() with the fragment program marked deferrable exactly when the shader allows it (it
// does not write depth; these scalar shaders never discard), so the pipeline's own decision is
// what the tests see.
template <class S>
void draw_deferrable(Framebuffer& fb, const RenderState& state, const S& shader,
                     const std::vector<uint32_t>& indices, uint32_t vertex_count) {
  constexpr int kStride = 4 + S::kVaryings;
  std::vector<float> clip(size_t(vertex_count) * kStride);
  for (uint32_t i = 0; i < vertex_count; ++i) {
    glm::vec4 p = shader.vertex(i, &clip[size_t(i) * kStride + 4]);
    std::memcpy(&clip[size_t(i) * kStride], &p, sizeof(p));
  }
  detail::ClipVertices vertices{clip.data(), vertex_count, kStride, S::kVaryings};
  detail::FragmentProgram program{&resolved_aware_shade_block<S>, &shader, !detail::WritesDepth<S>};
  detail::draw_clip_space(fb, state, vertices, indices.data(), indices.size(), program);
}

struct Scene {
  std::vector<glm::vec4> positions, colors;
  std::vector<uint32_t> indices;

  void triangle(glm::vec4 a, glm::vec4 b, glm::vec4 c, glm::vec4 color) {
    for (const glm::vec4& p : {a, b, c}) {
      indices.push_back(uint32_t(positions.size()));
      positions.push_back(p);
      // Vary the colour per vertex so interpolation shows who won a pixel.
      colors.push_back(color * (0.6f + 0.2f * float(positions.size() % 3)));
    }
  }
};

// `count` large triangles (most cover a good part of the image) at random depths, some with w
// varying across the triangle, some crossing the near plane (z < -w) when `cross_near`.
Scene overdraw_scene(int count, unsigned seed, bool cross_near) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.6f, 1.6f), unit(0.0f, 1.0f);
  Scene scene;
  for (int t = 0; t < count; ++t) {
    glm::vec4 color(unit(rng), unit(rng), unit(rng), 1.0f);
    glm::vec4 v[3];
    for (glm::vec4& p : v) {
      float w = 0.5f + 2.0f * unit(rng);
      float z = cross_near ? -1.3f + 2.2f * unit(rng) : -0.9f + 1.8f * unit(rng);
      p = glm::vec4(pos(rng) * w, pos(rng) * w, z * w, w);
    }
    scene.triangle(v[0], v[1], v[2], color);
  }
  return scene;
}

// Quads of constant depth covering the image, sorted by depth: back to front or front to back.
Scene layered_scene(int layers, bool back_to_front, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f), unit(0.0f, 1.0f);
  Scene scene;
  for (int k = 0; k < layers; ++k) {
    int layer = back_to_front ? layers - 1 - k : k;
    float z = -0.9f + 1.8f * float(layer) / float(layers);
    float x0 = -0.9f + jitter(rng), x1 = 0.9f + jitter(rng);
    float y0 = -0.9f + jitter(rng), y1 = 0.9f + jitter(rng);
    glm::vec4 color(unit(rng), unit(rng), unit(rng), 1.0f);
    glm::vec4 a(x0, y0, z, 1), b(x1, y0, z, 1), c(x1, y1, z, 1), d(x0, y1, z, 1);
    scene.triangle(a, b, c, color);
    scene.triangle(a, c, d, color);
  }
  return scene;
}

struct Buffers {
  std::vector<uint32_t> color;
  std::vector<float> depth;
  bool operator==(const Buffers& o) const {
    return color == o.color && depth.size() == o.depth.size() &&
           std::memcmp(depth.data(), o.depth.data(), depth.size() * sizeof(float)) == 0;
  }
};

Buffers read_back(const Framebuffer& fb) {
  Buffers b;
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) b.color.push_back(fb.color_at(x, y));
  }
  b.depth = fb.depth_values();
  return b;
}

// Draws each scene in turn (one draw call each) into one framebuffer.
Buffers render(const std::vector<const Scene*>& scenes, RenderState state, int threads,
               bool reference) {
  Framebuffer fb(301, 187);  // not a multiple of the tile size
  state.threads = threads;
  state.reference_path = reference;
  for (const Scene* s : scenes) {
    ColorShader shader{s->positions.data(), s->colors.data()};
    draw_deferrable(fb, state, shader, s->indices, uint32_t(s->positions.size()));
  }
  return read_back(fb);
}

// One and two threads, with the kernels of every SIMD level this CPU has; at AVX2 with the depth
// resolve's winners written both ways (masked stores and blends, core/store_mode.hpp).
void expect_same_as_reference(const std::vector<const Scene*>& scenes, const RenderState& state,
                              const char* what) {
  Buffers reference = render(scenes, state, 1, true);
  SimdLevel cap = simd_level();  // restored after: SOFTRAST_SIMD may have capped it
  const bool masked = detail::avx2_masked_stores();
  for (int level = 0; level <= int(cap); ++level) {
    set_simd_level(SimdLevel(level));
    for (bool masked_stores : {true, false}) {
      if (!masked_stores && SimdLevel(level) != SimdLevel::kAvx2) continue;
      detail::set_avx2_masked_stores(masked_stores);
      for (int threads : {1, 2}) {
        EXPECT_TRUE(render(scenes, state, threads, false) == reference)
            << what << ", threads " << threads << ", " << simd_level_name(SimdLevel(level))
            << (masked_stores ? "" : ", blends");
      }
    }
  }
  detail::set_avx2_masked_stores(masked);
  set_simd_level(cap);
}

RenderState opaque_state(DepthFunc func) {
  RenderState state;
  state.cull = CullMode::kNone;
  state.depth_func = func;
  return state;
}

TEST(Deferred, HeavyOverdrawInBothOrdersEqualsReference) {
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    for (bool back_to_front : {true, false}) {
      Scene layers = layered_scene(48, back_to_front, 3);
      expect_same_as_reference({&layers}, opaque_state(func), "layers");
    }
    Scene random = overdraw_scene(300, 11, false);
    expect_same_as_reference({&random}, opaque_state(func), "random");
  }
}

TEST(Deferred, EqualDepthsPickTheReferenceWinner) {
  // Every triangle twice, at exactly the same depths, in a different colour: LESS keeps the
  // first, LEQUAL the last, both within one draw and across two draws.
  Scene first = overdraw_scene(60, 5, false), second = first;
  for (glm::vec4& c : second.colors) c = glm::vec4(1.0f) - c;
  Scene both = first;
  for (size_t i = 0; i < second.indices.size(); ++i) {
    both.indices.push_back(uint32_t(both.positions.size()));
    both.positions.push_back(second.positions[i]);
    both.colors.push_back(second.colors[i]);
  }
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    expect_same_as_reference({&both}, opaque_state(func), "one draw");
    expect_same_as_reference({&first, &second}, opaque_state(func), "two draws");
  }
}

TEST(Deferred, SeveralDrawsAndNearClippingEqualReference) {
  Scene a = overdraw_scene(120, 21, true), b = layered_scene(20, false, 22),
        c = overdraw_scene(120, 23, true);
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    RenderState state = opaque_state(func);
    expect_same_as_reference({&a, &b, &c}, state, "three draws");
    state.cull = CullMode::kBack;
    state.raster = RasterAlgorithm::kScanline;
    expect_same_as_reference({&a, &b, &c}, state, "three draws, culled, scanline");
  }
}

TEST(Deferred, SeveralBatchesEqualReference) {
  // 36,030 triangles, more than one batch of the binned path (each batch resolves and shades its
  // tiles, then the next one tests against the depth the previous one wrote): a few large
  // triangles, then small ones at random depths (random ones shrunk around their first vertex).
  Scene scene = overdraw_scene(30, 41, true);
  Scene small = overdraw_scene(36000, 42, false);
  for (size_t i = 0; i + 2 < small.positions.size(); i += 3) {
    glm::vec2 c(small.positions[i]);
    glm::vec4 v[3];
    for (int k = 0; k < 3; ++k) {
      glm::vec4 p = small.positions[i + k];
      v[k] = glm::vec4(c + 0.05f * (glm::vec2(p) - c), p.z, p.w);
    }
    scene.triangle(v[0], v[1], v[2], small.colors[i]);
  }
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    expect_same_as_reference({&scene}, opaque_state(func), "several batches");
  }
}

// Shades with a counting shader and returns how many pixels were shaded.
template <class S>
long count_shaded(const Scene& scene, const RenderState& state, int* visible = nullptr) {
  std::atomic<long> shaded{0};
  Framebuffer fb(256, 192);
  S shader;
  shader.positions = scene.positions.data();
  shader.colors = scene.colors.data();
  shader.shaded = &shaded;
  draw_deferrable(fb, state, shader, scene.indices, uint32_t(scene.positions.size()));
  if (visible) {
    *visible = 0;
    for (int y = 0; y < fb.height(); ++y) {
      for (int x = 0; x < fb.width(); ++x) *visible += fb.depth_at(x, y) < 1.0f;
    }
  }
  return shaded.load();
}

TEST(Deferred, VisiblePixelsAreShadedOnceAndOnlyWhereAllowed) {
  Scene scene = layered_scene(16, true, 9);  // back to front: every layer passes everywhere
  for (int threads : {1, 2}) {
    RenderState state = opaque_state(DepthFunc::kLess);
    state.threads = threads;
    int visible = 0;
    long deferred = count_shaded<ColorShader>(scene, state, &visible);
    EXPECT_GT(visible, 0);
    EXPECT_EQ(deferred, visible) << "threads " << threads;

    // Each of these must shade every passing fragment: far more than the visible pixels.
    long writes_depth = count_shaded<DepthWritingShader>(scene, state);
    EXPECT_GT(writes_depth, 8 * long(visible)) << "threads " << threads;
    for (BlendMode blend : {BlendMode::kAlpha, BlendMode::kAdditive}) {
      RenderState blended = state;
      blended.blend = blend;
      EXPECT_GT(count_shaded<ColorShader>(scene, blended), 8 * long(visible));
    }
    RenderState no_write = state;
    no_write.depth_write = false;
    EXPECT_GT(count_shaded<ColorShader>(scene, no_write), 8 * long(visible));
    RenderState greater = state;
    greater.depth_func = DepthFunc::kGreater;
    greater.depth_write = true;
    EXPECT_EQ(count_shaded<ColorShader>(scene, greater), 0);  // nothing beats the clear depth 1
  }
}

// Two layers of large triangles (two quads filling the image, drawn back to front) overlap enough
// to be deferred by worth_deferring: each visible pixel shaded once. Were the pixels each
// triangle covers in a tile (Chunk::cover_area) estimated at half their number, each tile would
// seem one layer deep and be shaded immediately, every fragment of both layers.
TEST(Deferred, TwoLayersOfLargeTrianglesAreShadedOnce) {
  Scene scene;
  for (float z : {0.5f, -0.5f}) {
    glm::vec4 a(-1, -1, z, 1), b(1, -1, z, 1), c(1, 1, z, 1), d(-1, 1, z, 1);
    scene.triangle(a, b, c, glm::vec4(0.5f + z, 0.2f, 0.3f, 1.0f));
    scene.triangle(a, c, d, glm::vec4(0.5f + z, 0.2f, 0.3f, 1.0f));
  }
  for (int threads : {1, 2}) {
    RenderState state = opaque_state(DepthFunc::kLess);
    state.threads = threads;
    int visible = 0;
    long shaded = count_shaded<ColorShader>(scene, state, &visible);
    EXPECT_EQ(visible, 256 * 192);
    EXPECT_EQ(shaded, visible) << "threads " << threads;
  }
}

// The rule itself, on the loads that decide it (a 64x64 tile of 4096 pixels).
TEST(Deferred, TileRuleDefersOverlapAndSmallTrianglesOnly) {
  using detail::worth_deferring;
  auto load = [](double boxes, double cover, int64_t records) {
    detail::TileLoad t;
    t.pixels = 4096;
    t.boxes = int64_t(boxes * 4096);
    t.cover = cover * 4096;
    t.records = records;
    return t;
  };
  // One layer of a mesh: boxes about twice the area.
  EXPECT_FALSE(worth_deferring(load(2.2, 1.0, 300)));
  // One layer of slivers (boxes past three tiles): small triangles, deferred.
  EXPECT_TRUE(worth_deferring(load(3.5, 1.0, 200)));
  // A few long triangles crossing the tile, each pixel once (quad_grid): immediate.
  EXPECT_FALSE(worth_deferring(load(4.0, 1.0, 6)));
  EXPECT_FALSE(worth_deferring(load(4.0, 1.5, 6)));
  // The same overlapping a little more, or in two layers: deferred.
  EXPECT_TRUE(worth_deferring(load(4.0, 1.6, 6)));
  EXPECT_TRUE(worth_deferring(load(4.0, 2.0, 4)));
  // Heavy overdraw of large quads: deferred.
  EXPECT_TRUE(worth_deferring(load(128.0, 64.0, 128)));
  // The triangle size where small starts: 128 pixels of the tile each.
  EXPECT_FALSE(worth_deferring(load(4.0, 1.0, 32)));
  EXPECT_TRUE(worth_deferring(load(4.0, 1.0, 33)));
  // The cover is estimated only where it can change the answer (cover_matters): with few
  // records past three tiles of boxes.
  EXPECT_TRUE(detail::cover_matters(load(4.0, 0.0, 6)));
  EXPECT_TRUE(detail::cover_matters(load(4.0, 0.0, 48)));
  EXPECT_FALSE(detail::cover_matters(load(4.0, 0.0, 49)));
  EXPECT_FALSE(detail::cover_matters(load(2.0, 0.0, 6)));
  for (double boxes : {2.0, 3.5, 8.0}) {
    for (int64_t records : {1, 6, 32, 48, 49, 200}) {
      if (detail::cover_matters(load(boxes, 0.0, records))) continue;
      const bool answer = worth_deferring(load(boxes, 0.0, records));
      for (double cover : {0.25, 1.0, 1.5, 1.6, 3.0, 64.0}) {
        EXPECT_EQ(worth_deferring(load(boxes, cover, records)), answer)
            << boxes << " " << cover << " " << records;
      }
    }
  }
}

// ---- Wide shaders: derivatives, depth and facing through both paths. ----

// A wide shader whose colour depends on everything a lane takes from its own primitive: the
// varyings, their derivatives across the quad (so a helper pixel that took another primitive's
// values would show), the depth, the facing and the position. ColorShader's vertex stage; the
// wide fragment stage is the one draw() picks.
struct WideProbeShader : ColorShader {
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    F r = f.varying(0) + f.ddx(f.varying(1)) * F(16.0f) + f.x * F(1.0f / 4096.0f);
    F g = f.varying(1) + f.ddy(f.varying(2)) * F(16.0f) + f.y * F(1.0f / 4096.0f);
    F b = f.varying(2) * F(0.5f) + f.depth * F(0.5f);
    F a = f.varying(3) * F(f.front_facing ? 1.0f : 0.5f);
    f.color = {r, g, b, a};
  }
};

// A layer of small triangles on a grid (cells of about 7 x 7 pixels at 301 x 187), at varying
// depth and w, every other cell wound the other way (both facings); optionally under a few large
// triangles that cross it.
Scene small_triangle_scene(bool with_large, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Scene scene;
  constexpr int kColumns = 40, kRows = 26;
  auto corner = [&](int i, int j) {
    float w = 0.8f + 0.4f * float(i + j) / float(kColumns + kRows);
    float x = -1.0f + 2.0f * float(i) / kColumns, y = -1.0f + 2.0f * float(j) / kRows;
    float z = -0.2f + 0.3f * std::sin(float(i) * 0.7f) * std::cos(float(j) * 0.4f);
    return glm::vec4(x * w, y * w, z * w, w);
  };
  for (int j = 0; j < kRows; ++j) {
    for (int i = 0; i < kColumns; ++i) {
      glm::vec4 color(unit(rng), unit(rng), unit(rng), 1.0f);
      glm::vec4 a = corner(i, j), b = corner(i + 1, j), c = corner(i + 1, j + 1),
                d = corner(i, j + 1);
      if ((i + j) % 2) {
        scene.triangle(a, b, c, color);
        scene.triangle(a, c, d, color * 0.7f);
      } else {
        scene.triangle(a, c, b, color);
        scene.triangle(a, d, c, color * 0.7f);
      }
    }
  }
  if (with_large) {
    Scene large = overdraw_scene(6, seed + 1, false);
    for (size_t i = 0; i < large.positions.size(); i += 3) {
      scene.triangle(large.positions[i], large.positions[i + 1], large.positions[i + 2],
                     large.colors[i]);
    }
  }
  return scene;
}

// The same without derivatives, declared so: deferred tiles then shade the pixels that several
// triangles won in a 4x4 block in one call, each with its own triangle's values.
struct MixedProbeShader : ColorShader {
  bool reads_derivatives() const { return false; }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    F r = f.varying(0) + f.x * F(1.0f / 4096.0f);
    F g = f.varying(1) + f.y * F(1.0f / 4096.0f);
    F b = f.varying(2) * F(0.5f) + f.depth * F(0.5f);
    F a = f.varying(3) * F(f.front_facing ? 1.0f : 0.5f);
    f.color = {r, g, b, a};
  }
};

// Declares no derivatives and reads them all the same.
struct LyingProbeShader : ColorShader {
  bool reads_derivatives() const { return false; }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    f.color = {f.ddx(f.varying(0)), f.varying(1), f.varying(2), f.varying(3)};
  }
};

template <class Shader = WideProbeShader>
Buffers render_wide(const Scene& scene, RenderState state, int threads, bool reference) {
  Framebuffer fb(301, 187);
  state.threads = threads;
  state.reference_path = reference;
  Shader shader;
  shader.positions = scene.positions.data();
  shader.colors = scene.colors.data();
  draw(fb, state, shader, scene.indices, uint32_t(scene.positions.size()));
  return read_back(fb);
}

// `scene` drawn with Shader on the binned path, at every SIMD level the machine has and on 1 and
// 2 threads, equals the reference path's image bit for bit.
template <class Shader>
void expect_wide_as_reference(const Scene& scene, const RenderState& state, const char* label) {
  Buffers reference = render_wide<Shader>(scene, state, 1, true);
  SimdLevel cap = simd_level();
  for (int level = 0; level <= int(cap); ++level) {
    set_simd_level(SimdLevel(level));
    for (int threads : {1, 2}) {
      EXPECT_TRUE(render_wide<Shader>(scene, state, threads, false) == reference)
          << label << ", threads " << threads << ", " << simd_level_name(SimdLevel(level));
    }
  }
  set_simd_level(cap);
}

// Small triangles of both facings, alone (immediate tiles) and under large ones (deferred tiles),
// against the reference path, bit for bit, at every level and on 1 and 2 threads.
TEST(Deferred, WideShaderWithDerivativesEqualsReference) {
  for (bool with_large : {false, true}) {
    Scene scene = small_triangle_scene(with_large, 7);
    for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
      expect_wide_as_reference<WideProbeShader>(scene, opaque_state(func),
                                                with_large ? "with large triangles" : "one layer");
    }
  }
}

// Small triangles of both facings under large ones (deferred tiles, blocks that several small
// triangles won) with a shader that reads no derivatives: bit for bit the reference path's image,
// at every level and on 1 and 2 threads.
TEST(Deferred, WideShaderWithoutDerivativesShadesMixedBlocksAsReference) {
  for (bool with_large : {false, true}) {
    Scene scene = small_triangle_scene(with_large, 9);
    for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
      expect_wide_as_reference<MixedProbeShader>(scene, opaque_state(func),
                                                 with_large ? "with large triangles" : "one layer");
    }
  }
}

// Small triangles (2 to 8 pixels across, a few larger) scattered sparsely enough that every tile
// is shaded immediately, overlapping one another often, of both facings; a third at one shared
// depth (exact ties: LEQUAL lets the later one win). In submission order the held blocks of
// BlockBatch must still show every pixel its fragments in order.
Scene scattered_small_triangles(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Scene scene;
  for (int t = 0; t < count; ++t) {
    glm::vec4 color(unit(rng), unit(rng), unit(rng), 1.0f);
    float cx = -1.0f + 2.0f * unit(rng), cy = -1.0f + 2.0f * unit(rng);
    if (t % 3 == 0) cx = -1.0f + 0.5f * (cx + 1.0f) * 0.3f;  // ties crowd the left 30 %
    // In NDC: 2 to 8 pixels at 301 x 187; every tenth 10 to 20 (shaded at once, not held).
    float size = (t % 10 == 5 ? 10.0f + 10.0f * unit(rng) : 2.0f + 6.0f * unit(rng)) / 187.0f;
    float shared = t % 3 == 0 ? 0.25f : -0.9f + 1.8f * unit(rng);
    glm::vec4 v[3];
    for (glm::vec4& p : v) {
      // w = 1 at the shared depth: every pixel of those triangles gets exactly that depth.
      float w = t % 3 == 0 ? 1.0f : 0.8f + 0.4f * unit(rng);
      float z = t % 3 == 0 ? shared : shared + 0.1f * unit(rng);
      p = glm::vec4((cx + size * (unit(rng) - 0.5f)) * w, (cy + size * (unit(rng) - 0.5f)) * w,
                    z * w, w);
    }
    scene.triangle(v[0], v[1], v[2], color);  // random winding: both facings
  }
  return scene;
}

TEST(Deferred, BatchedSmallTrianglesInImmediateTilesEqualReference) {
  Scene scene = scattered_small_triangles(3000, 5);
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    expect_wide_as_reference<MixedProbeShader>(scene, opaque_state(func), "scattered");
  }
}

// A mesh of medium triangles (quads about 13 x 11 pixels at 301 x 187, cut in two) of random
// facing at one depth, with larger triangles (15 to 40 pixels) drawn among them, half at that
// depth exactly (ties), half nearer or farther: one layer, so most tiles are shaded immediately,
// where the edge blocks of every triangle are held (BlockBatch) and completed by the next ones.
Scene mesh_with_overlaps(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  auto color = [&] { return glm::vec4(unit(rng), unit(rng), unit(rng), 1.0f); };
  auto at = [](float x, float y, float z) { return glm::vec4(x, y, z, 1.0f); };
  Scene scene;
  constexpr int kColumns = 23, kRows = 17;
  const float shared = 0.25f;
  for (int j = 0; j < kRows; ++j) {
    for (int i = 0; i < kColumns; ++i) {
      float x0 = -1.0f + 2.0f * i / kColumns, x1 = -1.0f + 2.0f * (i + 1) / kColumns;
      float y0 = -1.0f + 2.0f * j / kRows, y1 = -1.0f + 2.0f * (j + 1) / kRows;
      glm::vec4 a = at(x0, y0, shared), b = at(x1, y0, shared), c = at(x1, y1, shared),
                d = at(x0, y1, shared);
      if (unit(rng) < 0.5f) std::swap(b, d);  // the other winding: the other facing
      scene.triangle(a, b, c, color());
      if (unit(rng) < 0.5f) std::swap(a, c);
      scene.triangle(a, c, d, color());
      if ((j * kColumns + i) % 9 == 4) {  // a larger triangle among the mesh's
        float cx = -1.0f + 2.0f * unit(rng), cy = -1.0f + 2.0f * unit(rng);
        float size = (15.0f + 25.0f * unit(rng)) / 187.0f;
        float z = unit(rng) < 0.5f ? shared : shared + 0.2f * (unit(rng) - 0.5f);
        glm::vec4 v[3];
        for (glm::vec4& p : v)
          p = at(cx + size * (unit(rng) - 0.5f), cy + size * (unit(rng) - 0.5f), z);
        scene.triangle(v[0], v[1], v[2], color());
      }
    }
  }
  return scene;
}

TEST(Deferred, HeldEdgeBlocksOfAMeshInImmediateTilesEqualReference) {
  Scene scene = mesh_with_overlaps(11);
  for (DepthFunc func : {DepthFunc::kLess, DepthFunc::kLessEqual}) {
    expect_wide_as_reference<MixedProbeShader>(scene, opaque_state(func), "mesh");
  }
}

// A shader that says it reads no derivatives and calls ddx stops with a message instead of
// shading with differences across triangles.
TEST(DeferredDeathTest, DerivativesInAMixedBlockStopWithAMessage) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  Scene scene = small_triangle_scene(true, 9);
  RenderState state = opaque_state(DepthFunc::kLess);
  EXPECT_DEATH(render_wide<LyingProbeShader>(scene, state, 1, false),
               "read derivatives .* reads_derivatives\\(\\) returned false");
}

}  // namespace
}  // namespace softrast
