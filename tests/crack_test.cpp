// tests/crack_test.cpp: cracks and double hits along shared edges, measured over random meshes.
// Each mesh covers a known region (a convex polygon or a rectangle) without gaps or overlaps:
// fans, jittered grids with random diagonals, and random triangulations (points inserted into
// the triangle containing them, then random edge flips). Shared vertices are one index, so
// neighbouring triangles see bit-identical positions, as in any indexed mesh. Half of the meshes
// have window positions on the 1/256 grid with pixel-centre ties on many edges (w = 1), half
// float positions with perspective (w in [0.1, 4] per vertex).
//
// Drawn with additive counting and no culling, every sample inside the region (farther than
// 1/256 pixel from its outline) must be hit exactly once. The figure reported is per rasterizer:
// cracks (0 hits) and double hits (2 or more) per million shared-edge pixels, those whose sample
// lies within half a pixel of an edge two triangles share. Target 0. SOFTRAST_CRACK_MESHES=N
// runs N meshes instead of the normal pass's 300 (the README's figure).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "softrast/framebuffer.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

using P2 = std::array<double, 2>;

struct Mesh {
  int width = 96, height = 96;
  std::vector<P2> points;                 // window coordinates, y down
  std::vector<std::array<int, 3>> faces;  // indices into points
  std::vector<int> outline;               // the region's outline, as indices into points
  bool grid = false;                      // points on the 1/256 grid, w = 1
};

double cross(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniform_int(std::mt19937_64& rng, int lo, int hi) {
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

// A rectangle region, from slightly beyond the image on some sides to well inside.
std::array<double, 4> random_rect(std::mt19937_64& rng, const Mesh& m) {
  double x0 = uniform(rng, -0.1, 0.4) * m.width, x1 = uniform(rng, 0.6, 1.1) * m.width;
  double y0 = uniform(rng, -0.1, 0.4) * m.height, y1 = uniform(rng, 0.6, 1.1) * m.height;
  return {x0, y0, x1, y1};
}

Mesh fan(std::mt19937_64& rng) {
  Mesh m;
  int k = uniform_int(rng, 3, 40);
  std::vector<double> angles;
  for (int i = 0; i < k; ++i) angles.push_back(uniform(rng, 0.0, 2.0 * 3.14159265358979));
  std::sort(angles.begin(), angles.end());
  double cx = uniform(rng, 0.3, 0.7) * m.width, cy = uniform(rng, 0.3, 0.7) * m.height;
  double rx = uniform(rng, 0.2, 0.7) * m.width, ry = uniform(rng, 0.2, 0.7) * m.height;
  for (double a : angles) m.points.push_back({cx + rx * std::cos(a), cy + ry * std::sin(a)});
  for (int i = 0; i < k; ++i) m.outline.push_back(i);
  // A fan from an inner point, or from the first corner (a triangle-fan primitive's layout).
  if (uniform_int(rng, 0, 1)) {
    m.points.push_back({cx, cy});
    for (int i = 0; i < k; ++i) m.faces.push_back({k, i, (i + 1) % k});
  } else {
    for (int i = 1; i + 1 < k; ++i) m.faces.push_back({0, i, i + 1});
  }
  return m;
}

Mesh grid(std::mt19937_64& rng) {
  Mesh m;
  auto r = random_rect(rng, m);
  int nx = uniform_int(rng, 1, 16), ny = uniform_int(rng, 1, 16);
  double dx = (r[2] - r[0]) / nx, dy = (r[3] - r[1]) / ny;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      // Jitter inner points in both directions, border points only along their side.
      double jx = (i > 0 && i < nx) ? uniform(rng, -0.3, 0.3) * dx : 0.0;
      double jy = (j > 0 && j < ny) ? uniform(rng, -0.3, 0.3) * dy : 0.0;
      m.points.push_back({r[0] + i * dx + jx, r[1] + j * dy + jy});
    }
  }
  auto at = [&](int i, int j) { return j * (nx + 1) + i; };
  m.outline = {at(0, 0), at(nx, 0), at(nx, ny), at(0, ny)};
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (uniform_int(rng, 0, 1)) {
        m.faces.push_back({a, b, c});
        m.faces.push_back({a, c, d});
      } else {
        m.faces.push_back({a, b, d});
        m.faces.push_back({b, c, d});
      }
    }
  }
  return m;
}

Mesh triangulation(std::mt19937_64& rng) {
  Mesh m;
  auto r = random_rect(rng, m);
  m.points = {{r[0], r[1]}, {r[2], r[1]}, {r[2], r[3]}, {r[0], r[3]}};
  m.outline = {0, 1, 2, 3};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  int inserts = uniform_int(rng, 1, 60);
  for (int n = 0; n < inserts; ++n) {
    P2 p = {uniform(rng, r[0], r[2]), uniform(rng, r[1], r[3])};
    for (size_t f = 0; f < m.faces.size(); ++f) {
      auto [a, b, c] = m.faces[f];
      double s = cross(m.points[a], m.points[b], m.points[c]);
      double s0 = cross(m.points[a], m.points[b], p), s1 = cross(m.points[b], m.points[c], p),
             s2 = cross(m.points[c], m.points[a], p);
      // Strictly inside, away from the edges (no slivers of zero area).
      double margin = 1e-3 * std::abs(s);
      if (s0 * s > margin && s1 * s > margin && s2 * s > margin) {
        int i = int(m.points.size());
        m.points.push_back(p);
        m.faces[f] = {a, b, i};
        m.faces.push_back({b, c, i});
        m.faces.push_back({c, a, i});
        break;
      }
    }
  }
  // Random flips of edges whose two triangles form a strictly convex quad.
  int flips = uniform_int(rng, 0, 3 * int(m.faces.size()));
  for (int n = 0; n < flips; ++n) {
    size_t f = size_t(uniform_int(rng, 0, int(m.faces.size()) - 1));
    int e = uniform_int(rng, 0, 2);
    int a = m.faces[f][e], b = m.faces[f][(e + 1) % 3], c = m.faces[f][(e + 2) % 3];
    for (size_t g = 0; g < m.faces.size(); ++g) {
      if (g == f) continue;
      for (int k = 0; k < 3; ++k) {
        if (m.faces[g][k] == b && m.faces[g][(k + 1) % 3] == a) {
          int d = m.faces[g][(k + 2) % 3];
          // Quad a, d, b, c (a-b is the diagonal): flip to c-d if convex.
          const auto& P = m.points;
          double s1 = cross(P[c], P[a], P[d]), s2 = cross(P[c], P[d], P[b]);
          double s = cross(P[a], P[b], P[c]);
          if (s1 * s > 1e-6 && s2 * s > 1e-6) {
            m.faces[f] = {c, a, d};
            m.faces[g] = {c, d, b};
          }
          g = m.faces.size();
          break;
        }
      }
    }
  }
  return m;
}

struct CountShader {
  static constexpr int kVaryings = 0;
  const float* clip = nullptr;
  glm::vec4 vertex(uint32_t i, float*) const {
    const float* v = clip + 4 * size_t(i);
    return {v[0], v[1], v[2], v[3]};
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    f.color = {F(1.0f / 255.0f), F(0.0f), F(0.0f), F(0.0f)};
  }
};

struct Tally {
  long shared_edge_pixels = 0, cracks = 0, double_hits = 0, interior_wrong = 0, meshes = 0;
};

double segment_distance(const P2& a, const P2& b, const P2& p) {
  double ex = b[0] - a[0], ey = b[1] - a[1];
  double len2 = ex * ex + ey * ey;
  double t =
      len2 > 0 ? std::clamp(((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2, 0.0, 1.0) : 0.0;
  double dx = p[0] - (a[0] + t * ex), dy = p[1] - (a[1] + t * ey);
  return std::sqrt(dx * dx + dy * dy);
}

// False (nothing measured) when the positions as drawn fold the mesh: a triangle whose vertex
// lies within 0.01 pixel of its opposite edge, or turned the other way, would overlap its
// neighbours once snapped, whatever the rasterizer does.
bool measure(const Mesh& m, std::mt19937_64& rng, Tally (&tally)[2]) {
  // Clip coordinates: on the grid (exact, w = 1) or float with a random w per vertex.
  std::vector<float> clip;
  std::vector<P2> window;  // the positions as drawn (after the grid snap)
  // Grid meshes: half pixels (edges through centres and corners) or 1/256 steps.
  double step = uniform_int(rng, 0, 1) ? 2.0 : 256.0;
  for (const P2& p : m.points) {
    double x = p[0], y = p[1], w = 1.0;
    if (m.grid) {
      x = std::round(x * step) / step;
      y = std::round(y * step) / step;
    } else {
      w = uniform(rng, 0.1, 4.0);
    }
    float cx = float((2.0 * x / m.width - 1.0) * w), cy = float((1.0 - 2.0 * y / m.height) * w);
    clip.insert(clip.end(), {cx, cy, float(uniform(rng, -0.5, 0.5) * w), float(w)});
    window.push_back({(double(cx) / float(w) + 1.0) * 0.5 * m.width,
                      (1.0 - double(cy) / float(w)) * 0.5 * m.height});
  }
  double orientation = 0;
  for (const auto& f : m.faces) {
    const P2 &a = window[size_t(f[0])], &b = window[size_t(f[1])], &c = window[size_t(f[2])];
    double area2 = cross(a, b, c);
    if (orientation == 0) orientation = area2 > 0 ? 1 : -1;
    double longest =
        std::max({std::hypot(b[0] - a[0], b[1] - a[1]), std::hypot(c[0] - b[0], c[1] - b[1]),
                  std::hypot(a[0] - c[0], a[1] - c[1])});
    if (!(area2 * orientation / longest > 0.01)) return false;
  }
  // The outline as drawn, and the shared edges.
  std::vector<P2> outline;
  for (int i : m.outline) outline.push_back(window[size_t(i)]);
  std::set<std::pair<int, int>> seen, shared;
  for (const auto& f : m.faces) {
    for (int k = 0; k < 3; ++k) {
      auto e = std::minmax(f[k], f[(k + 1) % 3]);
      if (!seen.insert(e).second) shared.insert(e);
    }
  }
  std::vector<uint32_t> indices;
  for (const auto& f : m.faces)
    indices.insert(indices.end(), {uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  CountShader shader{clip.data()};
  for (int r = 0; r < 2; ++r) {
    Framebuffer fb(m.width, m.height);
    fb.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
    RenderState state;
    state.cull = CullMode::kNone;
    state.depth_test = false;
    state.blend = BlendMode::kAdditive;
    state.raster = r == 0 ? RasterAlgorithm::kEdgeEquations : RasterAlgorithm::kScanline;
    state.threads = 1;
    draw(fb, state, shader, indices, uint32_t(window.size()));
    Tally& t = tally[r];
    t.meshes++;
    for (int y = 0; y < m.height; ++y) {
      for (int x = 0; x < m.width; ++x) {
        P2 s = {x + 0.5, y + 0.5};
        // Inside the outline (crossing number), farther than the band from it.
        bool inside = false, near_outline = false;
        for (size_t i = 0; i < outline.size(); ++i) {
          const P2& a = outline[i];
          const P2& b = outline[(i + 1) % outline.size()];
          if ((a[1] > s[1]) != (b[1] > s[1]) &&
              s[0] < a[0] + (s[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])) {
            inside = !inside;
          }
          if (segment_distance(a, b, s) <= 1.0 / 256.0) near_outline = true;
        }
        if (!inside || near_outline) continue;
        int hits = int(fb.color_at(x, y) & 0xff);
        t.interior_wrong += hits != 1;
        bool near_shared = false;
        for (const auto& [i, j] : shared) {
          if (segment_distance(window[size_t(i)], window[size_t(j)], s) < 0.5) {
            near_shared = true;
            break;
          }
        }
        if (!near_shared) continue;
        t.shared_edge_pixels++;
        t.cracks += hits == 0;
        t.double_hits += hits >= 2;
      }
    }
  }
  return true;
}

TEST(Cracks, NoneAndNoDoubleHitsAlongSharedEdgesOfRandomMeshes) {
  int meshes = 300;
  if (const char* text = std::getenv("SOFTRAST_CRACK_MESHES"))
    meshes = std::max(1, std::atoi(text));
  std::mt19937_64 rng(0xc7ac4);
  Tally tally[2];
  for (int n = 0; n < meshes; ++n) {
    int kind = n % 3;
    for (;;) {
      Mesh m = kind == 0 ? fan(rng) : kind == 1 ? grid(rng) : triangulation(rng);
      m.grid = uniform_int(rng, 0, 1);
      if (measure(m, rng, tally)) break;
    }
  }
  const char* names[2] = {"edge equations", "scanline"};
  for (int r = 0; r < 2; ++r) {
    const Tally& t = tally[r];
    double per_million = 1e6 / double(std::max(1L, t.shared_edge_pixels));
    std::printf(
        "cracks %-15s %d meshes, %ld shared-edge pixels: %ld cracks (%.3f per million), "
        "%ld double hits (%.3f per million); %ld interior pixels hit other than once\n",
        names[r], meshes, t.shared_edge_pixels, t.cracks, t.cracks * per_million, t.double_hits,
        t.double_hits * per_million, t.interior_wrong);
    EXPECT_GT(t.shared_edge_pixels, 1000 * std::min(meshes, 100)) << names[r];
    EXPECT_EQ(t.cracks, 0) << names[r];
    EXPECT_EQ(t.double_hits, 0) << names[r];
    EXPECT_EQ(t.interior_wrong, 0) << names[r];
  }
}

}  // namespace
}  // namespace softrast
