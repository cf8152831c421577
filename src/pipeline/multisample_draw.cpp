// pipeline/multisample_draw.cpp: multisampled triangles. Setup per triangle on the calling
// thread, binning into 64x64 tiles, then per tile (in parallel): coverage per sample
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

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

#include "raster/raster.hpp"
#include "raster/sample_coverage.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/detail/shade_block.hpp"
#include "softrast/framebuffer.hpp"

namespace softrast::detail {
namespace {

// Set-up triangles with their interpolants cut short after the last varying
// (interpolants_bytes), in submission order. Each record starts at a multiple of
// alignof(Interpolants) (its depth plane is doubles), which UBSan checks.
class TriangleList {
  static constexpr size_t kRecordAlign = alignof(Interpolants);
  static_assert(kRecordAlign % sizeof(float) == 0 && kRecordAlign <= alignof(std::max_align_t));

 public:
  explicit TriangleList(int num_varyings)
      : record_floats_((interpolants_bytes(num_varyings) + kRecordAlign - 1) / kRecordAlign *
                       kRecordAlign / sizeof(float)) {}
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
  size_t record_floats_;
  std::vector<SampleTriangle> coverage_;
  std::vector<float> interp_;
};

// Fills the samples from the pixels when they do not hold this sample count's state.
void prepare_samples(Framebuffer& fb, int count, int threads) {
  Framebuffer::Multisample& ms = fb.multisample();
  size_t pixels = size_t(fb.width()) * size_t(fb.height());
  if (ms.valid && ms.count == count && ms.color.size() == pixels * size_t(count)) return;
  ms.count = count;
  ms.color.resize(pixels * size_t(count));
  ms.depth.resize(pixels * size_t(count));
  parallel_for(size_t(fb.height()), threads, [&](size_t row) {
    int y = int(row);
    size_t base = size_t(y) * size_t(fb.width()) * size_t(count);
    for (int x = 0; x < fb.width(); ++x) {
      std::fill_n(&ms.color[base + size_t(x) * size_t(count)], count, fb.color_at(x, y));
      std::fill_n(&ms.depth[base + size_t(x) * size_t(count)], count, fb.depth_at(x, y));
    }
  });
  ms.valid = true;
}

// Each pixel of `rect` becomes the average of its samples (per channel, rounded to nearest) and
// the nearest of their depths.
void resolve(Framebuffer& fb, const PixelRect& rect) {
  const Framebuffer::Multisample& ms = fb.multisample();
  const size_t n = size_t(ms.count);
  const uint32_t half = uint32_t(n / 2);
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      size_t at = (size_t(y) * size_t(fb.width()) + size_t(x)) * n;
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
  }

  void triangle(const SampleTriangle& tri, const Interpolants& interp, const PixelRect& tile) {
    PixelRect area = intersect(tri.bounds, tile);
    if (area.empty()) return;
    for (int y = area.y0 & ~3; y < area.y1; y += kBlockSize) {
      for (int x = area.x0 & ~3; x < area.x1; x += kBlockSize) {
        uint8_t cov[16];
        uint32_t pixels = block_sample_coverage(tri, pattern_, area, x, y, cov);
        if (pixels) block(interp, x, y, pixels, cov);
      }
    }
  }

 private:
  // The samples of the 4x4 block at (x, y) that `cov` marks.
  void block(const Interpolants& in, int x, int y, uint32_t pixels, const uint8_t cov[16]) {
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
    for (uint32_t m = shade; m; m &= m - 1) {
      int i = __builtin_ctz(m);
      *fb_.depth_pixel(x + (i & 3), y + (i >> 2)) = -1.0f;
    }
    program_.shade_block(program_.shader, scratch_target_, in, x, y, shade);
    for (uint32_t m = shade; m; m &= m - 1) {
      int i = __builtin_ctz(m), px = x + (i & 3), py = y + (i >> 2);
      float shader_depth = *fb_.depth_pixel(px, py);
      if (!(shader_depth >= 0.0f)) continue;  // discarded
      write_samples(px, py, pass[i], z[i], shader_depth, *fb_.color_pixel(px, py), ms);
    }
  }

  void write_samples(int px, int py, uint8_t samples, const float* z, float shader_depth,
                     uint32_t color, Framebuffer::Multisample& ms) const {
    size_t at = sample_index(px, py);
    const bool opaque = state_.blend == BlendMode::kOpaque;
    glm::vec4 src = opaque ? glm::vec4(0.0f) : unpack_rgba8(color);
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

  size_t sample_index(int px, int py) const {
    return (size_t(py) * size_t(fb_.width()) + size_t(px)) * size_t(pattern_.count);
  }

  Framebuffer& fb_;
  const RenderState& state_;
  const FragmentProgram& program_;
  const SamplePattern& pattern_;
  RenderState scratch_state_;
  ShadeTarget scratch_target_;
  float offset_x_[kMaxSamples] = {}, offset_y_[kMaxSamples] = {};
};

}  // namespace

void draw_triangles_multisample(Framebuffer& fb, const GeometryStage& geometry,
                                const RenderState& state, const FragmentProgram& program,
                                const uint32_t* indices, size_t index_count, int threads) {
  const SamplePattern& pattern = *standard_sample_pattern(state.samples);
  prepare_samples(fb, pattern.count, threads);

  // Setup in submission order.
  TriangleList list(geometry.num_varyings());
  auto on_triangle = [&](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
    int64_t area = signed_area_fx16(a, b, c);
    if (area == 0 || is_culled(area, state.cull, state.front_face)) return;
    SampleTriangle tri;
    const WindowVertex* ordered[3];
    if (!setup_sample_triangle(a, b, c, area, geometry.scissor(), tri, ordered)) return;
    Interpolants interp;
    setup_triangle_interpolants(ordered, geometry.num_varyings(), area, state.front_face, interp);
    list.add(tri, interp);
  };
  for (size_t k = 0; k + 2 < index_count; k += 3) {
    if (geometry.valid(indices[k]) && geometry.valid(indices[k + 1]) &&
        geometry.valid(indices[k + 2])) {
      geometry.triangle(indices[k], indices[k + 1], indices[k + 2], on_triangle);
    }
  }

  // Binning: each tile lists the triangles whose bounds touch it, in order.
  const int tiles_x = (fb.width() + kTileSize - 1) / kTileSize;
  const int tiles_y = (fb.height() + kTileSize - 1) / kTileSize;
  std::vector<std::vector<uint32_t>> bins(size_t(tiles_x) * size_t(tiles_y));
  for (size_t t = 0; t < list.size(); ++t) {
    const PixelRect& b = list.coverage(t).bounds;
    for (int ty = b.y0 / kTileSize; ty <= (b.y1 - 1) / kTileSize; ++ty) {
      for (int tx = b.x0 / kTileSize; tx <= (b.x1 - 1) / kTileSize; ++tx) {
        bins[size_t(ty) * size_t(tiles_x) + size_t(tx)].push_back(uint32_t(t));
      }
    }
  }
  std::vector<uint32_t> busy;
  for (size_t i = 0; i < bins.size(); ++i) {
    if (!bins[i].empty()) busy.push_back(uint32_t(i));
  }

  parallel_for(busy.size(), threads, [&](size_t job) {
    uint32_t t = busy[job];
    int tx = int(t % uint32_t(tiles_x)), ty = int(t / uint32_t(tiles_x));
    PixelRect tile{tx * kTileSize, ty * kTileSize, std::min(fb.width(), (tx + 1) * kTileSize),
                   std::min(fb.height(), (ty + 1) * kTileSize)};
    fb.prepare_tile(tx, ty);  // a pending clear, before the tile's pixels are used as scratch
    TileShader shader(fb, state, program, pattern);
    for (uint32_t i : bins[t]) shader.triangle(list.coverage(i), list.interp(i), tile);
    resolve(fb, tile);
  });
}

}  // namespace softrast::detail
