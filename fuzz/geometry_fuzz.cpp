// fuzz/geometry_fuzz.cpp: arbitrary clip-space triangles through clipping, setup, rasterization
// and shading into a 32x32 framebuffer, checked on every input against the fill rule's
// brute-force oracle (tests/fill_rule_oracle.hpp).
//
// Input: byte 0 flags, byte 1 a scissor, then up to 15 vertices, consecutive triples being
// triangles.
//   flags bit 0: scanline rasterizer (else edge equations)      bit 1: wide shader (else scalar)
//         bit 2: grid vertices (else raw floats)                bit 3: counting draws on the
//         reference path (else binned)     bits 4-5: cull of the two-path draw (none, back, front)
//         bit 6: two threads on the binned path                 bit 7: a depth bias of -1e-3
//   scissor byte: x0 = 4 (b & 3), y0 = 4 ((b >> 2) & 3), x1 = 32 - 5 ((b >> 4) & 3),
//                 y1 = 32 - 5 (b >> 6)   (origins on the 4x4 block grid, as the rasterizers need)
//   raw vertex: 6 little-endian floats x, y, z, w, varying 0, varying 1 (NaN, Inf, 1e38,
//               denormals, w of either sign: anything)
//   grid vertex: int16 x, int16 y in 1/256 pixel from the image centre, int8 z (z_ndc = z / 127),
//                a byte choosing w from {1, 0.5, 2, 4, 0.25, -1, 1e-7, 8}, two varying bytes;
//                mapped to clip space exactly (powers of two), so edges through pixel centres
//                and shared vertices on the 1/256 grid are common.
// Checks:
//   1. Every window triangle the geometry stage makes of each input triangle (a clipped one
//      becomes a fan), set up with the fuzzed scissor and rasterized by both rasterizers, covers
//      exactly the oracle's pixels inside the scissor, none outside it, none twice.
//   2. Each input triangle drawn alone through the public draw() (no culling, additive counting)
//      hits every pixel exactly as often as the oracle says over its fan (so clipping, the SIMD
//      vertex front end of the binned path, binning and shading lose or add no pixel).
//   3. All triangles in one depth-tested opaque draw: the reference path and the binned path
//      (deferred shading when the shader is wide) give bit-identical colour and depth, and no
//      pixel outside the oracle's coverage changes.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "fill_rule_oracle.hpp"
#include "fuzz_entries.hpp"
#include "pipeline/geometry_stage.hpp"
#include "raster/raster.hpp"
#include "raster/setup.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/shader.hpp"

namespace softrast::fuzz {
namespace {

using detail::PixelRect;
using detail::WindowVertex;

constexpr int kSize = 32;
constexpr int kStride = 6;  // x, y, z, w, two varyings
constexpr size_t kMaxVertices = 15;

struct Input {
  bool scanline = false, wide = false, grid = false, reference = false, two_threads = false;
  bool depth_bias = false;
  CullMode cull = CullMode::kNone;
  PixelRect scissor{0, 0, kSize, kSize};
  std::vector<float> vertices;  // kStride floats each
  size_t count() const { return vertices.size() / kStride; }
};

float read_float(const uint8_t* p) {
  float f;
  std::memcpy(&f, p, 4);
  return f;
}

void read_grid_vertex(const uint8_t* p, std::vector<float>& out) {
  static constexpr float kW[8] = {1.0f, 0.5f, 2.0f, 4.0f, 0.25f, -1.0f, 1.0e-7f, 8.0f};
  int16_t xi, yi;
  std::memcpy(&xi, p, 2);
  std::memcpy(&yi, p + 2, 2);
  double x = xi / 256.0 + 16.0;  // window coordinates on the 1/256 grid, -112..144 pixels
  double y = yi / 256.0 + 16.0;
  float w = kW[p[5] & 7];
  out.push_back(float((2.0 * x / kSize - 1.0) * w));
  out.push_back(float((1.0 - 2.0 * y / kSize) * w));
  out.push_back(float(int8_t(p[4]) / 127.0 * w));
  out.push_back(w);
  out.push_back(p[6] / 255.0f);
  out.push_back(p[7] / 255.0f);
}

Input parse(const uint8_t* data, size_t size) {
  Input in;
  if (size < 2) return in;
  uint8_t f = data[0], s = data[1];
  in.scanline = f & 1;
  in.wide = f & 2;
  in.grid = f & 4;
  in.reference = f & 8;
  static constexpr CullMode kCull[4] = {CullMode::kNone, CullMode::kBack, CullMode::kFront,
                                        CullMode::kNone};
  in.cull = kCull[(f >> 4) & 3];
  in.two_threads = f & 64;
  in.depth_bias = f & 128;
  in.scissor = {4 * (s & 3), 4 * ((s >> 2) & 3), kSize - 5 * ((s >> 4) & 3), kSize - 5 * (s >> 6)};
  size_t bytes = in.grid ? 8 : 4 * kStride;
  for (size_t at = 2; at + bytes <= size && in.count() < kMaxVertices; at += bytes) {
    if (in.grid) {
      read_grid_vertex(data + at, in.vertices);
    } else {
      for (int k = 0; k < kStride; ++k) in.vertices.push_back(read_float(data + at + 4 * k));
    }
  }
  return in;
}

// The scalar shader: a constant 1/255 in red (one count per fragment under additive blending),
// the varyings in green and blue.
struct ScalarShader {
  static constexpr int kVaryings = 2;
  const float* vertices = nullptr;
  glm::vec4 vertex(uint32_t i, float* varyings) const {
    const float* v = vertices + size_t(i) * kStride;
    varyings[0] = v[4];
    varyings[1] = v[5];
    return {v[0], v[1], v[2], v[3]};
  }
  bool fragment(FragmentInput& in, glm::vec4& color) const {
    color = {1.0f / 255.0f, in.varyings[0], in.varyings[1], 1.0f};
    return true;
  }
};

// The same as a wide shader (deferrable: it neither discards nor writes depth).
struct WideShader {
  static constexpr int kVaryings = 2;
  const float* vertices = nullptr;
  glm::vec4 vertex(uint32_t i, float* varyings) const {
    return ScalarShader{vertices}.vertex(i, varyings);
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    f.color = {F(1.0f / 255.0f), f.varying(0), f.varying(1), F(1.0f)};
  }
};

template <class Fn>
void with_shader(const Input& in, Fn&& fn) {
  if (in.wide) {
    fn(WideShader{in.vertices.data()});
  } else {
    fn(ScalarShader{in.vertices.data()});
  }
}

std::string where(int x, int y) {
  return " at pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

// Hits per pixel of one rasterizer on one set-up triangle within `region`.
struct Recorder {
  PixelRect region;
  int hits[kSize * kSize] = {};
  std::string error;
  static void emit(void* self, int x, int y, uint32_t mask) {
    auto* r = static_cast<Recorder*>(self);
    if (mask == 0 && r->error.empty()) r->error = "empty mask emitted" + where(x, y);
    for (int bit = 0; bit < 16; ++bit) {
      if (!(mask >> bit & 1)) continue;
      int px = x + bit % 4, py = y + bit / 4;
      const PixelRect& s = r->region;
      if (px < s.x0 || px >= s.x1 || py < s.y0 || py >= s.y1) {
        if (r->error.empty()) r->error = "pixel written outside the scissor" + where(px, py);
        continue;
      }
      r->hits[py * kSize + px]++;
    }
  }
};

test::Fx8Triangle fx8(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
  return {{a.x, b.x, c.x}, {a.y, b.y, c.y}};
}

// Check 1 for one window triangle; adds its oracle coverage (whole image) to `oracle`.
void check_window_triangle(const Input& in, const WindowVertex& a, const WindowVertex& b,
                           const WindowVertex& c, int* oracle) {
  test::Fx8Triangle t = fx8(a, b, c);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) oracle[y * kSize + x] += test::rule_covers_pixel(t, x, y);
  }
  detail::TriangleSetup setup;
  bool drawn = detail::setup_triangle(a, b, c, 0, CullMode::kNone, FrontFace::kCounterClockwise,
                                      in.scissor, setup);
  for (bool scanline : {false, true}) {
    Recorder rec;
    rec.region = in.scissor;
    if (drawn) {
      detail::BlockSink sink{&Recorder::emit, &rec};
      if (scanline) {
        detail::rasterize_triangle_scanline(setup, in.scissor, sink);
      } else {
        detail::rasterize_triangle_edge_equations(setup, in.scissor, sink);
      }
    }
    const char* name = scanline ? "scanline: " : "edge equations: ";
    SOFTRAST_FUZZ_REQUIRE(rec.error.empty(), name + rec.error);
    const PixelRect& s = in.scissor;
    for (int y = s.y0; y < s.y1; ++y) {
      for (int x = s.x0; x < s.x1; ++x) {
        int want = test::rule_covers_pixel(t, x, y) ? 1 : 0;
        int got = rec.hits[y * kSize + x];
        SOFTRAST_FUZZ_REQUIRE(
            got == want, std::string(name) + "covers " + std::to_string(got) + " times, the rule " +
                             std::to_string(want) + where(x, y) + " (triangle " +
                             std::to_string(a.x) + "," + std::to_string(a.y) + " " +
                             std::to_string(b.x) + "," + std::to_string(b.y) + " " +
                             std::to_string(c.x) + "," + std::to_string(c.y) + " /256)");
      }
    }
  }
}

RenderState counting_state(const Input& in) {
  RenderState s;
  s.cull = CullMode::kNone;
  s.depth_test = false;
  s.blend = BlendMode::kAdditive;
  s.raster = in.scanline ? RasterAlgorithm::kScanline : RasterAlgorithm::kEdgeEquations;
  s.reference_path = in.reference;
  s.threads = in.two_threads ? 2 : 1;
  s.depth_bias = in.depth_bias ? -1.0e-3f : 0.0f;
  return s;
}

// Checks 1 and 2 for input triangle `t`; adds its oracle coverage to `all`.
void check_triangle(const Input& in, uint32_t t, int* all) {
  RenderState state = counting_state(in);
  detail::ClipVertices clip{in.vertices.data(), in.count(), kStride, 2};
  detail::GeometryStage geometry(kSize, kSize, state, clip);
  int oracle[kSize * kSize] = {};
  geometry.triangle(3 * t, 3 * t + 1, 3 * t + 2,
                    [&](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
                      check_window_triangle(in, a, b, c, oracle);
                    });
  Framebuffer fb(kSize, kSize);
  fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
  const uint32_t indices[3] = {3 * t, 3 * t + 1, 3 * t + 2};
  with_shader(in, [&](const auto& shader) {
    draw(fb, state, shader, std::span<const uint32_t>(indices, 3), uint32_t(in.count()));
  });
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      int got = int(fb.color_at(x, y) & 0xff), want = std::min(oracle[y * kSize + x], 255);
      SOFTRAST_FUZZ_REQUIRE(got == want, "draw() hits " + std::to_string(got) +
                                             " times, the oracle " + std::to_string(want) +
                                             where(x, y) + " (triangle " + std::to_string(t) + ")");
      all[y * kSize + x] += oracle[y * kSize + x];
    }
  }
}

// Check 3: the reference path and the binned path agree bit for bit.
void check_paths_agree(const Input& in, const int* covered) {
  std::vector<uint32_t> indices(in.count() / 3 * 3);
  for (uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
  RenderState state;
  state.cull = in.cull;
  state.raster = in.scanline ? RasterAlgorithm::kScanline : RasterAlgorithm::kEdgeEquations;
  state.depth_bias = in.depth_bias ? -1.0e-3f : 0.0f;
  state.threads = in.two_threads ? 2 : 1;
  Framebuffer ref(kSize, kSize), fast(kSize, kSize);
  ref.clear();
  fast.clear();
  with_shader(in, [&](const auto& shader) {
    RenderState r = state;
    r.reference_path = true;
    draw(ref, r, shader, indices, uint32_t(in.count()));
    draw(fast, state, shader, indices, uint32_t(in.count()));
  });
  Framebuffer clear(kSize, kSize);
  clear.clear();
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      float dr = ref.depth_at(x, y), df = fast.depth_at(x, y);
      SOFTRAST_FUZZ_REQUIRE(
          ref.color_at(x, y) == fast.color_at(x, y) && std::memcmp(&dr, &df, 4) == 0,
          "reference and binned paths differ" + where(x, y));
      bool changed = ref.color_at(x, y) != clear.color_at(x, y) || dr != clear.depth_at(x, y);
      SOFTRAST_FUZZ_REQUIRE(!changed || covered[y * kSize + x] > 0,
                            "a pixel no triangle covers was written" + where(x, y));
    }
  }
}

}  // namespace

int fuzz_geometry(const uint8_t* data, size_t size) {
  Input in = parse(data, size);
  if (in.count() < 3) return 0;
  int covered[kSize * kSize] = {};
  for (uint32_t t = 0; t < in.count() / 3; ++t) check_triangle(in, t, covered);
  check_paths_agree(in, covered);
  return 0;
}

}  // namespace softrast::fuzz
