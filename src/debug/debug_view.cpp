// debug/debug_view.cpp: the debug views. Each is an ordinary draw through the public pipeline
// (a counting shader, a per-triangle colour shader) or a pass over the shaded image (grid, heat),
// so what they show is what the pipeline did, not a model of it.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/mat4x4.hpp>

#include "debug/debug_render.hpp"
#include "raster/raster.hpp"
#include "softrast/debug_view.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

static_assert(kDebugTileSize == detail::kTileSize, "the grid drawn is the pipeline's tiles");

constexpr std::array<std::pair<DebugView, const char*>, 5> kViewNames = {{
    {DebugView::kNone, "none"},
    {DebugView::kTiles, "tiles"},
    {DebugView::kOverdraw, "overdraw"},
    {DebugView::kCost, "cost"},
    {DebugView::kTriangles, "triangles"},
}};

// The overdraw scale: counts 1..kOverdrawScaleTop run from blue to red; above it, white.
constexpr int kOverdrawScaleTop = 8;

// One fragment adds 1/255 to red (additive blending, no depth test): red = fragments, up to 255.
struct CountingShader {
  static constexpr int kVaryings = 0;
  const glm::vec3* positions;
  glm::mat4 mvp;
  glm::vec4 vertex(uint32_t i, float*) const { return mvp * glm::vec4(positions[i], 1.0f); }
  template <int N>
  void shade(Fragments<N>& f) const {
    f.color = {1.0f / 255.0f, 0.0f, 0.0f, 0.0f};
  }
};

// Every corner of every triangle is its own vertex (vertex i is corner i % 3 of triangle i / 3),
// so the triangle's colour can be a varying that is the same at its three corners.
struct TriangleColorShader {
  static constexpr int kVaryings = 3;
  const glm::vec3* positions;
  size_t position_count;
  const uint32_t* indices;
  glm::mat4 mvp;
  glm::vec4 vertex(uint32_t i, float* v) const {
    glm::vec4 c = unpack_rgba8(triangle_color(i / 3));
    v[0] = c.r, v[1] = c.g, v[2] = c.b;
    // An index out of range gives a NaN corner, which drops the triangle as draw() would.
    if (indices[i] >= position_count) return glm::vec4(std::nanf(""));
    return mvp * glm::vec4(positions[indices[i]], 1.0f);
  }
  template <int N>
  void shade(Fragments<N>& f) const {
    f.color = {f.varying(0), f.varying(1), f.varying(2), simd::Float<N>(1.0f)};
  }
};

glm::mat4 mvp_of(const Framebuffer& fb, const Camera& camera) {
  return camera.view_projection(float(fb.width()) / float(fb.height()));
}

// The mesh's indices in range (a partial last triangle dropped).
std::span<const uint32_t> triangle_indices(const Mesh& mesh) {
  return {mesh.indices.data(), mesh.triangle_count() * 3};
}

void draw_overdraw(Framebuffer& fb, const Mesh& mesh, const Camera& camera,
                   const RenderOptions& options) {
  Framebuffer counts(fb.width(), fb.height());
  counts.clear_color({0.0f, 0.0f, 0.0f, 0.0f});
  RenderState state = options.state;
  state.depth_test = false;
  state.depth_write = false;
  state.blend = BlendMode::kAdditive;
  state.wireframe = false;
  state.tile_times = nullptr;
  CountingShader shader{mesh.positions.data(), mvp_of(fb, camera)};
  draw(counts, state, shader, triangle_indices(mesh), uint32_t(mesh.positions.size()));
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) {
      fb.set_color(x, y, overdraw_color(int(counts.color_at(x, y) & 0xffu)));
    }
  }
}

void draw_triangles(Framebuffer& fb, const Mesh& mesh, const Camera& camera,
                    const RenderOptions& options) {
  std::span<const uint32_t> indices = triangle_indices(mesh);
  std::vector<uint32_t> corners(indices.size());
  std::iota(corners.begin(), corners.end(), 0u);
  RenderState state = options.state;
  state.wireframe = false;
  state.tile_times = nullptr;
  TriangleColorShader shader{mesh.positions.data(), mesh.positions.size(), indices.data(),
                             mvp_of(fb, camera)};
  draw(fb, state, shader, std::span<const uint32_t>(corners), uint32_t(corners.size()));
}

void draw_tile_grid(Framebuffer& fb) {
  for (int y = 0; y < fb.height(); ++y) {
    int step = y % kDebugTileSize == 0 ? 1 : kDebugTileSize;
    for (int x = 0; x < fb.width(); x += step) fb.set_color(x, y, kTileGridColor);
  }
}

// Each tile tinted by its share of the slowest tile's time, over the image in grey.
void draw_cost(Framebuffer& fb, const TileTimes& times) {
  double slowest = 0.0;
  for (double s : times.seconds) slowest = std::max(slowest, s);
  for (int y = 0; y < fb.height(); ++y) {
    int ty = y / kDebugTileSize;
    for (int x = 0; x < fb.width(); ++x) {
      int tx = x / kDebugTileSize;
      double spent = 0.0;
      if (tx < times.tiles_x && ty < times.tiles_y) {
        spent = times.seconds[size_t(ty) * size_t(times.tiles_x) + size_t(tx)];
      }
      glm::vec3 heat = heat_color(slowest > 0.0 ? float(spent / slowest) : 0.0f);
      glm::vec4 c = unpack_rgba8(fb.color_at(x, y));
      float grey = 0.299f * c.r + 0.587f * c.g + 0.114f * c.b;
      fb.set_color(x, y, pack_rgba8(glm::vec4(glm::vec3(0.35f * grey) + 0.65f * heat, 1.0f)));
    }
  }
  draw_tile_grid(fb);
}

}  // namespace

std::optional<DebugView> parse_debug_view(std::string_view name) {
  for (const auto& [view, text] : kViewNames) {
    if (name == text) return view;
  }
  return std::nullopt;
}

const char* debug_view_name(DebugView view) {
  for (const auto& [v, text] : kViewNames) {
    if (v == view) return text;
  }
  return "?";
}

glm::vec3 heat_color(float t) {
  static constexpr std::array<glm::vec3, 5> kStops = {{
      {0.0f, 0.0f, 1.0f},  // blue
      {0.0f, 1.0f, 1.0f},  // cyan
      {0.0f, 1.0f, 0.0f},  // green
      {1.0f, 1.0f, 0.0f},  // yellow
      {1.0f, 0.0f, 0.0f},  // red
  }};
  if (!(t > 0.0f)) return kStops.front();  // also NaN
  if (t >= 1.0f) return kStops.back();
  float scaled = t * float(kStops.size() - 1);
  int i = int(scaled);
  return glm::mix(kStops[size_t(i)], kStops[size_t(i) + 1], scaled - float(i));
}

uint32_t overdraw_color(int fragments) {
  if (fragments <= 0) return pack_rgba8({0.0f, 0.0f, 0.0f, 1.0f});
  if (fragments > kOverdrawScaleTop) return pack_rgba8({1.0f, 1.0f, 1.0f, 1.0f});
  float t = float(fragments - 1) / float(kOverdrawScaleTop - 1);
  return pack_rgba8(glm::vec4(heat_color(t), 1.0f));
}

uint32_t triangle_color(uint32_t triangle) {
  // splitmix32-style mixing: consecutive indices give unrelated bits.
  uint32_t h = triangle + 0x9e3779b9u;
  h = (h ^ (h >> 16)) * 0x85ebca6bu;
  h = (h ^ (h >> 13)) * 0xc2b2ae35u;
  h ^= h >> 16;
  auto channel = [&](int shift) { return 40u + ((h >> shift) & 0xffu) * 215u / 255u; };
  return channel(0) | channel(8) << 8 | channel(16) << 16 | 0xff000000u;
}

namespace detail {

void render_debug_view(Framebuffer& fb, const Mesh& mesh, const Camera& camera,
                       const RenderOptions& options) {
  RenderOptions shaded = options;
  shaded.debug_view = DebugView::kNone;
  switch (options.debug_view) {
    case DebugView::kNone:
      return render_mesh(fb, mesh, camera, shaded);
    case DebugView::kTiles:
      render_mesh(fb, mesh, camera, shaded);
      return draw_tile_grid(fb);
    case DebugView::kOverdraw:
      return draw_overdraw(fb, mesh, camera, options);
    case DebugView::kCost: {
      TileTimes times;
      shaded.state.tile_times = &times;
      render_mesh(fb, mesh, camera, shaded);
      return draw_cost(fb, times);
    }
    case DebugView::kTriangles:
      return draw_triangles(fb, mesh, camera, options);
  }
}

}  // namespace detail
}  // namespace softrast
