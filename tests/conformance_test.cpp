// tests/conformance_test.cpp: conformance classes against Mesa's llvmpipe, dEQP style. Random
// scenes of each class are drawn by softrast (in this process, both rasterizers, the binned
// path) and by llvmpipe (tools/reference/glconform: every case of a class in one process), and
// compared by the class's rule:
//   1. grid: vertices on the 1/256-pixel grid (exact in float, w a power of two): the number
//      of hits of every pixel is identical.
//   2. float: float vertices with perspective (w in [0.1, 4]): no pixel differs in hits outside
//      a band of +-1/256 pixel around the edges (the exact edges, computed in double).
//   3. colour: interpolated colour within 2/255 of a pixel of the other image within one pixel
//      (dEQP's position-deviation compare, both ways).
//   4. texture: bilinear and trilinear (the same mip chain uploaded to both) within 4/255, the
//      same compare.
//   5. depth: with a 24-bit depth buffer, every pixel drawn in both images has depths within one
//      unit (softrast's float depth rounded to 24 bits).
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

#include "shaders/builtin_shaders.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/shader.hpp"
#include "softrast/texture.hpp"

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
      for (int k = 0; k < per_primitive(); ++k) s.vertices.push_back(vertices[p * per_primitive() + k]);
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
        simd::Vec4<N> t = detail::sample_with_derivatives(*texture, sampler, f, 4);
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
// The double-precision oracle: each triangle clipped against the near and far planes in
// homogeneous coordinates, projected in double; a sample is covered when it lies strictly inside
// the projected polygon, and ambiguous when it lies within the band of one of its edges.

constexpr double kBand = 1.0 / 256.0;

struct Polygon {
  std::vector<std::array<double, 2>> points;  // window coordinates, y down
};

Polygon project_clipped(const Scene& s, int t) {
  using V4 = std::array<double, 4>;
  std::vector<V4> poly;
  for (int k = 0; k < 3; ++k) {
    const Vertex& v = s.vertices[3 * t + k];
    poly.push_back({v.x, v.y, v.z, v.w});
  }
  // Planes as distance functions: z + w >= 0, w - z >= 0, and w > tiny (only cuts what the
  // others leave at w <= 0, a degenerate point).
  auto clip = [&](auto dist) {
    std::vector<V4> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      const V4& a = poly[i];
      const V4& b = poly[(i + 1) % poly.size()];
      double da = dist(a), db = dist(b);
      if (da >= 0) out.push_back(a);
      if ((da >= 0) != (db >= 0)) {
        double t = da / (da - db);
        V4 p;
        for (int k = 0; k < 4; ++k) p[k] = a[k] + t * (b[k] - a[k]);
        out.push_back(p);
      }
    }
    poly = out;
  };
  clip([](const V4& p) { return p[2] + p[3]; });
  clip([](const V4& p) { return p[3] - p[2]; });
  clip([](const V4& p) { return p[3] - 1e-300; });
  Polygon result;
  for (const V4& p : poly) {
    result.points.push_back(
        {(p[0] / p[3] + 1.0) * 0.5 * s.width, (1.0 - p[1] / p[3]) * 0.5 * s.height});
  }
  return result;
}

// Per pixel: the oracle's count and whether the sample is within the band of an edge.
struct Oracle {
  std::vector<int> count;
  std::vector<bool> ambiguous;
};

Oracle oracle(const Scene& s) {
  Oracle o;
  size_t n = size_t(s.width) * s.height;
  o.count.assign(n, 0);
  o.ambiguous.assign(n, false);
  for (int t = 0; t < s.primitives(); ++t) {
    Polygon p = project_clipped(s, t);
    size_t m = p.points.size();
    if (m < 3) continue;
    double area = 0.0;
    for (size_t i = 0; i < m; ++i) {
      const auto& a = p.points[i];
      const auto& b = p.points[(i + 1) % m];
      area += a[0] * b[1] - a[1] * b[0];
    }
    if (!(std::abs(area) > 0.0)) continue;  // degenerate (or NaN): nothing is drawn
    double sign = area > 0 ? 1.0 : -1.0;
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const auto& q : p.points) {
      x0 = std::min(x0, q[0]), x1 = std::max(x1, q[0]);
      y0 = std::min(y0, q[1]), y1 = std::max(y1, q[1]);
    }
    int px0 = int(std::clamp(std::floor(x0 - 1), 0.0, double(s.width)));
    int px1 = int(std::clamp(std::ceil(x1 + 1), 0.0, double(s.width)));
    int py0 = int(std::clamp(std::floor(y0 - 1), 0.0, double(s.height)));
    int py1 = int(std::clamp(std::ceil(y1 + 1), 0.0, double(s.height)));
    for (int py = py0; py < py1; ++py) {
      for (int px = px0; px < px1; ++px) {
        double sx = px + 0.5, sy = py + 0.5;
        bool inside = true, near = false;
        for (size_t i = 0; i < m; ++i) {
          const auto& a = p.points[i];
          const auto& b = p.points[(i + 1) % m];
          double ex = b[0] - a[0], ey = b[1] - a[1];
          double len2 = ex * ex + ey * ey;
          double cross = ex * (sy - a[1]) - ey * (sx - a[0]);
          if (cross * sign <= 0) inside = false;
          // Distance to the segment.
          double t = len2 > 0 ? std::clamp(((sx - a[0]) * ex + (sy - a[1]) * ey) / len2, 0.0, 1.0)
                              : 0.0;
          double dx = sx - (a[0] + t * ex), dy = sy - (a[1] + t * ey);
          if (dx * dx + dy * dy <= kBand * kBand) near = true;
        }
        size_t at = size_t(py) * s.width + px;
        if (near) o.ambiguous[at] = true;
        if (inside) o.count[at]++;
      }
    }
  }
  return o;
}

// ---------------------------------------------------------------------------------------------
// Lines: the diamond-exit rule by brute force, in double. A pixel is drawn when the segment
// passes through the inside of its diamond |x - cx| + |y - cy| < 1/2 and its end does not lie in
// that diamond. Ties (the segment or an end within 1e-9 of a diamond's boundary) are ambiguous.

bool segment_meets_open_diamond(double x0, double y0, double x1, double y1, double cx, double cy,
                                bool& tie) {
  // The diamond is convex: the segment meets its inside when the minimum of |x-cx|+|y-cy| over
  // the segment is below 1/2. That function is piecewise linear in t: check the ends and the
  // points where x = cx or y = cy.
  double best = 1e300;
  auto at = [&](double t) {
    double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
    best = std::min(best, std::abs(x - cx) + std::abs(y - cy));
  };
  at(0.0);
  at(1.0);
  if (x1 != x0) {
    double t = (cx - x0) / (x1 - x0);
    if (t > 0 && t < 1) at(t);
  }
  if (y1 != y0) {
    double t = (cy - y0) / (y1 - y0);
    if (t > 0 && t < 1) at(t);
  }
  if (std::abs(best - 0.5) < 1e-9) tie = true;
  return best < 0.5;
}

Oracle line_oracle(const Scene& s) {
  Oracle o;
  size_t n = size_t(s.width) * s.height;
  o.count.assign(n, 0);
  o.ambiguous.assign(n, false);
  for (int l = 0; l < s.primitives(); ++l) {
    const Vertex& a = s.vertices[2 * l];
    const Vertex& b = s.vertices[2 * l + 1];
    double x0 = (double(a.x) / a.w + 1) * 0.5 * s.width, y0 = (1 - double(a.y) / a.w) * 0.5 * s.height;
    double x1 = (double(b.x) / b.w + 1) * 0.5 * s.width, y1 = (1 - double(b.y) / b.w) * 0.5 * s.height;
    for (int py = 0; py < s.height; ++py) {
      for (int px = 0; px < s.width; ++px) {
        double cx = px + 0.5, cy = py + 0.5;
        bool tie = false;
        bool meets = segment_meets_open_diamond(x0, y0, x1, y1, cx, cy, tie);
        double end = std::abs(x1 - cx) + std::abs(y1 - cy);
        if (std::abs(end - 0.5) < 1e-9) tie = true;
        size_t at = size_t(py) * s.width + px;
        if (tie) o.ambiguous[at] = true;
        if (meets && end >= 0.5) o.count[at]++;
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

enum class Rule { kExactHits, kHitsOutsideBand, kColour2, kColour4, kDepth1, kOracleOnly, kLines };

struct Verdict {
  int mismatches = 0;
  std::vector<bool> mask;
  int max_diff = 0;  // colour classes: largest channel difference at one position; depth: units
};

Verdict judge(Rule rule, const Scene& s, const Rendered& soft, const Rendered* gl) {
  Verdict v;
  v.mask.assign(size_t(s.width) * s.height, false);
  Oracle o;
  if (rule == Rule::kHitsOutsideBand || rule == Rule::kOracleOnly) o = oracle(s);
  if (rule == Rule::kLines) o = line_oracle(s);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      size_t at = size_t(y) * s.width + x;
      bool bad = false;
      int hits = soft.pixel(x, y)[0];
      switch (rule) {
        case Rule::kExactHits:
          bad = hits != gl->pixel(x, y)[0];
          break;
        case Rule::kHitsOutsideBand:
          bad = !o.ambiguous[at] && (hits != gl->pixel(x, y)[0] || hits != o.count[at]);
          break;
        case Rule::kOracleOnly:
          bad = !o.ambiguous[at] && hits != o.count[at];
          break;
        case Rule::kLines:
          bad = hits != gl->pixel(x, y)[0] || (!o.ambiguous[at] && hits != o.count[at]);
          break;
        case Rule::kColour2:
        case Rule::kColour4: {
          int threshold = rule == Rule::kColour2 ? 2 : 4;
          v.max_diff = std::max(v.max_diff, channel_diff(soft, x, y, *gl, x, y));
          bad = !close_neighbour(soft, *gl, x, y, threshold) ||
                !close_neighbour(*gl, soft, x, y, threshold);
          break;
        }
        case Rule::kDepth1: {
          bool both = soft.pixel(x, y)[0] == 255 && gl->pixel(x, y)[0] == 255;
          if (both) {
            int d = int(std::llabs(int64_t(soft.depth_at(x, y)) - int64_t(gl->depth_at(x, y))));
            v.max_diff = std::max(v.max_diff, d);
            bad = d > 1;
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
  ADD_FAILURE() << spec.name << ": " << v.mismatches << " mismatching pixels ("
                << (raster == RasterAlgorithm::kScanline ? "scanline" : "edge equations")
                << "); scene, images and mask in " << (dir / prefix).string()
                << "_*; shrunk from " << s.primitives() << " to " << small.primitives()
                << " primitives (" << prefix << "_shrunk_*)";
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
        mismatches += v.mismatches;
        if (v.mismatches > 0 && saved < 3) {
          save_failure(spec, s, soft, g, v, raster, dir,
                       spec.name + "_" + std::to_string(done + int(i)));
          ++saved;
        }
      }
    }
  }
  double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("conformance %-14s %7d cases, %ld pixels x 2 rasterizers, %ld mismatches, max "
              "difference %d, %.1f s\n",
              spec.name.c_str(), count, pixels, mismatches, max_diff, seconds);
  testing::Test::RecordProperty("cases", count);
  testing::Test::RecordProperty("mismatches", int(mismatches));
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
      double magnitude = uniform_int(rng, 0, 2) == 0 ? uniform(rng, 0.0, 1.5)
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

Scene texture_scene(std::mt19937_64& rng) {
  Scene s = float_scene(rng, Mode::kTexture, 2);
  s.filter = uniform_int(rng, 0, 1) ? Filter::kTrilinear : Filter::kBilinear;
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
  run_class({"colour", Rule::kColour2, true,
             [](auto& r) { return float_scene(r, Mode::kColour, 3); }},
            200);
}

TEST(Conformance, BilinearAndTrilinearTexturesWithin4) {
  run_class({"texture", Rule::kColour4, true, [](auto& r) { return texture_scene(r); }}, 200);
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
