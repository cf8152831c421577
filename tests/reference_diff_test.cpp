// tests/reference_diff_test.cpp: differential tests against the reference renderer. The same
// scenes (OBJ files and a texture written here) go through `softrast render` and through glref
// (tools/reference: OpenGL on Mesa's llvmpipe, the renderer softrast is judged against), and
// the two images are compared. Built only with -DSOFTRAST_BUILD_REFERENCE=ON; else one skipped
// test says so.
//
// Exact agreement where rounding cannot differ: with vertices on the 1/256-pixel grid, inside the
// viewport, and an orthographic camera whose every product is exact, the number of times each
// pixel is hit (counted with additive blending) must be identical, for every cull mode.
//
// Elsewhere the comparison follows dEQP's position-deviation compare (tcuImageCompare's
// intThresholdPositionDeviationCompare): a pixel matches when some pixel of the other image
// within its 3x3 neighbourhood is within a per-channel threshold, checked in both directions;
// at most kMaxMismatchFraction of the pixels may fail, and only a few may differ in coverage.
// The thresholds:
//  - 3/255 for flat, gouraud and normals: llvmpipe converts to unorm8 rounding half to even where
//    softrast rounds half up (1 step on exact ties, see ColourConversionDiffersOnlyOnTies)
//    and interpolates with its own planes and reciprocal (1 step); one step of margin.
//  - 8/255 for texture and phong: llvmpipe samples RGBA8 textures on its 8-bit path, with the
//    bilinear weights quantised to 1/256 and the lerps done in 8.8 fixed point (up to
//    contrast / 512 + 1 step per lerp, 3 lerps: about 3 steps for the checker's contrast of 200;
//    5 measured), and phong's normalize() and pow() go through approximations.
// The 3x3 neighbourhood absorbs edges that move because a vertex snapped differently.
//
// Differences that are llvmpipe's and not errors (each explained by a test or a scene here):
//  - llvmpipe has no guard band: it clips every triangle that crosses the viewport, in float, and
//    the cut edges move by up to about 1/256 pixel (TrianglesCrossingTheBorder...).
//  - llvmpipe computes the viewport transform in float (softrast in double), so a vertex close to
//    a 1/512 tie can snap to the other 1/256 step; samples within ~0.001 pixel of its edges flip.
//  - llvmpipe derives the depth plane from the unsnapped vertices, coverage from the snapped
//    ones: where a silhouette folds, a sample just outside the exact edge but inside the snapped
//    one can show the back face (cube_cull_none, one pixel).
// Differences where softrast follows CONVENTIONS.md and llvmpipe (behind OSMesa) does otherwise,
// pinned so that nothing else can hide behind them:
//  - the fill rule's tie-break on horizontal edges (HorizontalEdgeTiesAreTheOnlyFillRuleDifference)
//  - rounding of ties in the float to unorm8 conversion (ColourConversionDiffersOnlyOnTies)
//
// On failure (or with SOFTRAST_KEEP_REFERENCE_IMAGES=1) the scenes and images (NAME_softrast.png,
// NAME_llvmpipe.png, NAME_diff.png: red = mismatch, yellow = coverage differs, grey = different
// within tolerance) stay in the temporary folder whose path is printed.
#include <gtest/gtest.h>

#include <numeric>

#if defined(SOFTRAST_CLI_PATH) && defined(SOFTRAST_GLREF_PATH)

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxMismatchFraction = 0.001;
constexpr int kFlatThreshold = 3;
constexpr int kTextureThreshold = 8;
constexpr int kClear = 26;  // the clear colour 0.1 as unorm8, in both

// ---------------------------------------------------------------------------------------------
// Comparing two images.

int channel_diff(const Image& a, int ax, int ay, const Image& b, int bx, int by) {
  const uint8_t* p = a.pixel(ax, ay);
  const uint8_t* q = b.pixel(bx, by);
  int worst = 0;
  for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(int(p[c]) - int(q[c])));
  return worst;
}

// Whether pixel (x, y) of `a` is within `threshold` of some pixel of `b` in its 3x3 neighbourhood.
bool has_close_neighbour(const Image& a, const Image& b, int x, int y, int threshold) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      int bx = x + dx, by = y + dy;
      if (bx < 0 || by < 0 || bx >= b.width || by >= b.height) continue;
      if (channel_diff(a, x, y, b, bx, by) <= threshold) return true;
    }
  }
  return false;
}

bool is_background(const Image& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  return p[0] == kClear && p[1] == kClear && p[2] == kClear && p[3] == 255;
}

struct Comparison {
  int pixels = 0;
  int differing = 0;       // not identical
  int mismatches = 0;      // no close neighbour, in either direction
  int coverage_diffs = 0;  // background in one image only
  int max_diff = 0;        // largest channel difference at the same position
  Image diff;
  std::string examples;  // the first few mismatches
  double mismatch_fraction() const { return double(mismatches) / pixels; }
};

Comparison compare(const Image& soft, const Image& gl, int threshold) {
  Comparison c;
  c.pixels = soft.width * soft.height;
  c.diff = Image(soft.width, soft.height);
  for (int y = 0; y < soft.height; ++y) {
    for (int x = 0; x < soft.width; ++x) {
      int d = channel_diff(soft, x, y, gl, x, y);
      bool mismatch = !has_close_neighbour(soft, gl, x, y, threshold) ||
                      !has_close_neighbour(gl, soft, x, y, threshold);
      bool coverage = is_background(soft, x, y) != is_background(gl, x, y);
      c.max_diff = std::max(c.max_diff, d);
      c.differing += d > 0;
      c.mismatches += mismatch;
      c.coverage_diffs += coverage;
      uint8_t* out = c.diff.pixel(x, y);
      const uint8_t* s = soft.pixel(x, y);
      const uint8_t* g = gl.pixel(x, y);
      std::array<uint8_t, 3> colour = {uint8_t(s[0] / 4), uint8_t(s[1] / 4), uint8_t(s[2] / 4)};
      if (d > 0) colour = {96, 96, 96};
      if (coverage) colour = {255, 255, 0};
      if (mismatch) colour = {255, 0, 0};
      std::copy(colour.begin(), colour.end(), out);
      out[3] = 255;
      if ((mismatch || coverage) && c.examples.size() < 800) {
        char line[160];
        std::snprintf(line, sizeof line, "  (%d, %d): softrast %d,%d,%d,%d llvmpipe %d,%d,%d,%d\n",
                      x, y, s[0], s[1], s[2], s[3], g[0], g[1], g[2], g[3]);
        c.examples += line;
      }
    }
  }
  return c;
}

std::string summary(const Comparison& c) {
  std::ostringstream s;
  s << c.mismatches << " mismatches (" << 100.0 * c.mismatch_fraction() << " %), " << c.differing
    << " pixels differ, " << c.coverage_diffs << " differ in coverage, max channel difference "
    << c.max_diff << " of " << c.pixels << " pixels";
  return s.str();
}

// ---------------------------------------------------------------------------------------------
// Scenes as OBJ text.

// Exact decimal text for floats (max_digits10): the OBJ reader sees the same float in both.
std::string num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", float(v));
  return text;
}

class ObjWriter {
 public:
  int vertex(glm::dvec3 p) {
    text_ << "v " << num(p.x) << ' ' << num(p.y) << ' ' << num(p.z) << '\n';
    return ++positions_;
  }
  int uv(glm::dvec2 t) {
    text_ << "vt " << num(t.x) << ' ' << num(t.y) << '\n';
    return ++uvs_;
  }
  int normal(glm::dvec3 n) {
    text_ << "vn " << num(n.x) << ' ' << num(n.y) << ' ' << num(n.z) << '\n';
    return ++normals_;
  }
  // A face of corners "v", "v/vt", "v//vn" or "v/vt/vn" (0 for absent).
  void face(const std::vector<std::array<int, 3>>& corners) {
    text_ << 'f';
    for (const auto& [v, vt, vn] : corners) {
      text_ << ' ' << v;
      if (vt || vn) text_ << '/' << (vt ? std::to_string(vt) : "");
      if (vn) text_ << '/' << vn;
    }
    text_ << '\n';
  }
  void triangle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    face({{vertex(a), 0, 0}, {vertex(b), 0, 0}, {vertex(c), 0, 0}});
  }
  std::string str() const { return text_.str(); }

 private:
  std::ostringstream text_;
  int positions_ = 0, uvs_ = 0, normals_ = 0;
};

// A texture with visible orientation: 8 x 8 squares, light ones grey, dark ones tinted by their
// column (red) and row (green), like the benchmark's checker.png.
Image checker_texture(int size) {
  Image image(size, size);
  int square = size / 8;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      int i = x / square, j = y / square;
      uint8_t* p = image.pixel(x, y);
      bool light = (i + j) % 2 == 0;
      p[0] = light ? 235 : uint8_t(40 + 25 * i);
      p[1] = light ? 235 : uint8_t(40 + 25 * j);
      p[2] = light ? 235 : 120;
      p[3] = 255;
    }
  }
  return image;
}

// A grid of quads in the plane y = 0, x in [-w, w], z in [-d, 0], uv = (x, -z) / 4.
std::string quad_grid_obj(double w, double d, int nx, int nz) {
  ObjWriter obj;
  std::vector<int> vs;
  for (int j = 0; j <= nz; ++j) {
    for (int i = 0; i <= nx; ++i) {
      double x = -w + 2.0 * w * i / nx, z = -d * j / nz;
      int v = obj.vertex({x, 0.0, z});
      obj.uv({x / 4.0, -z / 4.0});
      vs.push_back(v);
    }
  }
  int n = obj.normal({0.0, 1.0, 0.0});
  auto at = [&](int i, int j) { return vs[size_t(j) * (nx + 1) + i]; };
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      // Counter-clockwise seen from above (+y): (i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)
      // where j grows towards -z.
      int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), e = at(i, j + 1);
      obj.face({{a, a, n}, {b, b, n}, {c, c, n}, {e, e, n}});
    }
  }
  return obj.str();
}

// UV spheres (normals and uvs as the benchmark's) on a rows x cols grid in the z = 0 plane.
std::string spheres_obj(int cols, int rows, int slices, int stacks, double radius) {
  ObjWriter obj;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      glm::dvec3 centre((c - (cols - 1) / 2.0), (r - (rows - 1) / 2.0), 0.0);
      std::vector<int> idx;
      for (int i = 0; i <= stacks; ++i) {
        double th = std::numbers::pi * i / stacks;
        for (int j = 0; j <= slices; ++j) {
          double ph = 2.0 * std::numbers::pi * j / slices;
          glm::dvec3 n(std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph));
          int v = obj.vertex(centre + radius * n);
          obj.uv({double(j) / slices, 1.0 - double(i) / stacks});
          obj.normal(n);
          idx.push_back(v);
        }
      }
      auto at = [&](int i, int j) { return idx[size_t(i) * (slices + 1) + j]; };
      for (int i = 0; i < stacks; ++i) {
        for (int j = 0; j < slices; ++j) {
          int a = at(i, j), b = at(i + 1, j), c2 = at(i + 1, j + 1), d = at(i, j + 1);
          if (i != 0) obj.face({{a, a, a}, {b, b, b}, {d, d, d}});
          if (i != stacks - 1) obj.face({{b, b, b}, {c2, c2, c2}, {d, d, d}});
        }
      }
    }
  }
  return obj.str();
}

// A unit cube at the origin, outward faces counter-clockwise, one normal per face.
std::string cube_obj() {
  ObjWriter obj;
  for (int i = 0; i < 8; ++i)
    obj.vertex({i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0});
  // Corners of each face counter-clockwise seen from outside, with the face normal.
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  const glm::dvec3 normals[6] = {{-1, 0, 0}, {1, 0, 0},  {0, -1, 0},
                                 {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    int n = obj.normal(normals[f]);
    std::vector<std::array<int, 3>> corners;
    for (int k : faces[f]) corners.push_back({k + 1, 0, n});
    obj.face(corners);
  }
  return obj.str();
}

// ---------------------------------------------------------------------------------------------
// Running both programs.

std::string quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ReferenceDiffTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_reference_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    if (HasFailure() || std::getenv("SOFTRAST_KEEP_REFERENCE_IMAGES")) {
      std::printf("reference diff: images kept in %s\n", dir_.c_str());
    } else {
      fs::remove_all(dir_);
    }
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  void write_texture(const std::string& name, const Image& image) const {
    ASSERT_TRUE(save_image(path(name), image).ok());
  }

  // Runs one program with `args` in the test folder; the image it wrote, or an empty one.
  // The light is pinned in world space for both (softrast's default headlight follows the
  // camera; the reference's light is fixed, as SCENES.md's command lines pin it).
  Image run(const std::string& program, const std::string& args, const std::string& out) {
    std::string log = path(out + ".log");
    std::string command = "cd " + quote(dir_.string()) + " && " + quote(program) + " " + args +
                          " --light 0.3,0.5,0.8 -q -o " + quote(out) + " >" + quote(log) +
                          " 2>&1 </dev/null";
    int status = std::system(command.c_str());
    bool ok = status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    EXPECT_TRUE(ok) << program << " " << args << "\n" << read_text(log);
    if (!ok) return {};
    Result<Image> image = load_image(path(out));
    EXPECT_TRUE(image.ok()) << image.status().message();
    return image.ok() ? *image : Image();
  }

  // Renders `args` with both programs as <name>_softrast.png and <name>_llvmpipe.png and
  // compares them; the diff image is written as <name>_diff.png.
  Comparison render_both(const std::string& name, const std::string& args, int threshold) {
    Image soft = run(SOFTRAST_CLI_PATH, args, name + "_softrast.png");
    Image gl = run(SOFTRAST_GLREF_PATH, args, name + "_llvmpipe.png");
    Comparison c;
    if (soft.rgba.empty() || gl.rgba.empty()) return c;
    EXPECT_EQ(soft.width, gl.width);
    EXPECT_EQ(soft.height, gl.height);
    if (soft.width != gl.width || soft.height != gl.height) return c;
    c = compare(soft, gl, threshold);
    EXPECT_TRUE(save_image(path(name + "_diff.png"), c.diff).ok());
    std::printf("[ %s ] %s\n", name.c_str(), summary(c).c_str());
    return c;
  }

  // The common check: few pixels without a close match, at most `max_coverage` pixels whose
  // coverage differs.
  void expect_close(const std::string& name, const std::string& args, int threshold,
                    int max_coverage) {
    Comparison c = render_both(name, args, threshold);
    EXPECT_GT(c.pixels, 0);
    EXPECT_LE(c.mismatch_fraction(), kMaxMismatchFraction)
        << name << ": " << summary(c) << "\n"
        << c.examples << "images: " << path(name + "_{softrast,llvmpipe,diff}.png");
    EXPECT_LE(c.coverage_diffs, max_coverage) << name << ": " << summary(c) << "\n" << c.examples;
  }

  fs::path dir_;
};

// ---------------------------------------------------------------------------------------------
// Exact coverage on the 1/256 grid: hit counts with additive blending.

// A triangle in window coordinates (y down), in 1/256 pixel.
struct FxTriangle {
  std::array<int64_t, 3> x{}, y{};
};

// glOrtho(0, W, H, 0) seen from z = 1: world x, y are window x, y (y down), z = 0 is depth 0.5.
// Every product on the way is exact for 1/256-grid coordinates and power-of-two sizes, in float
// and in double, with or without fused multiply-adds: both renderers see the same vertices.
std::string window_camera(int width, int height) {
  return "--size " + std::to_string(width) + "x" + std::to_string(height) + " --ortho 0," +
         std::to_string(width) + "," + std::to_string(height) +
         ",0 --eye 0,0,1 --target 0,0,0 --up 0,1,0 --near 0.5 --far 1.5";
}

// Each fragment adds 1 to red (1/255 is exactly one step in both).
constexpr const char* kCounting =
    " --shader flat --color 0.00392156886,0,0 --blend add --depth off";

std::string window_obj(const std::vector<FxTriangle>& triangles) {
  ObjWriter obj;
  for (const FxTriangle& t : triangles) {
    auto p = [&](int k) { return glm::dvec3(t.x[k] / 256.0, t.y[k] / 256.0, 0.0); };
    obj.triangle(p(0), p(1), p(2));
  }
  return obj.str();
}

// Hits per pixel from a counting render; -1 where the pixel is not a count.
std::vector<int> hit_counts(const Image& image) {
  std::vector<int> counts(size_t(image.width) * image.height);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* p = image.pixel(x, y);
      bool valid = p[1] == kClear && p[2] == kClear && p[0] >= kClear && p[0] < 255;
      counts[size_t(y) * image.width + x] = valid ? p[0] - kClear : -1;
    }
  }
  return counts;
}

// '.' for 0, a digit for 1-9, '#' above, '?' for not a count.
std::string ascii_counts(const std::vector<int>& counts, int width, int x0, int y0, int x1,
                         int y1) {
  std::string s;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      int v = counts[size_t(y) * width + x];
      s += v < 0 ? '?' : v == 0 ? '.' : v > 9 ? '#' : char('0' + v);
    }
    s += '\n';
  }
  return s;
}

class TriangleMaker {
 public:
  TriangleMaker(uint32_t seed, int width, int height) : rng_(seed), w_(width), h_(height) {}

  int64_t uniform(int64_t lo, int64_t hi) {
    return std::uniform_int_distribution<int64_t>(lo, hi)(rng_);
  }
  // Within `r` 1/256 pixels of a random point up to `margin` pixels outside the image.
  FxTriangle around(int64_t r, int margin) {
    int64_t cx = uniform(-margin * 256, (w_ + margin) * 256);
    int64_t cy = uniform(-margin * 256, (h_ + margin) * 256);
    FxTriangle t;
    for (int k = 0; k < 3; ++k) t.x[k] = cx + uniform(-r, r), t.y[k] = cy + uniform(-r, r);
    return t;
  }
  // Nearly collinear: the third vertex within 3/256 pixel of the line through the first two.
  FxTriangle sliver() {
    FxTriangle t = around(40 * 256, 8);
    int64_t s = uniform(-64, 320);
    t.x[2] = t.x[0] + (t.x[1] - t.x[0]) * s / 256 + uniform(-3, 3);
    t.y[2] = t.y[0] + (t.y[1] - t.y[0]) * s / 256 + uniform(-3, 3);
    return t;
  }
  // Vertices on pixel centres.
  FxTriangle centres(int margin) {
    FxTriangle t;
    for (int k = 0; k < 3; ++k) {
      t.x[k] = uniform(-margin, w_ + margin) * 256 + 128;
      t.y[k] = uniform(-margin, h_ + margin) * 256 + 128;
    }
    return t;
  }

 private:
  std::mt19937_64 rng_;
  int w_, h_;
};

// A horizontal edge through a row of samples: the one place where the tie-break of the fill
// rule decides (see HorizontalEdgeTiesAreTheOnlyFillRuleDifference).
bool has_horizontal_edge_on_samples(const FxTriangle& t) {
  for (int i = 0; i < 3; ++i) {
    int j = (i + 1) % 3;
    if (t.y[i] == t.y[j] && t.x[i] != t.x[j] && ((t.y[i] % 256) + 256) % 256 == 128) return true;
  }
  return false;
}

bool inside_viewport(const FxTriangle& t, int width, int height) {
  for (int k = 0; k < 3; ++k) {
    if (t.x[k] < 0 || t.x[k] > width * 256 || t.y[k] < 0 || t.y[k] > height * 256) return false;
  }
  return true;
}

// Random triangles with `inside` (true) or crossing (false) the viewport. Mesa's llvmpipe has no
// guard band: it clips every triangle that crosses the viewport, in float, and the new vertices
// move the cut edges by up to about 1/256 pixel. Triangles inside are drawn as they are.
std::vector<FxTriangle> random_grid_triangles(int width, int height, bool inside) {
  TriangleMaker make(inside ? 20240611 : 1789, width, height);
  std::vector<FxTriangle> out;
  auto add = [&](int count, auto generate) {
    for (int n = 0; n < count;) {
      FxTriangle t = generate();
      if (has_horizontal_edge_on_samples(t) || inside_viewport(t, width, height) != inside) {
        continue;
      }
      out.push_back(t);
      ++n;
    }
  };
  if (!inside) {
    add(100, [&] { return make.around(8 * 256, 8); });
    add(60, [&] { return make.around(60 * 256, 40); });
    add(20, [&] { return make.around(300 * 256, 256); });
    return out;
  }
  add(800, [&] { return make.around(3 * 256, 0); });  // small
  add(800, [&] { return make.around(256, 0); });      // about a pixel
  add(400, [&] { return make.sliver(); });
  add(100, [&] { return make.around(24 * 256, 0); });  // medium
  add(40, [&] { return make.centres(0); });            // large, vertices on pixel centres
  add(40, [&] { return make.around(200 * 256, 0); });  // large, off-centre
  // Right triangles with a vertical edge through a column of samples.
  add(200, [&] {
    FxTriangle t = make.around(12 * 256, 0);
    t.x[1] = t.x[0] = t.x[0] / 256 * 256 + 128;
    return t;
  });
  return out;
}

// Compares two hit-count maps; an empty string when equal, else the first differences and
// pictures of the region around the first one.
std::string count_differences(const std::vector<int>& soft, const std::vector<int>& gl, int width,
                              int height) {
  std::ostringstream s;
  int n = 0, first = -1;
  for (size_t i = 0; i < soft.size(); ++i) {
    if (soft[i] == gl[i]) continue;
    if (first < 0) first = int(i);
    if (++n <= 20) {
      s << "  pixel (" << i % width << ", " << i / width << "): softrast " << soft[i]
        << " hits, llvmpipe " << gl[i] << "\n";
    }
  }
  if (n == 0) return "";
  int fx = first % width, fy = first / width;
  int x0 = std::max(0, fx - 12), x1 = std::min(width, fx + 13);
  int y0 = std::max(0, fy - 6), y1 = std::min(height, fy + 7);
  s << n << " pixels differ; around the first, x " << x0 << ".." << x1 - 1 << ", y " << y0 << ".."
    << y1 - 1 << ":\nsoftrast\n"
    << ascii_counts(soft, width, x0, y0, x1, y1) << "llvmpipe\n"
    << ascii_counts(gl, width, x0, y0, x1, y1);
  return s.str();
}

// Distance in pixels from the sample of pixel (px, py) to the nearest edge line of `triangles`;
// `detail` receives the triangles with an edge within 1/16 pixel, for failure messages.
double nearest_edge(const std::vector<FxTriangle>& triangles, int px, int py, std::string* detail) {
  std::ostringstream s;
  double nearest = 1e30;
  int64_t sx = int64_t(px) * 256 + 128, sy = int64_t(py) * 256 + 128;
  for (size_t n = 0; n < triangles.size(); ++n) {
    const FxTriangle& t = triangles[n];
    for (int i = 0; i < 3; ++i) {
      int j = (i + 1) % 3;
      double dx = double(t.x[j] - t.x[i]), dy = double(t.y[j] - t.y[i]);
      double length = std::hypot(dx, dy);
      if (length == 0.0) continue;
      double distance = std::abs(dx * double(sy - t.y[i]) - dy * double(sx - t.x[i])) / length;
      nearest = std::min(nearest, distance / 256.0);
      if (distance > 16.0) continue;
      s << "    triangle " << n << " (1/256 px): (" << t.x[0] << ", " << t.y[0] << ") (" << t.x[1]
        << ", " << t.y[1] << ") (" << t.x[2] << ", " << t.y[2] << "), edge " << i << " at "
        << distance / 256.0 << " px\n";
    }
  }
  if (detail) *detail += s.str();
  return nearest;
}

// Renders `triangles` (window coordinates) with both programs in counting mode.
struct CountPair {
  std::vector<int> soft, gl;
};

class ReferenceCountTest : public ReferenceDiffTest {
 protected:
  CountPair count_both(const std::string& name, const std::vector<FxTriangle>& triangles, int width,
                       int height, const std::string& cull) {
    write(name + ".obj", window_obj(triangles));
    std::string args =
        name + ".obj " + window_camera(width, height) + kCounting + " --cull " + cull;
    Image soft = run(SOFTRAST_CLI_PATH, args, name + "_" + cull + "_softrast.png");
    Image gl = run(SOFTRAST_GLREF_PATH, args, name + "_" + cull + "_llvmpipe.png");
    if (soft.rgba.empty() || gl.rgba.empty()) return {};
    CountPair p{hit_counts(soft), hit_counts(gl)};
    EXPECT_LT(*std::max_element(p.soft.begin(), p.soft.end()), 200) << "too many overlaps";
    EXPECT_GE(*std::min_element(p.soft.begin(), p.soft.end()), 0) << "softrast: not a count";
    EXPECT_GE(*std::min_element(p.gl.begin(), p.gl.end()), 0) << "llvmpipe: not a count";
    return p;
  }
};

// About 2,400 triangles inside the viewport (small, pixel-sized, slivers, large, on pixel
// centres), no horizontal edge through a row of samples: every pixel is hit exactly as often
// by both, with each cull mode.
TEST_F(ReferenceCountTest, HitCountsMatchExactlyOnTheSubpixelGrid) {
  constexpr int kW = 256, kH = 256;
  std::vector<FxTriangle> triangles = random_grid_triangles(kW, kH, /*inside=*/true);
  for (const char* cull : {"none", "back", "front"}) {
    CountPair p = count_both("inside", triangles, kW, kH, cull);
    ASSERT_FALSE(p.soft.empty());
    std::string explained;
    for (size_t i = 0; i < p.soft.size(); ++i) {
      if (p.soft[i] == p.gl[i] || explained.size() > 4000) continue;
      explained += "  pixel (" + std::to_string(i % kW) + ", " + std::to_string(i / kW) + "):\n";
      nearest_edge(triangles, int(i % kW), int(i / kW), &explained);
    }
    EXPECT_EQ(count_differences(p.soft, p.gl, kW, kH), "")
        << "cull " << cull << "; edges near the differing samples:\n"
        << explained;
  }
}

// Triangles crossing the viewport: llvmpipe clips them (it has no guard band), softrast draws
// them whole. The cut edges move by rounding, so a sample within 1/128 pixel of an edge of such
// a triangle may go either way; any other difference is an error.
TEST_F(ReferenceCountTest, TrianglesCrossingTheBorderDifferOnlyNextToTheirEdges) {
  constexpr int kW = 256, kH = 256;
  constexpr double kClipSlack = 1.0 / 128.0;  // pixels
  std::vector<FxTriangle> triangles = random_grid_triangles(kW, kH, /*inside=*/false);
  CountPair p = count_both("crossing", triangles, kW, kH, "none");
  ASSERT_FALSE(p.soft.empty());
  int differing = 0;
  for (size_t i = 0; i < p.soft.size(); ++i) {
    if (p.soft[i] == p.gl[i]) continue;
    ++differing;
    std::string detail;
    double d = nearest_edge(triangles, int(i % kW), int(i / kW), &detail);
    EXPECT_LE(d, kClipSlack) << "pixel (" << i % kW << ", " << i / kW << "): softrast " << p.soft[i]
                             << " hits, llvmpipe " << p.gl[i] << "\n"
                             << detail;
  }
  std::printf("[ crossing ] %d pixels differ, all within %g px of an edge\n", differing,
              kClipSlack);
  EXPECT_LE(differing, 20);
}

// The tie-break for samples exactly on a horizontal edge, the one place where the conventions
// softrast follows (CONVENTIONS.md: top-left in y-down window coordinates, the example pair
// covering 15 and 10 pixels) and llvmpipe behind OSMesa (a window-system framebuffer, for which
// Mesa sets bottom_edge_rule: samples on a horizontal edge go to the triangle above it) differ.
// Checked: without ties the hit counts are identical; with ties both renderers are watertight
// (same total), and every pixel they disagree on has its sample exactly on a horizontal edge.
TEST_F(ReferenceDiffTest, HorizontalEdgeTiesAreTheOnlyFillRuleDifference) {
  constexpr int kW = 16, kH = 16;
  auto fx = [](double v) { return int64_t(std::llround(v * 256.0)); };
  auto tri = [&](double x0, double y0, double x1, double y1, double x2, double y2) {
    return FxTriangle{{fx(x0), fx(x1), fx(x2)}, {fx(y0), fx(y1), fx(y2)}};
  };
  struct Case {
    const char* name;
    std::vector<FxTriangle> triangles;
  };
  std::vector<Case> cases = {
      {"conventions_pair", {tri(0.5, 0.5, 5.5, 0.5, 5.5, 5.5), tri(0.5, 5.5, 0.5, 0.5, 5.5, 5.5)}},
      {"rectangle_on_centres",
       {tri(2.5, 3.5, 9.5, 3.5, 9.5, 11.5), tri(2.5, 3.5, 9.5, 11.5, 2.5, 11.5)}},
      {"rectangle_off_rows",
       {tri(2.5, 3.5 + 1 / 256.0, 9.5, 3.5 + 1 / 256.0, 9.5, 11.5 + 1 / 256.0),
        tri(2.5, 3.5 + 1 / 256.0, 9.5, 11.5 + 1 / 256.0, 2.5, 11.5 + 1 / 256.0)}},
  };
  // True when the sample of pixel row `row` lies exactly on a horizontal edge of the case.
  auto on_horizontal_edge = [](const Case& c, int row) {
    int64_t sample_y = int64_t(row) * 256 + 128;
    for (const FxTriangle& t : c.triangles) {
      for (int k = 0; k < 3; ++k) {
        if (t.y[k] == t.y[(k + 1) % 3] && t.y[k] == sample_y) return true;
      }
    }
    return false;
  };
  for (const Case& c : cases) {
    write(std::string(c.name) + ".obj", window_obj(c.triangles));
    std::string args =
        std::string(c.name) + ".obj " + window_camera(kW, kH) + kCounting + " --cull none";
    Image soft = run(SOFTRAST_CLI_PATH, args, std::string(c.name) + "_softrast.png");
    Image gl = run(SOFTRAST_GLREF_PATH, args, std::string(c.name) + "_llvmpipe.png");
    ASSERT_FALSE(soft.rgba.empty() || gl.rgba.empty());
    std::vector<int> a = hit_counts(soft), b = hit_counts(gl);
    std::string maps = std::string("softrast\n") + ascii_counts(a, kW, 0, 0, kW, kH) +
                       "llvmpipe\n" + ascii_counts(b, kW, 0, 0, kW, kH);
    EXPECT_EQ(std::accumulate(a.begin(), a.end(), 0), std::accumulate(b.begin(), b.end(), 0))
        << c.name << "\n"
        << maps;
    for (int i = 0; i < kW * kH; ++i) {
      if (a[size_t(i)] != b[size_t(i)]) {
        EXPECT_TRUE(on_horizontal_edge(c, i / kW))
            << c.name << ": pixel (" << i % kW << ", " << i / kW
            << ") differs off any horizontal edge\n"
            << maps;
      }
    }
  }
}

// glref's samples_passed (a GL_SAMPLES_PASSED query; with the depth test off every fragment
// counts) is the number of fragments softrast's image counts.
TEST_F(ReferenceCountTest, SamplesPassedIsTheFragmentCount) {
  constexpr int kW = 256, kH = 256;
  std::vector<FxTriangle> triangles = random_grid_triangles(kW, kH, /*inside=*/true);
  CountPair p = count_both("inside", triangles, kW, kH, "none");
  ASSERT_FALSE(p.soft.empty());
  long fragments = 0;
  for (int c : p.soft) fragments += c;
  std::string log = path("frames.log");
  std::string command = "cd " + quote(dir_.string()) + " && " + quote(SOFTRAST_GLREF_PATH) +
                        " inside.obj " + window_camera(kW, kH) + kCounting +
                        " --cull none --frames 1 -q >" + quote(log) + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_text(log);
  std::string json = read_text(log);
  EXPECT_NE(json.find("\"renderer\":\"llvmpipe\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"samples_passed\":" + std::to_string(fragments) + "}"), std::string::npos)
      << json << "\nsoftrast's image counts " << fragments << " fragments";
}

// Float colours to unorm8. softrast follows CONVENTIONS.md, x * 255 + 0.5 truncated (ties round
// up); llvmpipe rounds x * 255 to nearest with ties to even. So the two must agree exactly except
// on a tie, where they may differ by one step: 0.3 * 255 = 76.5 (the default albedo's blue) is 77
// and 76, 0.7 * 255 = 178.5 is 179 and 178, while 0.9 * 255 = 229.5 gives 230 in both.
TEST_F(ReferenceDiffTest, ColourConversionDiffersOnlyOnTies) {
  ObjWriter obj;
  int a = obj.vertex({0, 0, 0}), b = obj.vertex({0, 4, 0}), c = obj.vertex({4, 4, 0}),
      d = obj.vertex({4, 0, 0});
  obj.face({{a, 0, 0}, {b, 0, 0}, {c, 0, 0}, {d, 0, 0}});
  write("square.obj", obj.str());
  const std::vector<std::array<const char*, 3>> colours = {
      {"0.9", "0.6", "0.3"}, {"0.5", "0.7", "0.00980392157"}, {"0.25", "0.1", "0.8"}};
  for (const auto& colour : colours) {
    std::string text = std::string(colour[0]) + "," + colour[1] + "," + colour[2];
    std::string args =
        "square.obj " + window_camera(4, 4) + " --shader flat --cull none --color " + text;
    Image soft = run(SOFTRAST_CLI_PATH, args, "square_softrast.png");
    Image gl = run(SOFTRAST_GLREF_PATH, args, "square_llvmpipe.png");
    ASSERT_FALSE(soft.rgba.empty() || gl.rgba.empty());
    for (int ch = 0; ch < 3; ++ch) {
      float scaled = std::stof(colour[size_t(ch)]) * 255.0f;  // what both renderers round
      int s = soft.pixel(1, 1)[ch], g = gl.pixel(1, 1)[ch];
      bool tie = scaled - std::floor(scaled) == 0.5f;
      EXPECT_EQ(s, int(scaled + 0.5f)) << "softrast, channel " << ch << " of " << text;
      if (tie) {
        EXPECT_LE(std::abs(s - g), 1) << "channel " << ch << " of " << text;
      } else {
        EXPECT_EQ(s, g) << "channel " << ch << " of " << text << " is not a tie";
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Scenes compared with tolerance.

constexpr const char* kSmall = "--size 320x240";
// The closed scenes cull back faces as SCENES.md's do; both programs draw both by default.
constexpr const char* kCullBack = " --cull back";

TEST_F(ReferenceDiffTest, TexturedQuadGridSeenAtAnAngle) {
  write("grid.obj", quad_grid_obj(8.0, 14.0, 16, 28));
  write_texture("checker.png", checker_texture(256));
  std::string camera = std::string(kSmall) + kCullBack +
                       " --eye 0,3,3 --target 0,0,-4 --up 0,1,0 --fov 50 --near 0.5 --far 50";
  expect_close("grid_texture", "grid.obj " + camera + " --shader texture --texture checker.png",
               kTextureThreshold, 40);
  expect_close("grid_phong", "grid.obj " + camera + " --shader phong --texture checker.png",
               kTextureThreshold, 40);
}

TEST_F(ReferenceDiffTest, LitSpheres) {
  write("spheres.obj", spheres_obj(4, 3, 24, 16, 0.45));
  write_texture("checker.png", checker_texture(128));
  std::string camera = std::string(kSmall) + kCullBack +
                       " --eye 0,0,3.7 --target 0,0,0 --up 0,1,0 --fov 45 --near 1 --far 10";
  expect_close("spheres_gouraud", "spheres.obj " + camera + " --shader gouraud", kFlatThreshold,
               40);
  expect_close("spheres_phong", "spheres.obj " + camera + " --shader phong", kTextureThreshold, 40);
  expect_close("spheres_normals", "spheres.obj " + camera + " --shader normals", kFlatThreshold,
               40);
  expect_close("spheres_texture",
               "spheres.obj " + camera + " --shader texture --texture checker.png",
               kTextureThreshold, 40);
}

TEST_F(ReferenceDiffTest, FloorCrossingTheNearPlane) {
  ObjWriter obj;
  int a = obj.vertex({-30, 0, 20}), b = obj.vertex({30, 0, 20}), c = obj.vertex({30, 0, -60}),
      d = obj.vertex({-30, 0, -60});
  int ta = obj.uv({-3, -2}), tb = obj.uv({3, -2}), tc = obj.uv({3, 6}), td = obj.uv({-3, 6});
  obj.face({{a, ta, 0}, {b, tb, 0}, {c, tc, 0}, {d, td, 0}});
  write("floor.obj", obj.str());
  write_texture("checker.png", checker_texture(64));
  std::string camera = std::string(kSmall) + kCullBack +
                       " --eye 0.3,1,2 --target 0,0.2,-3 --up 0,1,0 --fov 60 --near 0.5 --far 40";
  expect_close("floor_flat", "floor.obj " + camera + " --shader flat", kFlatThreshold, 20);
  expect_close("floor_texture", "floor.obj " + camera + " --shader texture --texture checker.png",
               kTextureThreshold, 20);
}

TEST_F(ReferenceDiffTest, CubeWithEachCullMode) {
  write("cube.obj", cube_obj());
  std::string camera =
      std::string(kSmall) + " --eye 2.5,2,3.5 --target 0,0,0 --up 0,1,0 --fov 45 --near 1 --far 20";
  for (const char* cull : {"back", "front", "none"}) {
    expect_close(std::string("cube_cull_") + cull,
                 "cube.obj " + camera + " --shader gouraud --cull " + cull, kFlatThreshold, 20);
  }
}

// Triangles parallel to the image plane at eight depths, each with its own normal (so its own
// gouraud colour), drawn in random order: the depth test decides what is seen.
TEST_F(ReferenceDiffTest, RandomTrianglesAtSeveralDepths) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ObjWriter obj;
  for (int i = 0; i < 300; ++i) {
    double z = -1.0 - 0.5 * double(rng() % 8);
    glm::dvec3 centre(3.0 * u(rng), 2.2 * u(rng), z);
    int v[3];
    for (int& k : v) k = obj.vertex(centre + glm::dvec3(0.6 * u(rng), 0.6 * u(rng), 0.0));
    int n = obj.normal(glm::normalize(glm::dvec3(u(rng), u(rng), u(rng) + 1.2)));
    obj.face({{v[0], 0, n}, {v[1], 0, n}, {v[2], 0, n}});
  }
  write("layers.obj", obj.str());
  std::string camera =
      std::string(kSmall) + " --eye 0,0,3 --target 0,0,0 --up 0,1,0 --fov 60 --near 0.5 --far 10";
  expect_close("layers", "layers.obj " + camera + " --shader gouraud --cull none", kFlatThreshold,
               20);
}

// A fan of slivers a few hundredths of a pixel wide at the rim, and long needles.
TEST_F(ReferenceDiffTest, ThinSlivers) {
  ObjWriter obj;
  int centre = obj.vertex({0.0, 0.0, 0.0});
  constexpr int kSpokes = 720;
  std::vector<int> rim;
  for (int i = 0; i < kSpokes; ++i) {
    double a = 2.0 * std::numbers::pi * i / kSpokes;
    rim.push_back(obj.vertex({2.0 * std::cos(a), 2.0 * std::sin(a), 0.0}));
  }
  for (int i = 0; i < kSpokes; i += 2) {
    obj.face({{centre, 0, 0}, {rim[size_t(i)], 0, 0}, {rim[size_t(i + 1)], 0, 0}});
  }
  for (int i = 0; i < 40; ++i) {
    double y = -1.9 + 0.095 * i;
    obj.triangle({-2.9, y, 0.0}, {2.9, y + 0.004, 0.0}, {2.9, y + 0.004 + 0.0005 * i, 0.0});
  }
  write("slivers.obj", obj.str());
  std::string camera = std::string(kSmall) +
                       " --eye 0.1,-0.2,4 --target 0,0,0 --up 0.1,1,0 --fov 70 --near 1 --far 10";
  expect_close("slivers", "slivers.obj " + camera + " --shader flat --cull none", kFlatThreshold,
               30);
}

}  // namespace
}  // namespace softrast

#else  // no reference renderer in this build

TEST(ReferenceDiffTest, NeedsTheReferenceRenderer) {
  GTEST_SKIP() << "glref not built: configure with -DSOFTRAST_BUILD_REFERENCE=ON "
                  "(needs libosmesa6-dev)";
}

#endif
