// pipeline/multisample_draw.cpp: multisampled triangles. Setup and binning into 64x64 tiles in
// chunks of consecutive triangles (in parallel), then per tile (in parallel): coverage per sample
// (raster/sample_coverage.hpp), the depth test per sample, one run of the fragment program per
// pixel with a covered sample that passed, its colour blended into those samples, and at the end
// the tile's pixels resolved from its samples.
//
// The fragment program writes into the framebuffer's own pixels as a scratch area: it runs with
// the depth test "always" and depth writes on, over pixels whose depth was set to -1 first, so
// afterwards a pixel's depth says whether the shader discarded it (still -1) or which depth it
// wrote (the pixel centre's depth, or the shader's own), and its colour is the shaded colour. The
// pixels are rewritten from the samples when the tile is resolved, so nothing of this shows.
// The shaded colour reaches the samples as RGBA8: exact for opaque and additive blending; alpha
// blending sees the source rounded to 1/255 first.
#include "pipeline/multisample_draw.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

#include "pipeline/draw_internal.hpp"
#include "raster/raster.hpp"
#include "raster/sample_coverage.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/detail/shade_block.hpp"
#include "softrast/detail/shade_simd.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::detail {
namespace {

// Set-up triangles with their interpolants cut short after the last varying
// (interpolants_bytes), in submission order. Each record starts at a multiple of
// alignof(Interpolants) (its depth plane is doubles), which UBSan checks.
class TriangleList {
  static constexpr size_t kRecordAlign = alignof(Interpolants);
  static_assert(kRecordAlign % sizeof(float) == 0 && kRecordAlign <= alignof(std::max_align_t));

 public:
  // Empties the list for a draw with `num_varyings`, keeping its storage.
  void reset(int num_varyings) {
    record_floats_ = (interpolants_bytes(num_varyings) + kRecordAlign - 1) / kRecordAlign *
                     kRecordAlign / sizeof(float);
    coverage_.clear();
    interp_.clear();
  }
  void add(const SampleTriangle& tri, const Interpolants& interp) {
    coverage_.push_back(tri);
    size_t at = interp_.size();
    interp_.resize(at + record_floats_);
    std::memcpy(&interp_[at], &interp, interpolants_bytes(interp.num_varyings));
  }
  size_t size() const { return coverage_.size(); }
  const SampleTriangle& coverage(size_t i) const { return coverage_[i]; }
  const Interpolants& interp(size_t i) const {
    return *reinterpret_cast<const Interpolants*>(&interp_[i * record_floats_]);
  }

 private:
  size_t record_floats_ = 0;
  std::vector<SampleTriangle> coverage_;
  std::vector<float> interp_;
};

// One chunk of consecutive triangles: their records and, per tile, the ones touching it.
struct MultisampleChunk {
  TriangleList list;
  std::vector<std::vector<uint32_t>> bins;
};

struct MultisampleCache {
  std::vector<MultisampleChunk> chunks;  // the most any draw used (alternating thread counts)
  std::vector<uint32_t> busy;            // the tiles with triangles
  WindowVertices vertices;               // as the binned draw keeps them
};

// Where the samples of pixel (px, py) start: tile by tile (each tile's 64x64 pixels row by row),
// so that a tile's samples are one contiguous block that stays in the cache while it is drawn.
size_t sample_offset(const Framebuffer& fb, int px, int py, int count) {
  size_t tiles_x = size_t(fb.width() + kTileSize - 1) / kTileSize;
  size_t tile = size_t(py / kTileSize) * tiles_x + size_t(px / kTileSize);
  size_t within = size_t(py % kTileSize) * kTileSize + size_t(px % kTileSize);
  return (tile * size_t(kTileSize) * kTileSize + within) * size_t(count);
}

// Makes the samples this sample count's: when they do not hold its state, every tile's samples
// are marked to be filled from the pixels when a draw first touches the tile (fill_samples).
void prepare_samples(Framebuffer& fb, int count) {
  Framebuffer::Multisample& ms = fb.multisample();
  size_t tiles = size_t((fb.width() + kTileSize - 1) / kTileSize) *
                 size_t((fb.height() + kTileSize - 1) / kTileSize);
  size_t samples = tiles * size_t(kTileSize) * kTileSize * size_t(count);
  if (ms.valid && ms.count == count && ms.color.size() == samples) return;
  ms.count = count;
  ms.color.resize(samples);
  ms.depth.resize(samples);
  ms.stale.assign(tiles, 1);
  ms.valid = true;
}

// Fills the samples of tile (tx, ty), whose pixels are `rect`, from its pixels: all with the
// pending clear when it has one (the usual first draw of a frame: one fill of the tile's
// samples), else pixel by pixel. Before prepare_tile.
void fill_samples(Framebuffer& fb, int tx, int ty, const PixelRect& rect) {
  Framebuffer::Multisample& ms = fb.multisample();
  const int n = ms.count;
  if (fb.tile_pending(tx, ty)) {
    size_t first = sample_offset(fb, rect.x0, rect.y0, n),
           count = size_t(kTileSize) * kTileSize * n;
    std::fill_n(&ms.color[first], count, fb.color_at(rect.x0, rect.y0));
    std::fill_n(&ms.depth[first], count, fb.depth_at(rect.x0, rect.y0));
    return;
  }
  for (int y = rect.y0; y < rect.y1; ++y) {
    size_t at = sample_offset(fb, rect.x0, y, n);  // a row's pixels are consecutive
    for (int x = rect.x0; x < rect.x1; ++x, at += size_t(n)) {
      std::fill_n(&ms.color[at], n, *fb.color_pixel(x, y));
      std::fill_n(&ms.depth[at], n, *fb.depth_pixel(x, y));
    }
  }
}

// Each pixel of `rect` becomes the average of its samples (per channel, rounded to nearest) and
// the nearest of their depths.
void resolve(Framebuffer& fb, const PixelRect& rect) {
  const Framebuffer::Multisample& ms = fb.multisample();
  const size_t n = size_t(ms.count);
  const uint32_t half = uint32_t(n / 2);
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      size_t at = sample_offset(fb, x, y, int(n));
      uint32_t sum[4] = {0, 0, 0, 0};
      float depth = ms.depth[at];
      for (size_t s = 0; s < n; ++s) {
        uint32_t c = ms.color[at + s];
        for (int k = 0; k < 4; ++k) sum[k] += (c >> (8 * k)) & 0xffu;
        depth = std::min(depth, ms.depth[at + s]);
      }
      uint32_t packed = 0;
      for (int k = 0; k < 4; ++k) packed |= ((sum[k] + half) / uint32_t(n)) << (8 * k);
      *fb.color_pixel(x, y) = packed;
      *fb.depth_pixel(x, y) = depth;
    }
  }
}

// Vectors passed between the AVX-512 helpers below stay inside this file. GCC 12's headers leave
// the source of unmasked AVX-512 conversions and casts "uninitialised" (_mm512_undefined_*, GCC
// bug 105593, fixed in GCC 13), which it then reports at every use.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define SOFTRAST_AVX512_FN [[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]]

// resolve() for 4 samples per pixel with AVX-512, the same results: four pixels at a time (their
// 16 samples are one 64-byte vector of colours and one of depths). Each pixel's samples are one
// 128-bit lane: its bytes regrouped by channel, summed in pairs and then in fours, rounded, and
// narrowed back to bytes; its depth the smallest of the four, taken in the scalar order.
SOFTRAST_AVX512_FN void resolve4(Framebuffer& fb, const PixelRect& rect) {
  const Framebuffer::Multisample& ms = fb.multisample();
  const __m512i by_channel =
      _mm512_broadcast_i32x4(_mm_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15));
  const __m512i ones8 = _mm512_set1_epi8(1), ones16 = _mm512_set1_epi16(1);
  const __m512i half = _mm512_set1_epi32(2);
  __m512i sample_of[4];
  for (int s = 0; s < 4; ++s) {
    sample_of[s] = _mm512_setr_epi32(s, 4 + s, 8 + s, 12 + s, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
  }
  for (int y = rect.y0; y < rect.y1; ++y) {
    int x = rect.x0;
    for (; x + kBlockSize <= rect.x1 && (x & (kBlockSize - 1)) == 0; x += kBlockSize) {
      size_t at = sample_offset(fb, x, y, 4);
      __m512i c = _mm512_shuffle_epi8(_mm512_loadu_si512(&ms.color[at]), by_channel);
      __m512i sums = _mm512_madd_epi16(_mm512_maddubs_epi16(c, ones8), ones16);
      __m512i mean = _mm512_srli_epi32(_mm512_add_epi32(sums, half), 2);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(fb.color_pixel(x, y)),
                       _mm512_cvtepi32_epi8(mean));
      __m512 d = _mm512_loadu_ps(&ms.depth[at]);
      __m128 depth = _mm512_castps512_ps128(_mm512_permutexvar_ps(sample_of[0], d));
      for (int s = 1; s < 4; ++s) {  // depth = std::min(depth, sample s): (s < depth) ? s : depth
        __m128 v = _mm512_castps512_ps128(_mm512_permutexvar_ps(sample_of[s], d));
        depth = _mm_blendv_ps(depth, v, _mm_cmplt_ps(v, depth));
      }
      _mm_storeu_ps(fb.depth_pixel(x, y), depth);
    }
    if (x < rect.x1) resolve(fb, {x, y, rect.x1, y + 1});
  }
}

class TileShader {
 public:
  TileShader(Framebuffer& fb, const RenderState& state, const FragmentProgram& program,
             const SamplePattern& pattern)
      : fb_(fb), state_(state), program_(program), pattern_(pattern) {
    scratch_state_ = state;
    scratch_state_.depth_test = true;
    scratch_state_.depth_func = DepthFunc::kAlways;
    scratch_state_.depth_write = true;
    scratch_state_.blend = BlendMode::kOpaque;
    scratch_target_ = ShadeTarget{&fb, &scratch_state_, false};
    for (int s = 0; s < pattern.count; ++s) {
      offset_x_[s] = float(pattern.x[s]) / float(kSubpixelOne);  // exact: multiples of 1/16
      offset_y_[s] = float(pattern.y[s]) / float(kSubpixelOne);
    }
    fast4_ = fast_path_applies(state, program, pattern);
    coverage_ = block_sample_coverage_kernel(simd_level());
  }
  static bool fast_path_applies(const RenderState& state, const FragmentProgram& program,
                                const SamplePattern& pattern) {
    return pattern.count == 4 && state.blend == BlendMode::kOpaque && !program.writes_depth &&
           simd_level() >= SimdLevel::kAvx512;
  }

  void triangle(const SampleTriangle& tri, const Interpolants& interp, const PixelRect& tile) {
    PixelRect area = intersect(tri.bounds, tile);
    if (area.empty()) return;
    for (int y = area.y0 & ~3; y < area.y1; y += kBlockSize) {
      for (int x = area.x0 & ~3; x < area.x1; x += kBlockSize) {
        uint8_t cov[16];
        uint32_t pixels = coverage_(tri, pattern_, area, x, y, cov);
        if (pixels) block(interp, x, y, pixels, cov);
      }
    }
  }

 private:
  // The samples of the 4x4 block at (x, y) that `cov` marks.
  void block(const Interpolants& in, int x, int y, uint32_t pixels, const uint8_t cov[16]) {
    if (fast4_) return block4(in, x, y, pixels, cov);
    const int n = pattern_.count;
    const bool depth_test = state_.depth_test;
    Framebuffer::Multisample& ms = fb_.multisample();
    float z[16][kMaxSamples];
    uint8_t pass[16];
    uint32_t shade = 0;
    for (uint32_t m = pixels; m; m &= m - 1) {
      int i = __builtin_ctz(m), px = x + (i & 3), py = y + (i >> 2);
      const float* stored = &ms.depth[sample_index(px, py)];
      pass[i] = 0;
      for (int s = 0; s < n; ++s) {
        if (!(cov[i] >> s & 1)) continue;
        float dx = float(px) + offset_x_[s] - in.x_ref, dy = float(py) + offset_y_[s] - in.y_ref;
        z[i][s] = std::clamp(eval_plane(in.z, dx, dy), 0.0f, 1.0f);
        // A shader that writes depth is tested after it ran (late depth test).
        if (program_.writes_depth || !depth_test ||
            depth_passes(state_.depth_func, z[i][s], stored[s])) {
          pass[i] |= uint8_t(1u << s);
        }
      }
      if (pass[i]) shade |= 1u << i;
    }
    if (!shade) return;
    shade_into_pixels(in, x, y, shade);
    for (uint32_t m = shade; m; m &= m - 1) {
      int i = __builtin_ctz(m), px = x + (i & 3), py = y + (i >> 2);
      float shader_depth = *fb_.depth_pixel(px, py);
      if (!(shader_depth >= 0.0f)) continue;  // discarded
      write_samples(px, py, pass[i], z[i], shader_depth, *fb_.color_pixel(px, py), ms);
    }
  }

  // block() for 4 samples per pixel, opaque, the shader not writing depth, with AVX-512: a row
  // of the block (4 pixels, 16 samples) is one vector. The same operations on each sample as
  // block() and write_samples(), so the same results.
  SOFTRAST_AVX512_FN void block4(const Interpolants& in, int x, int y, uint32_t pixels,
                                 const uint8_t cov[16]) {
    Framebuffer::Multisample& ms = fb_.multisample();
    const __m512i column = _mm512_srli_epi32(
        _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), 2);
    const __m512 off_x = _mm512_broadcast_f32x4(_mm_loadu_ps(offset_x_));
    const __m512 off_y = _mm512_broadcast_f32x4(_mm_loadu_ps(offset_y_));
    const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
    // dx = float(px) + offset_x - x_ref, dy likewise; the depth plane through the wide fragment
    // stage's eval_plane (in double, as block() computes it).
    simd::Float<16> dx, dy;
    dx.p[0] = simd::Native<16>::F(_mm512_sub_ps(
        _mm512_add_ps(_mm512_cvtepi32_ps(_mm512_add_epi32(_mm512_set1_epi32(x), column)), off_x),
        _mm512_set1_ps(in.x_ref)));
    const bool test = state_.depth_test;
    __m512 z[4];
    __mmask16 pass[4] = {0, 0, 0, 0};
    uint32_t shade = 0;
    for (int r = 0; r < 4; ++r) {
      uint32_t row = (pixels >> (4 * r)) & 0xfu;
      if (row == 0) continue;
      __mmask16 covered = 0;
      for (int p = 0; p < 4; ++p) {
        if (row >> p & 1) covered |= __mmask16((cov[4 * r + p] & 0xfu) << (4 * p));
      }
      dy.p[0] = simd::Native<16>::F(_mm512_sub_ps(
          _mm512_add_ps(_mm512_set1_ps(float(y + r)), off_y), _mm512_set1_ps(in.y_ref)));
      __m512 zr = __m512(eval_plane<16>(in.z, dx, dy).p[0]);
      // std::clamp(z, 0, 1): z < 0 ? 0 : (1 < z ? 1 : z).
      zr = _mm512_mask_mov_ps(zr, _mm512_cmp_ps_mask(zr, zero, _CMP_LT_OQ), zero);
      zr = _mm512_mask_mov_ps(zr, _mm512_cmp_ps_mask(one, zr, _CMP_LT_OQ), one);
      __mmask16 ok = covered;
      if (test) {  // the masked load reads only covered samples (never past the image)
        __m512 stored = _mm512_maskz_loadu_ps(covered, &ms.depth[sample_index(x, y + r)]);
        ok &= passes(state_.depth_func, zr, stored);
      }
      z[r] = zr;
      pass[r] = ok;
      for (int p = 0; p < 4; ++p) {
        if ((ok >> (4 * p)) & 0xfu) shade |= 1u << (4 * r + p);
      }
    }
    if (!shade) return;
    shade_into_pixels(in, x, y, shade);
    for (int r = 0; r < 4; ++r) {
      __mmask16 write = pass[r];
      for (int p = 0; p < 4; ++p) {
        if (((write >> (4 * p)) & 0xfu) && !(*fb_.depth_pixel(x + p, y + r) >= 0.0f)) {
          write &= __mmask16(~(0xfu << (4 * p)));  // discarded
        }
      }
      if (!write) continue;
      size_t at = sample_index(x, y + r);
      if (test && state_.depth_write) _mm512_mask_storeu_ps(&ms.depth[at], write, z[r]);
      __m128i colours =
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(fb_.color_pixel(x, y + r)));
      _mm512_mask_storeu_epi32(&ms.color[at], write,
                               _mm512_permutexvar_epi32(column, _mm512_castsi128_si512(colours)));
    }
  }

  // The wide fragment stage's depth_passes (shade_simd.hpp) as a mask register.
  SOFTRAST_AVX512_FN static __mmask16 passes(DepthFunc f, __m512 z, __m512 stored) {
    simd::Float<16> a, b;
    a.p[0] = simd::Native<16>::F(z);
    b.p[0] = simd::Native<16>::F(stored);
    return _mm512_movepi32_mask(__m512i(depth_passes<16>(f, a, b).p[0]));
  }

  // Runs the fragment program over the pixels of `shade` with the pixels as scratch: their depth
  // set to -1 first, so that afterwards -1 says the shader discarded the pixel.
  void shade_into_pixels(const Interpolants& in, int x, int y, uint32_t shade) {
    for (uint32_t m = shade; m; m &= m - 1) {
      int i = __builtin_ctz(m);
      *fb_.depth_pixel(x + (i & 3), y + (i >> 2)) = -1.0f;
    }
    program_.shade_block(program_.shader, scratch_target_, in, x, y, shade);
  }

  void write_samples(int px, int py, uint8_t samples, const float* z, float shader_depth,
                     uint32_t color, Framebuffer::Multisample& ms) const {
    size_t at = sample_index(px, py);
    const bool opaque = state_.blend == BlendMode::kOpaque;
    glm::vec4 src = opaque ? glm::vec4(0.0f) : softrast::unpack_rgba8(color);
    for (int s = 0; s < pattern_.count; ++s) {
      if (!(samples >> s & 1)) continue;
      float depth = program_.writes_depth ? shader_depth : z[s];
      if (state_.depth_test) {
        if (program_.writes_depth && !depth_passes(state_.depth_func, depth, ms.depth[at + s])) {
          continue;
        }
        if (state_.depth_write) ms.depth[at + s] = depth;
      }
      uint32_t& dst = ms.color[at + s];
      dst = opaque ? color : blend_pixel(state_.blend, src, dst);
    }
  }

  size_t sample_index(int px, int py) const { return sample_offset(fb_, px, py, pattern_.count); }

  Framebuffer& fb_;
  const RenderState& state_;
  const FragmentProgram& program_;
  const SamplePattern& pattern_;
  RenderState scratch_state_;
  ShadeTarget scratch_target_;
  float offset_x_[kMaxSamples] = {}, offset_y_[kMaxSamples] = {};
  bool fast4_ = false;
  BlockSampleCoverageFn coverage_ = nullptr;
};

#undef SOFTRAST_AVX512_FN
#pragma GCC diagnostic pop

}  // namespace

void draw_triangles_multisample(Framebuffer& fb, const GeometryStage& geometry,
                                const RenderState& state, const FragmentProgram& program,
                                const uint32_t* indices, size_t index_count, int threads) {
  const SamplePattern& pattern = *standard_sample_pattern(state.samples);
  prepare_samples(fb, pattern.count);

  // The triangle records and bins of the calling thread's previous draws, reused: no allocation
  // per frame once a frame of the same size has been drawn (a million-triangle mesh's records
  // are 150 MB, which the kernel had to map and clear again every frame).
  thread_local MultisampleCache thread_cache;
  // A reference, so that the jobs on other threads reach this thread's cache (a thread_local
  // named inside a lambda would be the running thread's own).
  MultisampleCache& cache = thread_cache;
  const int tiles_x = (fb.width() + kTileSize - 1) / kTileSize;
  const int tiles_y = (fb.height() + kTileSize - 1) / kTileSize;
  const size_t tiles = size_t(tiles_x) * size_t(tiles_y);

  // Outcodes and window positions once per vertex, in parallel.
  cache.vertices.transform(geometry, threads);

  // Setup and binning in chunks of consecutive triangles, in parallel; a tile's triangles are its
  // bins' contents chunk after chunk, which is submission order.
  const size_t triangles = index_count / 3;
  const size_t chunks = threads <= 1 ? 1 : std::min<size_t>(size_t(threads) * 4, triangles + 1);
  if (cache.chunks.size() < chunks) cache.chunks.resize(chunks);
  const size_t per_chunk = (triangles + chunks - 1) / chunks;
  parallel_for(chunks, threads, [&](size_t c) {
    MultisampleChunk& chunk = cache.chunks[c];
    TriangleList& list = chunk.list;
    list.reset(geometry.num_varyings());
    chunk.bins.resize(tiles);
    for (std::vector<uint32_t>& bin : chunk.bins) bin.clear();
    auto on_triangle = [&](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c3) {
      int64_t area = signed_area_fx16(a, b, c3);
      if (area == 0 || is_culled(area, state.cull, state.front_face)) return;
      SampleTriangle tri;
      const WindowVertex* ordered[3];
      if (!setup_sample_triangle(a, b, c3, area, geometry.scissor(), tri, ordered)) return;
      Interpolants interp;
      setup_triangle_interpolants(ordered, geometry.num_varyings(), area, state.front_face, interp);
      const PixelRect& r = tri.bounds;
      uint32_t at = uint32_t(list.size());
      for (int ty = r.y0 / kTileSize; ty <= (r.y1 - 1) / kTileSize; ++ty) {
        for (int tx = r.x0 / kTileSize; tx <= (r.x1 - 1) / kTileSize; ++tx) {
          chunk.bins[size_t(ty) * size_t(tiles_x) + size_t(tx)].push_back(at);
        }
      }
      list.add(tri, interp);
    };
    size_t end = std::min(triangles, (c + 1) * per_chunk);
    for (size_t t = std::min(triangles, c * per_chunk); t < end; ++t) {
      cache.vertices.triangle(geometry, indices + 3 * t, on_triangle);
    }
  });
  std::vector<uint32_t>& busy = cache.busy;
  busy.clear();
  for (size_t t = 0; t < tiles; ++t) {
    for (size_t c = 0; c < chunks; ++c) {
      if (!cache.chunks[c].bins[t].empty()) {
        busy.push_back(uint32_t(t));
        break;
      }
    }
  }

  parallel_for(busy.size(), threads, [&](size_t job) {
    uint32_t t = busy[job];
    int tx = int(t % uint32_t(tiles_x)), ty = int(t / uint32_t(tiles_x));
    PixelRect tile{tx * kTileSize, ty * kTileSize, std::min(fb.width(), (tx + 1) * kTileSize),
                   std::min(fb.height(), (ty + 1) * kTileSize)};
    Framebuffer::Multisample& ms = fb.multisample();
    if (ms.stale[t]) {
      fill_samples(fb, tx, ty, tile);
      ms.stale[t] = 0;
    }
    fb.prepare_tile(tx, ty);  // a pending clear, before the tile's pixels are used as scratch
    TileShader shader(fb, state, program, pattern);
    for (size_t c = 0; c < chunks; ++c) {
      const MultisampleChunk& chunk = cache.chunks[c];
      for (uint32_t i : chunk.bins[t]) {
        shader.triangle(chunk.list.coverage(i), chunk.list.interp(i), tile);
      }
    }
    if (pattern.count == 4 && simd_level() >= SimdLevel::kAvx512) {
      resolve4(fb, tile);
    } else {
      resolve(fb, tile);
    }
  });
}

}  // namespace softrast::detail
