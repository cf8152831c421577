// tests/conformance_test.cpp: conformance classes against Mesa's llvmpipe, dEQP style. Random
// scenes of each class are drawn by softrast (in this process, both rasterizers, the binned
// path) and by llvmpipe (tools/reference/glconform: every case of a class in one process), and
// compared by the class's rule:
//   1. grid: vertices on the 1/256-pixel grid (exact in float, w a power of two): the number
//      of hits of every pixel equals the exact top-left rule's (fill_rule_oracle.hpp; the window
//      positions are exact, so it decides ties on an edge too). llvmpipe's pixels that differ
//      from the same rule are counted and printed (Mesa 22.3.6 drops a whole draw of three
//      triangles when the third is degenerate).
//   2. float: float vertices with perspective (w in [0.1, 4]): no pixel differs in hits outside
//      a band of +-1/256 pixel around the edges (the exact edges, computed in double).
//   3. colour: interpolated colour within 2/255 of a pixel of the other image within one pixel
//      (dEQP's position-deviation compare, both ways), except at pixels whose sample lies in the
//      +-1/256 band of an edge (their coverage is class 2's matter).
//   4. texture: bilinear and trilinear (the same mip chain uploaded to both) within 4/255, the
//      same compare; where bilinear images differ at a sample only one triangle covers,
//      softrast within 4/255 of the exact value (coordinates and filter in double) is right, and
//      llvmpipe is counted as wrong.
//   5. depth: vertices as in class 1, random depths: wherever both images draw and the coverage
//      is certain, softrast's depth (float, rounded to 24 bits) is within one unit of 2^-24 of
//      the exact depth; the largest difference to llvmpipe's 24-bit buffer is reported (llvmpipe
//      evaluates the depth plane in float and is hundreds of units off on steep slivers, so one
//      unit between the two cannot be asked; softrast's plane is in double, DepthPlane).
//   6. clip: clip coordinates up to 1e6 * w (and z beyond near and far, w of either sign): hits
//      as in class 2; beyond 1e6 * w, up to 1e30 * w, softrast alone against the double-precision
//      oracle of this file (llvmpipe itself goes wrong near 1e8).
//   7. lines: endpoints on the 1/256 grid: the pixels of every line identical (both follow the
//      diamond-exit rule), and softrast's also equal to the brute-force rule of this file away
//      from exact ties.
// Coverage in classes 2 and 6 is also held to the double-precision oracle (outside the band).
//
// llvmpipe gives a sample exactly on a horizontal edge to the triangle above it in the image,
// softrast (CONVENTIONS.md) to the triangle below. glconform --mirror-y draws every scene upside
// down and reads it back unflipped: the same image, with llvmpipe's ties then falling as
// softrast's, so coverage is compared exactly (reference_diff_test.cpp pins the tie itself).
//
// Cases per class: a few hundred in the normal test pass (about ten seconds for all);
// SOFTRAST_CONFORMANCE_CASES=100000 runs that many per class (the README's table). On a
// mismatch the scene, both images and the error mask are saved in a folder named by the failure
// message, and the scene is shrunk (delta debugging: drop primitives while the mismatch stays)
// to the fewest primitives that still differ, saved beside it.
#include <gtest/gtest.h>

#if defined(SOFTRAST_GLCONFORM_PATH)

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fill_rule_oracle.hpp"
#include "shaders/builtin_shaders.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/shader.hpp"
#include "softrast/texture.hpp"
#include "texture_oracle.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

struct Vertex {
  float x = 0, y = 0, z = 0, w = 1;
  float r = 0, g = 0, b = 0, a = 1;
  float u = 0, v = 0;
};

enum class Mode { kCount, kColour, kTexture, kDepth };

struct Scene {
  int width = 64, height = 64;
  Mode mode = Mode::kCount;
  bool lines = false;
  std::vector<Vertex> vertices;  // 3 per triangle, 2 per line
  Filter filter = Filter::kBilinear;
  std::shared_ptr<Texture> texture;
  int per_primitive() const { return lines ? 2 : 3; }
  int primitives() const { return int(vertices.size()) / per_primitive(); }
  Scene with(const std::vector<int>& keep) const {
    Scene s = *this;
    s.vertices.clear();
    for (int p : keep) {
      for (int k = 0; k < per_primitive(); ++k)
        s.vertices.push_back(vertices[p * per_primitive() + k]);
    }
    return s;
  }
};

struct Rendered {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  std::vector<uint32_t> depth;  // 24-bit units
  const uint8_t* pixel(int x, int y) const { return &rgba[(size_t(y) * width + x) * 4]; }
  uint32_t depth_at(int x, int y) const { return depth[size_t(y) * width + x]; }
};

// ---------------------------------------------------------------------------------------------
// The case file (see glconform.cpp).

std::string hex(float f) {
  char text[40];
  std::snprintf(text, sizeof text, "%a", double(f));
  return text;
}

void write_scene(std::ostream& out, const Scene& s) {
  static constexpr const char* kModes[] = {"count", "colour", "texture", "depth"};
  out << "case " << s.width << ' ' << s.height << ' ' << kModes[int(s.mode)] << ' '
      << (s.lines ? "lines" : "triangles") << ' ' << s.vertices.size() << '\n';
  if (s.mode == Mode::kTexture) {
    const Texture& t = *s.texture;
    int levels = s.filter == Filter::kTrilinear ? t.levels() : 1;
    out << "texture " << (s.filter == Filter::kTrilinear ? "trilinear" : "bilinear") << ' '
        << levels << '\n';
    static constexpr char kDigits[] = "0123456789abcdef";
    for (int l = 0; l < levels; ++l) {
      const MipLevel& m = t.level(l);
      out << "level " << m.width << ' ' << m.height << ' ';
      const uint8_t* p = t.texels() + m.offset * 4;
      for (size_t i = 0; i < size_t(m.width) * m.height * 4; ++i) {
        out << kDigits[p[i] >> 4] << kDigits[p[i] & 15];
      }
      out << '\n';
    }
  }
  for (const Vertex& v : s.vertices) {
    out << "v " << hex(v.x) << ' ' << hex(v.y) << ' ' << hex(v.z) << ' ' << hex(v.w) << ' '
        << hex(v.r) << ' ' << hex(v.g) << ' ' << hex(v.b) << ' ' << hex(v.a) << ' ' << hex(v.u)
        << ' ' << hex(v.v) << '\n';
  }
}

// Draws every scene with llvmpipe in one glconform process.
std::vector<Rendered> llvmpipe(const std::vector<Scene>& scenes, const fs::path& dir) {
  fs::path cases = dir / "cases.txt", out = dir / "llvmpipe.bin";
  {
    std::ofstream file(cases);
    for (const Scene& s : scenes) write_scene(file, s);
  }
  std::string command = "LP_NUM_THREADS=0 '" + std::string(SOFTRAST_GLCONFORM_PATH) + "' '" +
                        cases.string() + "' '" + out.string() + "' --mirror-y";
  int status = std::system(command.c_str());
  std::vector<Rendered> result;
  if (status != 0) {
    ADD_FAILURE() << command << " failed with status " << status;
    return result;
  }
  std::ifstream in(out, std::ios::binary);
  for (const Scene& s : scenes) {
    Rendered r;
    r.width = s.width, r.height = s.height;
    size_t n = size_t(s.width) * s.height;
    r.rgba.resize(n * 4);
    r.depth.resize(n);
    in.read(reinterpret_cast<char*>(r.rgba.data()), std::streamsize(n * 4));
    in.read(reinterpret_cast<char*>(r.depth.data()), std::streamsize(n * 4));
    if (!in) {
      ADD_FAILURE() << "glconform's output is short";
      result.clear();
      return result;
    }
    result.push_back(std::move(r));
  }
  return result;
}

// ---------------------------------------------------------------------------------------------
// softrast's side.

struct ConformShader {
  static constexpr int kVaryings = 6;  // r, g, b, a, u, v
  const Vertex* vertices = nullptr;
  Mode mode = Mode::kCount;
  const Texture* texture = nullptr;
  Sampler sampler;
  glm::vec4 vertex(uint32_t i, float* out) const {
    const Vertex& v = vertices[i];
    out[0] = v.r, out[1] = v.g, out[2] = v.b, out[3] = v.a, out[4] = v.u, out[5] = v.v;
    return {v.x, v.y, v.z, v.w};
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    switch (mode) {
      case Mode::kCount:
        f.color = {F(1.0f / 255.0f), F(0.0f), F(0.0f), F(0.0f)};
        break;
      case Mode::kColour:
        f.color = {f.varying(0), f.varying(1), f.varying(2), f.varying(3)};
        break;
      case Mode::kTexture: {
        simd::Vec4<N> t = detail::sample_with_derivatives(SampledTexture(*texture, sampler), f, 4);
        f.color = {t.x, t.y, t.z, t.w};
        break;
      }
      case Mode::kDepth:
        f.color = {F(1.0f), F(0.0f), F(0.0f), F(1.0f)};
        break;
    }
  }
};

Rendered draw_softrast(const Scene& s, RasterAlgorithm raster) {
  Framebuffer fb(s.width, s.height);
  fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
  fb.clear_depth(1.0f);
  RenderState state;
  state.primitive = s.lines ? Primitive::kLines : Primitive::kTriangles;
  state.cull = CullMode::kNone;
  state.depth_test = s.mode == Mode::kDepth;
  state.blend = s.mode == Mode::kCount ? BlendMode::kAdditive : BlendMode::kOpaque;
  state.raster = raster;
  state.threads = 1;
  ConformShader shader;
  shader.vertices = s.vertices.data();
  shader.mode = s.mode;
  shader.texture = s.texture.get();
  shader.sampler.filter = s.filter;
  std::vector<uint32_t> indices(s.vertices.size());
  for (uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
  draw(fb, state, shader, indices, uint32_t(indices.size()));
  Rendered r;
  r.width = s.width, r.height = s.height;
  r.rgba.resize(size_t(s.width) * s.height * 4);
  r.depth.resize(size_t(s.width) * s.height);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      uint32_t c = fb.color_at(x, y);
      uint8_t* p = &r.rgba[(size_t(y) * s.width + x) * 4];
      for (int k = 0; k < 4; ++k) p[k] = uint8_t(c >> (8 * k));
      r.depth[size_t(y) * s.width + x] =
          uint32_t(std::lround(double(fb.depth_at(x, y)) * double((1 << 24) - 1)));
    }
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// The oracle: exact homogeneous rasterization (Olano and Greer), no clipping arithmetic. With the
// triangle's clip-space rows V_i = (x_i, y_i, w_i) and a sample's ray S = (X, Y, W) (integers:
// NDC scaled by width * height), a point sum(l_i V_i) of the triangle (l_i >= 0) lies on the ray
// in front of the eye exactly when l_i = m E_i / D with m > 0, where E_i = det[S; V_i+1; V_i+2]
// and D = det[V_0; V_1; V_2]. So the sample is covered when every E_i has D's sign and the point
// lies between the near and far planes: sum E_i (z_i + w_i) and sum E_i (w_i - z_i) of D's sign.
// The signs of E_i and D are exact: products of floats are exact in double, and sums of them are
// kept as floating-point expansions (Shewchuk), so vertices at 1e30 * w are judged correctly.
// Every condition is linear in the pixel position; a sample within 1/256 pixel of the line where
// one of them changes sign (or whose sign the double arithmetic of the two plane sums cannot
// tell) is ambiguous.

constexpr double kBand = 1.0 / 256.0;

// An exact sum of doubles: non-overlapping components, smallest first (Shewchuk's expansions).
struct Expansion {
  std::vector<double> parts;
  void add(double b) {
    std::vector<double> out;
    double q = b;
    for (double e : parts) {
      double sum = q + e;
      double bv = sum - q;
      double error = (q - (sum - bv)) + (e - bv);
      if (error != 0.0) out.push_back(error);
      q = sum;
    }
    out.push_back(q);
    parts = std::move(out);
  }
  // a * b exactly, added.
  void add_product(double a, double b) {
    double p = a * b;
    add(std::fma(a, b, -p));
    add(p);
  }
  int sign() const {
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
      if (*it != 0.0) return *it > 0 ? 1 : -1;
    }
    return 0;
  }
  double value() const {
    double v = 0.0;
    for (double p : parts) v += p;
    return v;
  }
};

using Row = std::array<double, 3>;  // x, y, w

// det[a; b; c] exactly, for b and c of float values (their products are exact in double) and any
// double a.
Expansion det3(const Row& a, const Row& b, const Row& c) {
  Expansion e;
  // a.x (b.y c.w - b.w c.y) - a.y (b.x c.w - b.w c.x) + a.w (b.x c.y - b.y c.x)
  const double minors[3][4] = {{b[1] * c[2], -(b[2] * c[1]), 0, 0},
                               {-(b[0] * c[2]), b[2] * c[0], 0, 0},
                               {b[0] * c[1], -(b[1] * c[0]), 0, 0}};
  for (int k = 0; k < 3; ++k) {
    e.add_product(a[size_t(k)], minors[k][0]);
    e.add_product(a[size_t(k)], minors[k][1]);
  }
  return e;
}

// The 3-vector of det[S; b; c] as a linear function of S (its minors), rounded.
Row minors(const Row& b, const Row& c) {
  return {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
}

// Per pixel: the oracle's count and whether the sample is within the band of an edge.
struct Oracle {
  std::vector<int> count;
  std::vector<bool> ambiguous;
  std::vector<double> depth;  // the nearest covering triangle's window depth (1 if none)
  std::vector<int> top;       // the last triangle in draw order covering the sample (-1 if none)
  std::vector<std::array<double, 2>> uv;  // that triangle's perspective-correct (u, v) there
};

Oracle oracle(const Scene& s) {
  Oracle o;
  size_t n = size_t(s.width) * s.height;
  o.count.assign(n, 0);
  o.ambiguous.assign(n, false);
  o.depth.assign(n, 1.0);
  o.top.assign(n, -1);
  o.uv.assign(n, {0.0, 0.0});
  const double W = s.width, H = s.height;
  for (int t = 0; t < s.primitives(); ++t) {
    Row v[3];
    double z[3];
    for (int k = 0; k < 3; ++k) {
      const Vertex& p = s.vertices[size_t(3 * t + k)];
      v[k] = {p.x, p.y, p.w};
      z[k] = p.z;
    }
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      for (double c : {v[k][0], v[k][1], v[k][2], z[k]}) finite = finite && std::isfinite(c);
    }
    if (!finite) continue;
    int d = det3(v[0], v[1], v[2]).sign();
    if (d == 0) continue;  // seen edge-on: nothing drawn
    Row m[3], am[3];       // the minors, and the sums of the magnitudes of their two products
    for (int i = 0; i < 3; ++i) {
      const Row &b = v[(i + 1) % 3], &c = v[(i + 2) % 3];
      m[i] = minors(b, c);
      am[i] = {std::abs(b[1] * c[2]) + std::abs(b[2] * c[1]),
               std::abs(b[2] * c[0]) + std::abs(b[0] * c[2]),
               std::abs(b[0] * c[1]) + std::abs(b[1] * c[0])};
    }
    // The plane sums as linear functions of S.
    Row near{}, far{};
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) {
        near[size_t(k)] += m[i][size_t(k)] * (z[i] + v[i][2]);
        far[size_t(k)] += m[i][size_t(k)] * (v[i][2] - z[i]);
      }
    }
    // When no vertex needs clipping, the window depth is the affine function of the window
    // position through the three projected vertices: computed from window-space barycentrics in
    // double (exact edge functions for vertices on the 1/256 grid with power-of-two w), which
    // keeps its error far below 2^-24 even for steep planes, where the ratio of the homogeneous
    // sums loses digits to cancellation.
    bool window_depth = true;
    double wx[3], wy[3], wz[3];
    for (int k = 0; k < 3; ++k) {
      double w = v[k][2];
      window_depth = window_depth && w > 0 && std::abs(z[k]) <= w;
      wx[k] = (v[k][0] / w + 1.0) * 0.5 * W;
      wy[k] = (1.0 - v[k][1] / w) * 0.5 * H;
      wz[k] = 0.5 * (z[k] / w) + 0.5;
    }
    double area = (wx[1] - wx[0]) * (wy[2] - wy[0]) - (wx[2] - wx[0]) * (wy[1] - wy[0]);
    window_depth = window_depth && area != 0.0;
    // S = ((2 px + 1 - W) H, (H - 2 py - 1) W, W H); d/dpx = (2H, 0, 0), d/dpy = (0, -2W, 0).
    auto gradient = [&](const Row& f) { return std::hypot(2 * H * f[0], 2 * W * f[1]); };
    for (int py = 0; py < s.height; ++py) {
      for (int px = 0; px < s.width; ++px) {
        Row S = {(2.0 * px + 1 - W) * H, (H - 2.0 * py - 1) * W, W * H};
        bool inside = true, near_edge = false;
        double e_values[3];
        for (int i = 0; i < 3; ++i) {
          // The rounded value decides unless it is within its error bound of zero.
          double value = m[i][0] * S[0] + m[i][1] * S[1] + m[i][2] * S[2];
          double bound = 1e-15 * (std::abs(S[0]) * am[i][0] + std::abs(S[1]) * am[i][1] +
                                  std::abs(S[2]) * am[i][2]);
          int sign = value > bound ? 1 : value < -bound ? -1 : 0;
          if (sign == 0) {
            Expansion e = det3(S, v[(i + 1) % 3], v[(i + 2) % 3]);
            sign = e.sign();
            value = e.value();
          }
          if (sign * d <= 0) inside = false;
          if (!(std::abs(value) > kBand * gradient(m[i]))) near_edge = true;
          e_values[i] = value;
        }
        for (const Row* f : {&near, &far}) {
          double value = (*f)[0] * S[0] + (*f)[1] * S[1] + (*f)[2] * S[2];
          double magnitude =
              std::abs((*f)[0] * S[0]) + std::abs((*f)[1] * S[1]) + std::abs((*f)[2] * S[2]);
          for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) {
              magnitude +=
                  std::abs(m[i][size_t(k)] * S[size_t(k)]) * (std::abs(z[i]) + std::abs(v[i][2]));
            }
          }
          if (value * d < 0) inside = false;
          if (!(std::abs(value) > kBand * gradient(*f) + 1e-12 * magnitude)) near_edge = true;
        }
        size_t at = size_t(py) * s.width + px;
        if (near_edge) o.ambiguous[at] = true;
        if (inside) {
          o.count[at]++;
          o.top[at] = t;
          // Attributes: sum E_i a_i / sum E_i (the point's homogeneous barycentrics).
          double es = e_values[0] + e_values[1] + e_values[2], u = 0.0, tv = 0.0;
          for (int i = 0; i < 3; ++i) {
            const Vertex& p = s.vertices[size_t(3 * t + i)];
            u += e_values[i] * p.u;
            tv += e_values[i] * p.v;
          }
          o.uv[at] = {u / es, tv / es};
          // The point sum E_i V_i / sum E_i (homogeneous): z_ndc = sum E_i z_i / sum E_i w_i.
          double depth;
          if (window_depth) {
            double cx = px + 0.5, cy = py + 0.5, sum = 0.0;
            for (int i = 0; i < 3; ++i) {
              int b = (i + 1) % 3, c = (i + 2) % 3;
              double e = (wx[b] - cx) * (wy[c] - cy) - (wx[c] - cx) * (wy[b] - cy);
              sum += e / area * wz[i];
            }
            depth = sum;
          } else {
            double zs = 0, ws = 0;
            for (int i = 0; i < 3; ++i) zs += e_values[i] * z[i], ws += e_values[i] * v[i][2];
            depth = 0.5 * (zs / ws) + 0.5;
          }
          o.depth[at] = std::min(o.depth[at], depth);
        }
      }
    }
  }
  return o;
}

// ---------------------------------------------------------------------------------------------
// Lines: OpenGL's diamond-exit rule by brute force, exactly. A pixel is drawn when the segment
// meets the inside of its diamond |x - cx| + |y - cy| < 1/2 and its end does not lie in that
// diamond, both after the endpoint perturbation the specification uses to break ties (4.6,
// 14.5.1: each endpoint moved by a vanishing (e, e^2)). The perturbation is made concrete: with
// every coordinate on the 1/256 grid, e = 2^-26 is small enough that no test's sign changes for
// any smaller e (an e term is at most 2^7 e = 2^-19, below the smallest nonzero unperturbed
// value, 2^-16; an e^2 term at most 2^7 e^2 = 2^-45, below the smallest nonzero e term, 2^-34).
// Coordinates are then integers in units of 2^-52 pixel and every test is exact in 128 bits.
// Which way the perturbation points in softrast's y-down window (kLineNudgeX, kLineNudgeY) is
// line_raster.cpp's reading of the specification's y-up one; the class checks it pixel for pixel.

constexpr int kLineNudgeX = 1, kLineNudgeY = -1;  // (+e, -e^2) in y-down window coordinates
using Wide = __int128;
constexpr Wide kUnit = Wide(1) << 52;  // one pixel

bool in_open_diamond(Wide x, Wide y, Wide cx, Wide cy) {
  Wide dx = x - cx, dy = y - cy;
  return (dx < 0 ? -dx : dx) + (dy < 0 ? -dy : dy) < kUnit / 2;
}

// Whether the closed segment (x0, y0)-(x1, y1) meets the open diamond of centre (cx, cy): no
// separating axis among the diamond's four edge normals and the segment's normal.
bool segment_meets_open_diamond(Wide x0, Wide y0, Wide x1, Wide y1, Wide cx, Wide cy) {
  if (x0 == x1 && y0 == y1) return in_open_diamond(x0, y0, cx, cy);
  for (int a : {-1, 1}) {
    for (int b : {-1, 1}) {
      if (a * (x0 - cx) + b * (y0 - cy) >= kUnit / 2 && a * (x1 - cx) + b * (y1 - cy) >= kUnit / 2)
        return false;
    }
  }
  Wide nx = -(y1 - y0), ny = x1 - x0;
  bool all_at_or_above = true, all_at_or_below = true;
  const Wide corners[4][2] = {
      {cx - kUnit / 2, cy}, {cx + kUnit / 2, cy}, {cx, cy - kUnit / 2}, {cx, cy + kUnit / 2}};
  for (const auto& c : corners) {
    Wide side = nx * (c[0] - x0) + ny * (c[1] - y0);
    all_at_or_above = all_at_or_above && side >= 0;
    all_at_or_below = all_at_or_below && side <= 0;
  }
  return !(all_at_or_above || all_at_or_below);
}

Oracle line_oracle(const Scene& s) {
  Oracle o;
  size_t n = size_t(s.width) * s.height;
  o.count.assign(n, 0);
  o.ambiguous.assign(n, false);
  const Wide e = Wide(1) << 26, e2 = 1;  // e and e^2 in units of 2^-52 pixel
  for (int l = 0; l < s.primitives(); ++l) {
    Wide p[2][2];
    bool on_grid = true;
    for (int k = 0; k < 2; ++k) {
      const Vertex& v = s.vertices[size_t(2 * l + k)];
      double x = (double(v.x) / v.w + 1) * 0.5 * s.width;
      double y = (1 - double(v.y) / v.w) * 0.5 * s.height;
      on_grid = on_grid && x * 256 == std::floor(x * 256) && y * 256 == std::floor(y * 256) &&
                std::abs(x) < 4096 && std::abs(y) < 4096;
      p[k][0] = Wide(int64_t(x * 256)) * (kUnit / 256) + kLineNudgeX * e;
      p[k][1] = Wide(int64_t(y * 256)) * (kUnit / 256) + kLineNudgeY * e2;
    }
    if (!on_grid) {  // outside what the exact test covers: every pixel is left to llvmpipe
      o.ambiguous.assign(n, true);
      continue;
    }
    for (int py = 0; py < s.height; ++py) {
      for (int px = 0; px < s.width; ++px) {
        Wide cx = Wide(px) * kUnit + kUnit / 2, cy = Wide(py) * kUnit + kUnit / 2;
        if (segment_meets_open_diamond(p[0][0], p[0][1], p[1][0], p[1][1], cx, cy) &&
            !in_open_diamond(p[1][0], p[1][1], cx, cy)) {
          o.count[size_t(py) * s.width + px]++;
        }
      }
    }
  }
  return o;
}

// ---------------------------------------------------------------------------------------------
// Comparisons. Each returns the number of mismatching pixels and marks them in `mask`.

int channel_diff(const Rendered& a, int ax, int ay, const Rendered& b, int bx, int by) {
  const uint8_t* p = a.pixel(ax, ay);
  const uint8_t* q = b.pixel(bx, by);
  int worst = 0;
  for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(int(p[c]) - int(q[c])));
  return worst;
}

// GL_LINEAR with GL_REPEAT at (u, v) of the base level, in double: the exact bilinear value
// (texture_oracle.hpp).
std::array<double, 4> exact_bilinear(const Texture& t, double u, double v) {
  auto texel = [&](int i, int j) { return glm::dvec4(t.texel(i, j)); };
  glm::dvec4 c = test::spec_linear(texel, t.width(), t.height(), Sampler{}, u, v);
  return {c.r, c.g, c.b, c.a};
}

bool close_neighbour(const Rendered& a, const Rendered& b, int x, int y, int threshold) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      int bx = x + dx, by = y + dy;
      if (bx < 0 || by < 0 || bx >= b.width || by >= b.height) continue;
      if (channel_diff(a, x, y, b, bx, by) <= threshold) return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Trilinear filtering as the OpenGL specification bounds it (4.6, 8.14): the scale factor rho may
// be any value between max(m_u, m_v) and m_u + m_v, where m_u = max(|du/dx|, |du/dy|) in texels
// (m_v likewise), and the derivatives themselves are differences within the 2x2 quad (either
// row, either column) or the exact ones. Over the whole level-of-detail interval that allows
// (widened by kLodSlack), trilinear filtering is piecewise linear in the level of detail, so its
// extreme values per channel are taken at the interval's ends and at whole levels inside it. A
// pixel passes when each channel lies within 4/255 of that range. This is how dEQP's texture
// lookup verifier judges a filtered result, and what lets two correct implementations (softrast
// uses the exact rho, llvmpipe the max of the components) differ by whole levels on skewed quads.

constexpr double kLodSlack = 1.0 / 64.0;  // level-of-detail precision: 6 fraction bits

struct UvFunction {  // the perspective-correct (u, v) of one triangle at any window position
  double x[3], y[3], inv_w[3], u_w[3], v_w[3], area;
  explicit UvFunction(const Scene& s, int t) {
    for (int k = 0; k < 3; ++k) {
      const Vertex& p = s.vertices[size_t(3 * t + k)];
      x[k] = (double(p.x) / p.w + 1.0) * 0.5 * s.width;
      y[k] = (1.0 - double(p.y) / p.w) * 0.5 * s.height;
      inv_w[k] = 1.0 / p.w;
      u_w[k] = double(p.u) / p.w;
      v_w[k] = double(p.v) / p.w;
    }
    area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  }
  std::array<double, 2> at(double px, double py) const {
    double q = 0, u = 0, v = 0;
    for (int i = 0; i < 3; ++i) {
      int b = (i + 1) % 3, c = (i + 2) % 3;
      double l = ((x[b] - px) * (y[c] - py) - (x[c] - px) * (y[b] - py)) / area;
      q += l * inv_w[i], u += l * u_w[i], v += l * v_w[i];
    }
    return {u / q, v / q};
  }
};

// Bilinear filtering of level l at (u, v), wrap repeat, in double: channels in [0, 255].
std::array<double, 4> bilinear_exact(const Texture& t, int l, double u, double v) {
  const MipLevel& m = t.level(l);
  double x = u * m.width - 0.5, y = v * m.height - 0.5;
  double fx = x - std::floor(x), fy = y - std::floor(y);
  auto wrap = [](double i, int size) { return int(((int64_t(i) % size) + size) % size); };
  int i0 = wrap(std::floor(x), m.width), i1 = wrap(std::floor(x) + 1, m.width);
  int j0 = wrap(std::floor(y), m.height), j1 = wrap(std::floor(y) + 1, m.height);
  auto texel = [&](int i, int j) { return t.texels() + (m.offset + size_t(j) * m.width + i) * 4; };
  std::array<double, 4> r;
  for (int c = 0; c < 4; ++c) {
    double bottom = texel(i0, j0)[c] * (1 - fx) + texel(i1, j0)[c] * fx;
    double top = texel(i0, j1)[c] * (1 - fx) + texel(i1, j1)[c] * fx;
    r[size_t(c)] = bottom * (1 - fy) + top * fy;
  }
  return r;
}

// GL_LINEAR_MIPMAP_LINEAR (magnification GL_LINEAR) at level of detail `lod`.
std::array<double, 4> trilinear_exact(const Texture& t, double lod, double u, double v) {
  if (!(lod > 0.0)) return bilinear_exact(t, 0, u, v);
  double d = std::min(lod, double(t.levels() - 1));
  int l0 = int(d);
  double f = d - l0;
  std::array<double, 4> a = bilinear_exact(t, l0, u, v);
  if (f == 0.0) return a;
  std::array<double, 4> b = bilinear_exact(t, l0 + 1, u, v);
  for (size_t c = 0; c < 4; ++c) a[c] = a[c] * (1 - f) + b[c] * f;
  return a;
}

// Whether `pixel` is a trilinear result the specification allows at (x, y) of triangle t.
bool trilinear_allowed(const Scene& s, int t, int x, int y, const uint8_t* pixel) {
  const Texture& tex = *s.texture;
  UvFunction f(s, t);
  // The quad's four samples; derivatives in texels.
  int qx = x & ~1, qy = y & ~1;
  std::array<double, 2> q[2][2];
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) q[j][i] = f.at(qx + i + 0.5, qy + j + 0.5);
  }
  const double w = tex.width(), h = tex.height();
  double lo = INFINITY, hi = -INFINITY;
  auto bound = [&](double dudx, double dvdx, double dudy, double dvdy) {
    double mu = std::max(std::abs(dudx), std::abs(dudy)) * w;
    double mv = std::max(std::abs(dvdx), std::abs(dvdy)) * h;
    lo = std::min(lo, std::log2(std::max(mu, mv)));
    hi = std::max(hi, std::log2(mu + mv));
  };
  for (int row = 0; row < 2; ++row) {
    for (int column = 0; column < 2; ++column) {
      bound(q[row][1][0] - q[row][0][0], q[row][1][1] - q[row][0][1],
            q[1][column][0] - q[0][column][0], q[1][column][1] - q[0][column][1]);
    }
  }
  const double e = 1.0 / 1024.0;  // the exact derivatives, by central differences
  std::array<double, 2> c = f.at(x + 0.5, y + 0.5);
  std::array<double, 2> xp = f.at(x + 0.5 + e, y + 0.5), xm = f.at(x + 0.5 - e, y + 0.5);
  std::array<double, 2> yp = f.at(x + 0.5, y + 0.5 + e), ym = f.at(x + 0.5, y + 0.5 - e);
  bound((xp[0] - xm[0]) / (2 * e), (xp[1] - xm[1]) / (2 * e), (yp[0] - ym[0]) / (2 * e),
        (yp[1] - ym[1]) / (2 * e));
  if (std::isnan(lo) || std::isnan(hi)) return true;  // degenerate: not judged
  // Below 0 is the base level and above the last level the last: log2(0) = -inf is fine.
  const double top = tex.levels() - 1;
  lo = std::clamp(lo - kLodSlack, -1.0, top + 1.0),
  hi = std::clamp(hi + kLodSlack, -1.0, top + 1.0);
  std::array<double, 4> least, most;
  least.fill(INFINITY), most.fill(-INFINITY);
  auto include = [&](double lod) {
    std::array<double, 4> r = trilinear_exact(tex, lod, c[0], c[1]);
    for (size_t k = 0; k < 4; ++k)
      least[k] = std::min(least[k], r[k]), most[k] = std::max(most[k], r[k]);
  };
  include(lo);
  include(hi);
  for (double l = std::ceil(lo); l < hi; l += 1.0) include(l);
  for (size_t k = 0; k < 4; ++k) {
    if (pixel[k] < least[k] - 4.0 || pixel[k] > most[k] + 4.0) return false;
  }
  return true;
}

enum class Rule {
  kExactHits,
  kHitsOutsideBand,
  kColour2,
  kColour4,
  kTrilinear,
  kDepth1,
  kOracleOnly,
  kLines
};

struct Verdict {
  int mismatches = 0;
  std::vector<bool> mask;
  int max_diff = 0;  // colour classes: largest channel difference at one position; depth: units
  double max_own = 0.0, max_other = 0.0;  // depth: softrast's and llvmpipe's largest error
  long llvmpipe_wrong = 0;  // coverage: llvmpipe's pixels that differ from the exact oracle
};

// Class 1's exact answer: with vertices on the 1/256 grid and w a power of two, the window
// positions are exact 1/256 multiples, so the top-left rule (fill_rule_oracle.hpp, written from
// CONVENTIONS.md alone) decides every sample, ties on an edge included: the hits per pixel.
std::vector<int> fill_rule_counts(const Scene& s) {
  std::vector<int> count(size_t(s.width) * s.height, 0);
  for (int p = 0; p < s.primitives(); ++p) {
    test::Fx8Triangle t;
    for (int k = 0; k < 3; ++k) {
      const Vertex& v = s.vertices[size_t(p) * 3 + size_t(k)];
      double x = (double(v.x) / v.w + 1.0) * 0.5 * s.width;   // exact: see grid_scene
      double y = (1.0 - double(v.y) / v.w) * 0.5 * s.height;  // y down
      t.x[size_t(k)] = std::llround(x * 256.0);
      t.y[size_t(k)] = std::llround(y * 256.0);
    }
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        count[size_t(y) * s.width + x] += test::rule_covers_pixel(t, x, y);
      }
    }
  }
  return count;
}

Verdict judge(Rule rule, const Scene& s, const Rendered& soft, const Rendered* gl) {
  Verdict v;
  v.mask.assign(size_t(s.width) * s.height, false);
  Oracle o;
  if (rule == Rule::kExactHits || rule == Rule::kHitsOutsideBand || rule == Rule::kOracleOnly ||
      rule == Rule::kColour2 || rule == Rule::kColour4 || rule == Rule::kDepth1 ||
      rule == Rule::kTrilinear) {
    o = oracle(s);
  }
  if (rule == Rule::kLines) o = line_oracle(s);
  std::vector<int> exact;
  if (rule == Rule::kExactHits) exact = fill_rule_counts(s);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      size_t at = size_t(y) * s.width + x;
      bool bad = false;
      int hits = soft.pixel(x, y)[0];
      switch (rule) {
        // Where llvmpipe differs from the exact oracle away from every edge, llvmpipe is wrong
        // (Mesa 22.3.6 drops a whole draw of three triangles when the third is degenerate, a
        // case the grid class found): counted in llvmpipe_wrong, and softrast is held to the
        // oracle there.
        case Rule::kExactHits: {
          // Every sample against the exact rule, ties included; llvmpipe's differences from it
          // are counted (at ties where it drew the scene right, the two agree).
          bad = hits != exact[at];
          v.llvmpipe_wrong += gl->pixel(x, y)[0] != exact[at];
          break;
        }
        case Rule::kHitsOutsideBand: {
          int theirs = gl->pixel(x, y)[0];
          if (o.ambiguous[at]) {
            bad = false;
          } else {
            bad = hits != o.count[at];
            v.llvmpipe_wrong += theirs != o.count[at];
          }
          break;
        }
        case Rule::kOracleOnly:
          bad = !o.ambiguous[at] && hits != o.count[at];
          break;
        case Rule::kLines:
          // softrast against the exact rule; llvmpipe's differences from it are counted (the
          // specification lets an implementation differ from the rule by a pixel at the ends).
          if (o.ambiguous[at]) {
            bad = hits != gl->pixel(x, y)[0];
          } else {
            bad = hits != o.count[at];
            v.llvmpipe_wrong += gl->pixel(x, y)[0] != o.count[at];
          }
          break;
        case Rule::kColour2:
        case Rule::kColour4: {
          int threshold = rule == Rule::kColour2 ? 2 : 4;
          // Where both images show the same triangle, the largest difference at one position.
          if (o.count[at] > 0 && !o.ambiguous[at]) {
            v.max_diff = std::max(v.max_diff, channel_diff(soft, x, y, *gl, x, y));
          }
          // A pixel whose sample lies in the band of an edge belongs to the coverage classes.
          bad = !o.ambiguous[at] && (!close_neighbour(soft, *gl, x, y, threshold) ||
                                     !close_neighbour(*gl, soft, x, y, threshold));
          // Bilinear, one triangle at the sample: where the two differ, softrast within 4/255 of
          // the exact value (double-precision coordinates and filter) is right, and llvmpipe is
          // counted as wrong there.
          if (bad && rule == Rule::kColour4 && s.filter == Filter::kBilinear && o.count[at] == 1) {
            std::array<double, 4> e = exact_bilinear(*s.texture, o.uv[at][0], o.uv[at][1]);
            bool right = true;
            for (int c = 0; c < 4; ++c) {
              right = right && std::abs(soft.pixel(x, y)[c] - e[size_t(c)] * 255.0) <= threshold;
            }
            if (right) {
              bad = false;
              v.llvmpipe_wrong++;
            }
          }
          break;
        }
        case Rule::kTrilinear: {
          // Held to the specification's range (trilinear_allowed); llvmpipe's pixels are judged
          // by the same range (llvmpipe_wrong), and the largest difference between the two
          // images where the oracle is sure of the coverage is reported.
          if (o.count[at] > 0 && !o.ambiguous[at]) {
            v.max_diff = std::max(v.max_diff, channel_diff(soft, x, y, *gl, x, y));
            bad = !trilinear_allowed(s, o.top[at], x, y, soft.pixel(x, y));
            v.llvmpipe_wrong += !trilinear_allowed(s, o.top[at], x, y, gl->pixel(x, y));
          }
          break;
        }
        case Rule::kDepth1: {
          // softrast within one unit of the exact depth (24 bits) wherever the oracle is sure of
          // the coverage; the largest difference to llvmpipe's is reported, and llvmpipe's own
          // error (it interpolates in float: up to 1,110 units measured) in max_other.
          bool both = soft.pixel(x, y)[0] == 255 && gl->pixel(x, y)[0] == 255;
          if (both && !o.ambiguous[at] && o.count[at] > 0) {
            double exact = o.depth[at] * double((1 << 24) - 1);
            v.max_diff = std::max(v.max_diff, int(std::llabs(int64_t(soft.depth_at(x, y)) -
                                                             int64_t(gl->depth_at(x, y)))));
            v.max_other = std::max(v.max_other, std::abs(double(gl->depth_at(x, y)) - exact));
            double error = std::abs(double(soft.depth_at(x, y)) - exact);
            v.max_own = std::max(v.max_own, error);
            bad = error > 1.0;
            v.llvmpipe_wrong += std::abs(double(gl->depth_at(x, y)) - exact) > 1.0;
          }
          break;
        }
      }
      if (bad) {
        v.mask[at] = true;
        v.mismatches++;
      }
    }
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// Saving and shrinking a failure.

Image to_image(const Rendered& r, bool counts) {
  Image image(r.width, r.height);
  for (size_t i = 0; i < size_t(r.width) * r.height; ++i) {
    for (int k = 0; k < 4; ++k) image.rgba[i * 4 + k] = r.rgba[i * 4 + k];
    if (counts) {  // hits 0, 1, 2, 3+ as black, grey, white, red
      int h = r.rgba[i * 4];
      uint8_t g = uint8_t(std::min(h, 2) * 127);
      image.rgba[i * 4] = h >= 3 ? 255 : g;
      image.rgba[i * 4 + 1] = h >= 3 ? 0 : g;
      image.rgba[i * 4 + 2] = h >= 3 ? 0 : g;
    }
    image.rgba[i * 4 + 3] = 255;
  }
  return image;
}

Image mask_image(const Verdict& v, int width, int height) {
  Image image(width, height);
  for (size_t i = 0; i < v.mask.size(); ++i) {
    image.rgba[i * 4] = v.mask[i] ? 255 : 0;
    image.rgba[i * 4 + 3] = 255;
  }
  return image;
}

struct ClassSpec {
  std::string name;
  Rule rule;
  bool against_llvmpipe = true;
  std::function<Scene(std::mt19937_64&)> make;
  bool open = false;  // does not meet its target yet (reported, not asserted)
};

// Renders and judges one scene on its own (softrast's rasterizer `raster`, llvmpipe in a process
// of its own): the number of mismatches.
int mismatches_alone(const ClassSpec& spec, const Scene& s, RasterAlgorithm raster,
                     const fs::path& dir) {
  Rendered soft = draw_softrast(s, raster);
  std::vector<Rendered> gl;
  if (spec.against_llvmpipe) {
    gl = llvmpipe({s}, dir);
    if (gl.empty()) return 0;
  }
  return judge(spec.rule, s, soft, gl.empty() ? nullptr : &gl[0]).mismatches;
}

// Delta debugging (ddmin, complement removal): the smallest set of primitives found that still
// mismatches.
Scene shrink(const ClassSpec& spec, const Scene& s, RasterAlgorithm raster, const fs::path& dir) {
  std::vector<int> keep(size_t(s.primitives()));
  for (size_t i = 0; i < keep.size(); ++i) keep[i] = int(i);
  size_t chunks = 2;
  while (keep.size() > 1) {
    size_t size = (keep.size() + chunks - 1) / chunks;
    bool reduced = false;
    for (size_t start = 0; start < keep.size(); start += size) {
      std::vector<int> rest(keep.begin(), keep.begin() + long(start));
      rest.insert(rest.end(), keep.begin() + long(std::min(keep.size(), start + size)), keep.end());
      if (!rest.empty() && mismatches_alone(spec, s.with(rest), raster, dir) > 0) {
        keep = rest;
        chunks = std::max<size_t>(chunks - 1, 2);
        reduced = true;
        break;
      }
    }
    if (!reduced) {
      if (size == 1) break;
      chunks = std::min(keep.size(), chunks * 2);
    }
  }
  return s.with(keep);
}

void save_failure(const ClassSpec& spec, const Scene& s, const Rendered& soft, const Rendered* gl,
                  const Verdict& v, RasterAlgorithm raster, const fs::path& dir,
                  const std::string& prefix) {
  bool counts = s.mode == Mode::kCount;
  std::ofstream(dir / (prefix + "_scene.txt")) << [&] {
    std::ostringstream text;
    write_scene(text, s);
    return text.str();
  }();
  (void)save_image((dir / (prefix + "_softrast.png")).string(), to_image(soft, counts));
  if (gl) (void)save_image((dir / (prefix + "_llvmpipe.png")).string(), to_image(*gl, counts));
  (void)save_image((dir / (prefix + "_mask.png")).string(), mask_image(v, s.width, s.height));
  if (s.mode == Mode::kDepth && gl) {  // the depths of the mismatching pixels
    std::ofstream depths(dir / (prefix + "_depths.txt"));
    for (int y = 0; y < s.height; ++y) {
      for (int x = 0; x < s.width; ++x) {
        if (v.mask[size_t(y) * s.width + x]) {
          depths << x << ' ' << y << " softrast " << soft.depth_at(x, y) << " llvmpipe "
                 << gl->depth_at(x, y) << '\n';
        }
      }
    }
  }
  Scene small = shrink(spec, s, raster, dir);
  std::ofstream(dir / (prefix + "_shrunk_scene.txt")) << [&] {
    std::ostringstream text;
    write_scene(text, small);
    return text.str();
  }();
  Rendered soft_small = draw_softrast(small, raster);
  (void)save_image((dir / (prefix + "_shrunk_softrast.png")).string(),
                   to_image(soft_small, counts));
  if (spec.against_llvmpipe) {
    std::vector<Rendered> gl_small = llvmpipe({small}, dir);
    if (!gl_small.empty()) {
      (void)save_image((dir / (prefix + "_shrunk_llvmpipe.png")).string(),
                       to_image(gl_small[0], counts));
      Verdict vs = judge(spec.rule, small, soft_small, &gl_small[0]);
      (void)save_image((dir / (prefix + "_shrunk_mask.png")).string(),
                       mask_image(vs, small.width, small.height));
    }
  }
  std::ostringstream message;
  message << spec.name << ": " << v.mismatches << " mismatching pixels ("
          << (raster == RasterAlgorithm::kScanline ? "scanline" : "edge equations")
          << "); scene, images and mask in " << (dir / prefix).string() << "_*; shrunk from "
          << s.primitives() << " to " << small.primitives() << " primitives (" << prefix
          << "_shrunk_*)";
  if (spec.open && !std::getenv("SOFTRAST_CONFORMANCE_ALL")) {
    std::printf("%s\n", message.str().c_str());
  } else {
    ADD_FAILURE() << message.str();
  }
}

int cases_per_class(int normal) {
  const char* text = std::getenv("SOFTRAST_CONFORMANCE_CASES");
  if (!text) return normal;
  return std::max(1, std::atoi(text));
}

// Runs `count` cases of a class in batches, each batch through one llvmpipe process.
void run_class(const ClassSpec& spec, int normal_count) {
  int count = cases_per_class(normal_count);
  std::string pattern = (fs::temp_directory_path() / "softrast_conformance_XXXXXX").string();
  ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
  fs::path dir = pattern;
  std::mt19937_64 rng(0x5eed0000u + std::hash<std::string>{}(spec.name) % 1000);
  constexpr int kBatch = 2000;
  long mismatches = 0, pixels = 0;
  int saved = 0, max_diff = 0;
  double max_own = 0.0, max_other = 0.0;
  long llvmpipe_wrong = 0;
  auto start = std::chrono::steady_clock::now();
  for (int done = 0; done < count; done += kBatch) {
    std::vector<Scene> scenes;
    for (int i = done; i < std::min(count, done + kBatch); ++i) scenes.push_back(spec.make(rng));
    std::vector<Rendered> gl;
    if (spec.against_llvmpipe) {
      gl = llvmpipe(scenes, dir);
      ASSERT_EQ(gl.size(), scenes.size());
    }
    for (size_t i = 0; i < scenes.size(); ++i) {
      const Scene& s = scenes[i];
      pixels += long(s.width) * s.height;
      for (RasterAlgorithm raster : {RasterAlgorithm::kEdgeEquations, RasterAlgorithm::kScanline}) {
        Rendered soft = draw_softrast(s, raster);
        const Rendered* g = spec.against_llvmpipe ? &gl[i] : nullptr;
        Verdict v = judge(spec.rule, s, soft, g);
        max_diff = std::max(max_diff, v.max_diff);
        max_own = std::max(max_own, v.max_own);
        llvmpipe_wrong += v.llvmpipe_wrong;
        max_other = std::max(max_other, v.max_other);
        mismatches += v.mismatches;
        if (v.mismatches > 0 && saved < 3) {
          save_failure(spec, s, soft, g, v, raster, dir,
                       spec.name + "_" + std::to_string(done + int(i)));
          ++saved;
        }
      }
    }
  }
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "conformance %-14s %7d cases, %ld pixels x 2 rasterizers, %ld mismatches, max "
      "difference %d, %.1f s\n",
      spec.name.c_str(), count, pixels, mismatches, max_diff, seconds);
  if (llvmpipe_wrong > 0) {
    std::printf(
        "conformance %-14s llvmpipe fails the same rule against the exact oracle at %ld pixels "
        "(counted "
        "twice, once per softrast rasterizer)\n",
        spec.name.c_str(), llvmpipe_wrong);
  }
  if (spec.rule == Rule::kDepth1) {
    std::printf(
        "conformance %-14s largest error against the exact depth: softrast %.2f, llvmpipe "
        "%.2f units of 2^-24\n",
        spec.name.c_str(), max_own, max_other);
  }
  testing::Test::RecordProperty("cases", count);
  testing::Test::RecordProperty("mismatches", int(mismatches));
  if (spec.open || std::getenv("SOFTRAST_CONFORMANCE_ALL")) {
    // An open class (see the README's table): its figures are printed and its failures saved,
    // but it fails the run only with SOFTRAST_CONFORMANCE_ALL=1 until it meets its target.
    if (spec.open && !std::getenv("SOFTRAST_CONFORMANCE_ALL")) {
      std::printf("conformance %-14s OPEN: %ld mismatches (target 0), cases kept in %s\n",
                  spec.name.c_str(), mismatches, dir.string().c_str());
      return;
    }
  }
  EXPECT_EQ(mismatches, 0) << spec.name;
  if (saved == 0) fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Scene makers.

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniform_int(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

// A vertex at window position (x, y) (pixels, y down) with NDC depth z and clip w.
Vertex at_window(const Scene& s, double x, double y, double z, double w) {
  Vertex v;
  v.x = float((2.0 * x / s.width - 1.0) * w);
  v.y = float((1.0 - 2.0 * y / s.height) * w);
  v.z = float(z * w);
  v.w = float(w);
  return v;
}

// Grid vertices: 1/256 steps inside the image, half of them on pixel centres or corners, and a
// pool shared between triangles so that shared edges and vertices are common; w a power of two
// (every product exact).
Scene grid_scene(std::mt19937_64& rng, Mode mode) {
  Scene s;
  s.width = s.height = 64;
  s.mode = mode;
  std::vector<std::array<int, 2>> pool;
  int n = uniform_int(rng, 1, 8);
  for (int i = 0; i < n + 3; ++i) {
    int x = uniform_int(rng, 0, 64 * 256), y = uniform_int(rng, 0, 64 * 256);
    if (uniform_int(rng, 0, 1)) x = x / 128 * 128, y = y / 128 * 128;
    pool.push_back({x, y});
  }
  static constexpr double kW[] = {0.25, 0.5, 1.0, 2.0, 4.0};
  for (int t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) {
      const auto& p = pool[size_t(uniform_int(rng, 0, int(pool.size()) - 1))];
      double z = std::ldexp(double(uniform_int(rng, -1000, 1000)), -10);
      Vertex v = at_window(s, p[0] / 256.0, p[1] / 256.0, z, kW[uniform_int(rng, 0, 4)]);
      s.vertices.push_back(v);
    }
  }
  return s;
}

Vertex random_colour(Vertex v, std::mt19937_64& rng) {
  v.r = float(uniform(rng, 0, 1)), v.g = float(uniform(rng, 0, 1));
  v.b = float(uniform(rng, 0, 1)), v.a = float(uniform(rng, 0, 1));
  return v;
}

// Float vertices in and a little beyond the image, w in [0.1, 4], z inside the clip volume.
Scene float_scene(std::mt19937_64& rng, Mode mode, int max_triangles) {
  Scene s;
  s.width = uniform_int(rng, 16, 64);
  s.height = uniform_int(rng, 16, 64);
  s.mode = mode;
  int n = uniform_int(rng, 1, max_triangles);
  for (int i = 0; i < 3 * n; ++i) {
    Vertex v = at_window(s, uniform(rng, -0.1, 1.1) * s.width, uniform(rng, -0.1, 1.1) * s.height,
                         uniform(rng, -0.99, 0.99), uniform(rng, 0.1, 4.0));
    s.vertices.push_back(random_colour(v, rng));
  }
  return s;
}

// Large clip coordinates: |x|, |y| up to `limit` * w (log-uniform), z often beyond near or far,
// w of either sign now and then.
Scene clip_scene(std::mt19937_64& rng, double limit) {
  Scene s;
  s.width = uniform_int(rng, 16, 64);
  s.height = uniform_int(rng, 16, 64);
  int n = uniform_int(rng, 1, 4);
  for (int i = 0; i < 3 * n; ++i) {
    double w = uniform(rng, 0.1, 4.0) * (uniform_int(rng, 0, 9) == 0 ? -1.0 : 1.0);
    auto coordinate = [&] {
      double magnitude = uniform_int(rng, 0, 2) == 0
                             ? uniform(rng, 0.0, 1.5)
                             : std::pow(10.0, uniform(rng, 0.0, std::log10(limit)));
      return (uniform_int(rng, 0, 1) ? 1.0 : -1.0) * magnitude * w;
    };
    Vertex v;
    v.x = float(coordinate());
    v.y = float(coordinate());
    v.z = float(uniform(rng, -1.5, 1.5) * w);
    v.w = float(w);
    s.vertices.push_back(v);
  }
  return s;
}

// A random texture: blocks of random colour of a random size (1 to 8 texels), so contrast
// appears at every scale, over 2^k x 2^m texels.
std::shared_ptr<Texture> random_texture(std::mt19937_64& rng) {
  int w = 1 << uniform_int(rng, 2, 6), h = 1 << uniform_int(rng, 2, 6);
  int block = 1 << uniform_int(rng, 0, 3);
  Image image(w, h);
  std::vector<std::array<uint8_t, 4>> colours(size_t(w / std::min(w, block) + 1) *
                                              (h / std::min(h, block) + 1));
  for (auto& c : colours) {
    for (auto& ch : c) ch = uint8_t(uniform_int(rng, 0, 255));
  }
  int per_row = w / std::min(w, block) + 1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto& c = colours[size_t(y / block) * per_row + x / block];
      std::copy(c.begin(), c.end(), image.pixel(x, y));
    }
  }
  return std::make_shared<Texture>(Texture::from_image(image));
}

Scene texture_scene(std::mt19937_64& rng, Filter filter) {
  Scene s = float_scene(rng, Mode::kTexture, 2);
  s.filter = filter;
  s.texture = random_texture(rng);
  double scale = std::pow(2.0, uniform(rng, -2.0, 3.0));  // magnified to minified
  double u0 = uniform(rng, -2, 2), v0 = uniform(rng, -2, 2);
  for (Vertex& v : s.vertices) {
    v.u = float(u0 + scale * uniform(rng, 0, 1));
    v.v = float(v0 + scale * uniform(rng, 0, 1));
  }
  return s;
}

Scene line_scene(std::mt19937_64& rng) {
  Scene s;
  s.width = s.height = 64;
  s.lines = true;
  int n = uniform_int(rng, 1, 8);
  for (int i = 0; i < 2 * n; ++i) {
    int x = uniform_int(rng, 0, 64 * 256), y = uniform_int(rng, 0, 64 * 256);
    if (uniform_int(rng, 0, 1)) x = x / 128 * 128, y = y / 128 * 128;
    s.vertices.push_back(at_window(s, x / 256.0, y / 256.0, 0.0, 1.0));
  }
  return s;
}

TEST(Conformance, GridCoverageExact) {
  run_class({"grid", Rule::kExactHits, true, [](auto& r) { return grid_scene(r, Mode::kCount); }},
            300);
}

TEST(Conformance, FloatPerspectiveCoverageOutsideBand) {
  run_class({"float", Rule::kHitsOutsideBand, true,
             [](auto& r) { return float_scene(r, Mode::kCount, 6); }},
            300);
}

TEST(Conformance, InterpolatedColourWithin2) {
  run_class(
      {"colour", Rule::kColour2, true, [](auto& r) { return float_scene(r, Mode::kColour, 3); }},
      200);
}

TEST(Conformance, BilinearTexturesWithin4) {
  run_class({"bilinear", Rule::kColour4, true,
             [](auto& r) { return texture_scene(r, Filter::kBilinear); }},
            200);
}

TEST(Conformance, TrilinearTexturesWithin4) {
  run_class({"trilinear", Rule::kTrilinear, true,
             [](auto& r) { return texture_scene(r, Filter::kTrilinear); }},
            200);
}

TEST(Conformance, DepthWithinOneUnitOf24Bits) {
  run_class({"depth", Rule::kDepth1, true, [](auto& r) { return grid_scene(r, Mode::kDepth); }},
            200);
}

TEST(Conformance, ClippingUpTo1e6W) {
  run_class({"clip", Rule::kHitsOutsideBand, true, [](auto& r) { return clip_scene(r, 1e6); }},
            300);
}

TEST(Conformance, ClippingBeyond1e6WAgainstTheOracle) {
  run_class({"clip_oracle", Rule::kOracleOnly, false, [](auto& r) { return clip_scene(r, 1e30); }},
            300);
}

TEST(Conformance, LinesDiamondExit) {
  run_class({"lines", Rule::kLines, true, [](auto& r) { return line_scene(r); }}, 300);
}

}  // namespace
}  // namespace softrast

#else
TEST(Conformance, SkippedWithoutTheReferenceRenderer) {
  GTEST_SKIP() << "built without glconform (tools/reference, needs libosmesa6-dev)";
}
#endif
