// tests/test_util.hpp: helpers shared by the rasterization, clipping and pipeline tests: shaders
// that place vertices at exact window coordinates, hit counting with additive blending, the
// top-left fill rule written out independently of raster/setup.cpp, the analytic coverage of a
// polygon lying in a world-space plane seen through a perspective camera, and collection of the
// internal rasterizers' output (tests have src/ on their include path).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "fill_rule_oracle.hpp"
#include "raster/raster.hpp"
#include "raster/setup.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"
#include "softrast/shader.hpp"

namespace softrast::test {

// Every SIMD level this CPU runs, from SSE2 up to cpu_simd_level().
inline std::vector<SimdLevel> levels_of_this_cpu() {
  std::vector<SimdLevel> levels;
  for (int i = 0; i <= int(cpu_simd_level()); ++i) levels.push_back(SimdLevel(i));
  return levels;
}

// Names the raster algorithm in parameterised test names (BothRasterizers/Foo/Scanline).
inline std::string algorithm_name(const testing::TestParamInfo<RasterAlgorithm>& info) {
  return info.param == RasterAlgorithm::kScanline ? "Scanline" : "EdgeEquations";
}

// ---------------------------------------------------------------------------------------------
// Window coordinates <-> clip space.

// The clip-space position (w = 1) that the viewport maps to window position (x, y) of a
// width x height image: x_clip = 2x/W - 1, y_clip = 1 - 2y/H. Exact (no rounding anywhere in
// the pipeline) when W and H are powers of two and x, y are multiples of 1/256 of moderate size.
inline glm::vec4 window_to_clip(double x, double y, int width, int height, float z = 0.0f) {
  return {float(2.0 * x / width - 1.0), float(1.0 - 2.0 * y / height), z, 1.0f};
}

// True when window_to_clip(x, y) reproduces x and y exactly after the viewport transform
// (a precondition the exact tests check, so that a failure cannot come from rounding).
inline bool window_to_clip_is_exact(double x, double y, int width, int height) {
  glm::vec4 c = window_to_clip(x, y, width, height);
  return (double(c.x) + 1.0) * 0.5 * width == x && (1.0 - double(c.y)) * 0.5 * height == y;
}

// ---------------------------------------------------------------------------------------------
// Shaders.

// Positions given in clip space; every fragment gets one constant colour.
struct ClipSpaceShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions = nullptr;
  glm::vec4 color{1.0f / 255.0f, 0.0f, 0.0f, 0.0f};

  glm::vec4 vertex(uint32_t index, float*) const { return positions[index]; }
  bool fragment(FragmentInput&, glm::vec4& out) const {
    out = color;
    return true;
  }
};

// ---------------------------------------------------------------------------------------------
// Hit counting: additive blending of 1/255 in red adds exactly one per fragment (up to 255).

inline RenderState counting_state(RasterAlgorithm raster = RasterAlgorithm::kEdgeEquations) {
  RenderState s;
  s.cull = CullMode::kNone;
  s.depth_test = false;
  s.blend = BlendMode::kAdditive;
  s.raster = raster;
  return s;
}

// Hits per pixel (row-major) as counted in the red channel of a framebuffer cleared to zero.
inline std::vector<int> red_counts(const Framebuffer& fb) {
  std::vector<int> counts(size_t(fb.width()) * fb.height());
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x)
      counts[size_t(y) * fb.width() + x] = fb.color_at(x, y) & 0xff;
  }
  return counts;
}

// Draws clip-space `positions` with `indices` under `state` into a fresh width x height
// framebuffer cleared to zero, and returns the hit count of every pixel.
inline std::vector<int> count_hits(int width, int height, const RenderState& state,
                                   std::span<const glm::vec4> positions,
                                   std::span<const uint32_t> indices) {
  Framebuffer fb(width, height);
  fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
  ClipSpaceShader shader;
  shader.positions = positions.data();
  draw(fb, state, shader, indices, uint32_t(positions.size()));
  return red_counts(fb);
}

// The same with window-space positions, mapped by window_to_clip.
inline std::vector<int> count_hits_window(int width, int height, const RenderState& state,
                                          std::span<const glm::dvec2> window,
                                          std::span<const uint32_t> indices) {
  std::vector<glm::vec4> clip;
  for (glm::dvec2 p : window) clip.push_back(window_to_clip(p.x, p.y, width, height));
  return count_hits(width, height, state, clip, indices);
}

// An ASCII picture of a per-pixel map for failure messages: '.' for 0, the digit otherwise
// ('#' above 9).
inline std::string ascii_map(const std::vector<int>& values, int width, int height) {
  std::string s;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      int v = values[size_t(y) * width + x];
      s += v == 0 ? '.' : v > 9 ? '#' : char('0' + v);
    }
    s += '\n';
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// The fill rule oracle (Fx8Triangle, rule_covers, rule_covers_pixel) is in fill_rule_oracle.hpp,
// free of GoogleTest so that the geometry fuzz target uses the same one.

// Exact 1/256 coordinates of a window position that must lie on the 1/256 grid.
inline int64_t to_fx8_exact(double v) {
  return int64_t(std::llround(v * 256.0));
}

inline Fx8Triangle fx8_triangle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  return {{to_fx8_exact(a.x), to_fx8_exact(b.x), to_fx8_exact(c.x)},
          {to_fx8_exact(a.y), to_fx8_exact(b.y), to_fx8_exact(c.y)}};
}

// Per-pixel 0/1 map of the rule's coverage over a width x height image.
inline std::vector<int> rule_map(const Fx8Triangle& t, int width, int height) {
  std::vector<int> m(size_t(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) m[size_t(y) * width + x] = rule_covers_pixel(t, x, y) ? 1 : 0;
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Analytic coverage of a convex polygon lying in the plane y = plane_y (world space), seen
// through `view_proj` (OpenGL conventions): a pixel is covered when the ray through its centre
// meets the polygon between the near and the far plane. Computed in double.

enum class Expect : uint8_t { kOut, kIn, kUnsure };

class FloorOracle {
 public:
  FloorOracle(const glm::dmat4& view_proj, int width, int height, double plane_y,
              std::vector<glm::dvec2> polygon_xz)
      : inv_(glm::inverse(view_proj)),
        width_(width),
        height_(height),
        plane_y_(plane_y),
        poly_(std::move(polygon_xz)) {}

  // Whether the ray through window point (wx, wy) meets the polygon between near and far.
  bool hits(double wx, double wy) const {
    double nx = 2.0 * wx / width_ - 1.0, ny = 1.0 - 2.0 * wy / height_;
    glm::dvec3 n = unproject(nx, ny, -1.0), f = unproject(nx, ny, 1.0);
    if (f.y == n.y) return false;
    double t = (plane_y_ - n.y) / (f.y - n.y);
    if (!(t >= 0.0 && t <= 1.0)) return false;
    glm::dvec3 p = n + t * (f - n);
    return inside_polygon(p.x, p.z);
  }

  // kIn / kOut for pixels whose centre is further than `tolerance` pixels from the boundary of
  // the covered region (judged by probing 16 points on a circle of that radius); else kUnsure.
  Expect classify(int px, int py, double tolerance = 0.01) const {
    double cx = px + 0.5, cy = py + 0.5;
    bool centre = hits(cx, cy);
    for (int k = 0; k < 16; ++k) {
      double a = k * (2.0 * std::numbers::pi / 16.0);
      if (hits(cx + tolerance * std::cos(a), cy + tolerance * std::sin(a)) != centre) {
        return Expect::kUnsure;
      }
    }
    return centre ? Expect::kIn : Expect::kOut;
  }

 private:
  glm::dvec3 unproject(double nx, double ny, double nz) const {
    glm::dvec4 h = inv_ * glm::dvec4(nx, ny, nz, 1.0);
    return glm::dvec3(h) / h.w;
  }
  bool inside_polygon(double x, double z) const {
    int pos = 0, neg = 0;
    for (size_t i = 0; i < poly_.size(); ++i) {
      glm::dvec2 a = poly_[i], b = poly_[(i + 1) % poly_.size()];
      double c = (b.x - a.x) * (z - a.y) - (b.y - a.y) * (x - a.x);
      pos += c > 0.0;
      neg += c < 0.0;
    }
    return pos == 0 || neg == 0;
  }

  glm::dmat4 inv_;
  int width_, height_;
  double plane_y_;
  std::vector<glm::dvec2> poly_;
};

// World-space positions transformed in double by a double matrix, then rounded once to float:
// the clip coordinates carry no error from a float matrix product, so the analytic oracle above
// (which uses the same matrix) can be held to a 0.01 pixel tolerance.
struct WorldShader {
  static constexpr int kVaryings = 0;
  const glm::dvec3* positions = nullptr;
  glm::dmat4 view_proj{1.0};
  glm::vec4 color{1.0f / 255.0f, 0.0f, 0.0f, 0.0f};

  glm::vec4 vertex(uint32_t index, float*) const {
    return glm::vec4(view_proj * glm::dvec4(positions[index], 1.0));
  }
  bool fragment(FragmentInput&, glm::vec4& out) const {
    out = color;
    return true;
  }
};

// ---------------------------------------------------------------------------------------------
// The internal rasterizer interface: what a triangle rasterizer emits through its BlockSink,
// collected into per-pixel hit counts with the block contract checked on the way, and random
// triangles (in 1/256 pixel) in the shapes that stress rasterizers.
// Hit counts over a scissor rectangle, reset in time proportional to what was emitted.
class CoverageCollector {
 public:
  explicit CoverageCollector(const detail::PixelRect& scissor)
      : scissor_(scissor), counts_(size_t(scissor.x1 - scissor.x0) * (scissor.y1 - scissor.y0)) {}

  // Starts a new primitive; pixels must lie inside `bounds` (and the scissor).
  void reset(const detail::PixelRect& bounds) {
    for (auto [x, y] : pixels_) counts_[index(x, y)] = 0;
    pixels_.clear();
    errors_.clear();
    bounds_ = bounds;
  }

  detail::BlockSink sink() { return {&CoverageCollector::emit, this}; }

  int count(int x, int y) const {
    if (x < scissor_.x0 || x >= scissor_.x1 || y < scissor_.y0 || y >= scissor_.y1) return 0;
    return counts_[index(x, y)];
  }
  const std::vector<std::pair<int, int>>& pixels() const { return pixels_; }
  // Contract violations seen since reset(): blocks off the 4x4 grid, empty masks, pixels
  // outside the bounds or the scissor, pixels emitted twice.
  const std::string& errors() const { return errors_; }

 private:
  static void emit(void* self, int x, int y, uint32_t mask) {
    static_cast<CoverageCollector*>(self)->add_block(x, y, mask);
  }
  void add_block(int x, int y, uint32_t mask) {
    if (x % 4 != 0 || y % 4 != 0) error("block not on the 4x4 grid", x, y);
    if (mask == 0) error("empty mask", x, y);
    if (mask > 0xffffu) error("mask beyond 16 bits", x, y);
    for (int bit = 0; bit < 16; ++bit) {
      if (mask >> bit & 1u) add_pixel(x + (bit & 3), y + (bit >> 2));
    }
  }
  void add_pixel(int x, int y) {
    if (x < scissor_.x0 || x >= scissor_.x1 || y < scissor_.y0 || y >= scissor_.y1) {
      return error("pixel outside the scissor", x, y);
    }
    if (x < bounds_.x0 || x >= bounds_.x1 || y < bounds_.y0 || y >= bounds_.y1) {
      error("pixel outside the triangle's bounds", x, y);
    }
    uint8_t& c = counts_[index(x, y)];
    if (c != 0) return error("pixel emitted twice", x, y);
    c = 1;
    pixels_.push_back({x, y});
  }
  void error(const char* what, int x, int y) {
    if (errors_.size() < 2000) {
      errors_ += std::string(what) + " at " + std::to_string(x) + ", " + std::to_string(y) + "\n";
    }
  }
  size_t index(int x, int y) const {
    return size_t(y - scissor_.y0) * size_t(scissor_.x1 - scissor_.x0) + size_t(x - scissor_.x0);
  }

  detail::PixelRect scissor_;
  detail::PixelRect bounds_;
  std::vector<uint8_t> counts_;
  std::vector<std::pair<int, int>> pixels_;
  std::string errors_;
};

inline detail::WindowVertex window_vertex(int64_t x_fx8, int64_t y_fx8) {
  detail::WindowVertex v;
  v.x = int32_t(x_fx8);
  v.y = int32_t(y_fx8);
  return v;
}

inline std::string describe_triangle(const detail::WindowVertex (&v)[3],
                                     const detail::PixelRect& scissor) {
  std::ostringstream s;
  s << "triangle (1/256 px) (" << v[0].x << ", " << v[0].y << "), (" << v[1].x << ", " << v[1].y
    << "), (" << v[2].x << ", " << v[2].y << ") scissor [" << scissor.x0 << ", " << scissor.x1
    << ") x [" << scissor.y0 << ", " << scissor.y1 << ")";
  return s.str();
}

// Random triangles in 1/256 pixel around a scissor, in the shapes that stress rasterizers.
class TriangleGenerator {
 public:
  enum Kind { kSmall, kTiny, kSliver, kHuge, kPixelCentres, kSubpixelGrid, kAxisAligned, kCount };

  explicit TriangleGenerator(uint32_t seed) : rng_(seed) {}

  // Fills v with a triangle of `kind` for `scissor` (pixels).
  void make(Kind kind, const detail::PixelRect& s, detail::WindowVertex (&v)[3]) {
    const int64_t margin = 16 * 256;
    int64_t x0 = int64_t(s.x0) * 256 - margin, x1 = int64_t(s.x1) * 256 + margin;
    int64_t y0 = int64_t(s.y0) * 256 - margin, y1 = int64_t(s.y1) * 256 + margin;
    switch (kind) {
      case kSmall:
      case kTiny: {
        int64_t r = kind == kSmall ? 3 * 256 : 256;
        int64_t cx = uniform(x0, x1), cy = uniform(y0, y1);
        for (auto& p : v) p = window_vertex(cx + uniform(-r, r), cy + uniform(-r, r));
        break;
      }
      case kSliver: {  // nearly collinear: the third vertex within 3/256 px of the line
        int64_t ax = uniform(x0, x1), ay = uniform(y0, y1);
        int64_t bx = uniform(x0, x1), by = uniform(y0, y1);
        int64_t t = uniform(-64, 320);  // along the line, in 1/256 of its length
        v[0] = window_vertex(ax, ay);
        v[1] = window_vertex(bx, by);
        v[2] = window_vertex(ax + (bx - ax) * t / 256 + uniform(-3, 3),
                             ay + (by - ay) * t / 256 + uniform(-3, 3));
        break;
      }
      case kHuge: {  // up to several thousand pixels, mostly outside the scissor
        int64_t r = 4000 * 256;
        int64_t cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
        for (auto& p : v) p = window_vertex(cx + uniform(-r, r), cy + uniform(-r, r));
        break;
      }
      case kPixelCentres:
        for (auto& p : v) {
          p = window_vertex(uniform(x0 / 256, x1 / 256) * 256 + 128,
                            uniform(y0 / 256, y1 / 256) * 256 + 128);
        }
        break;
      case kSubpixelGrid:
        for (auto& p : v) p = window_vertex(uniform(x0, x1), uniform(y0, y1));
        break;
      default: {  // two vertices share x or y (exactly horizontal or vertical edges)
        for (auto& p : v) p = window_vertex(uniform(x0, x1), uniform(y0, y1));
        if (uniform(0, 1)) {
          v[1].y = v[0].y;
        } else {
          v[1].x = v[0].x;
        }
        if (uniform(0, 1)) {  // and snap them to pixel centres half of the time
          for (auto& p : v) p.x = p.x / 256 * 256 + 128, p.y = p.y / 256 * 256 + 128;
        }
        break;
      }
    }
  }

  int64_t uniform(int64_t lo, int64_t hi) {
    return std::uniform_int_distribution<int64_t>(lo, hi)(rng_);
  }

 private:
  std::mt19937_64 rng_;
};

}  // namespace softrast::test
