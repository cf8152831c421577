// The wireframe overlay: edges drawn over their own filled triangles with glPolygonOffset keep
// every pixel (a shared diagonal is a solid line, not a dotted one), and edges behind other
// surfaces stay hidden.
#include <gtest/gtest.h>

#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr uint32_t kWire = 0xff0000ffu;  // pure red, RGBA8 little-endian

Mesh square(float size, float z, float tilt) {
  Mesh m;
  m.positions = {{-size, -size, z - tilt},
                 {size, -size, z - tilt},
                 {size, size, z + tilt},
                 {-size, size, z + tilt}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.uvs.assign(4, glm::vec2(0));
  m.indices = {0, 1, 2, 0, 2, 3};  // the diagonal 0-2 is shared
  return m;
}

RenderOptions overlay_options() {
  RenderOptions options;
  options.shader = ShaderKind::kFlat;
  options.color = {0.2f, 0.6f, 0.2f};
  options.wireframe_overlay = true;
  options.wire_color = {1.0f, 0.0f, 0.0f};
  return options;
}

Camera looking_at_square() {
  Camera camera;
  camera.eye = {0.3f, -2.0f, 3.0f};  // oblique: the square's depth slopes steeply in the image
  camera.target = {0, 0, 0};
  return camera;
}

// The diagonal runs from corner 0 to corner 2; a line by the diamond-exit rule has one pixel
// per step along its major axis. Counted between its projected ends, away from the outline.
// A floor (y = 0) seen from 45 degrees above, as the CLI frames flat models, and a tilted square.
Mesh floor_square() {
  Mesh m;
  m.positions = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}};
  m.normals.assign(4, glm::vec3(0, 1, 0));
  m.uvs.assign(4, glm::vec2(0));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

TEST(WireframeOverlay, SharedDiagonalIsASolidLine) {
  for (int view = 0; view < 3; ++view) {
    float tilt = view == 1 ? 0.8f : 0.0f;
    Mesh quad = view == 2 ? floor_square() : square(1.0f, 0.0f, tilt);
    Camera camera = looking_at_square();
    if (view == 2) camera.eye = {0.0f, 2.6f, 2.6f};
    Framebuffer fb(256, 256);
    render_mesh(fb, quad, camera, overlay_options());
    glm::mat4 mvp = camera.view_projection(1.0f);
    auto window = [&](glm::vec3 p) {
      glm::vec4 c = mvp * glm::vec4(p, 1.0f);
      return glm::vec2((c.x / c.w + 1.0f) * 128.0f, (1.0f - c.y / c.w) * 128.0f);
    };
    glm::vec2 a = window(quad.positions[0]), b = window(quad.positions[2]);
    bool x_major = std::abs(b.x - a.x) >= std::abs(b.y - a.y);
    float lo = x_major ? std::min(a.x, b.x) : std::min(a.y, b.y);
    float hi = x_major ? std::max(a.x, b.x) : std::max(a.y, b.y);
    int steps = 0, drawn = 0;
    for (int m = int(lo) + 10; m <= int(hi) - 10; ++m) {
      // The diagonal's minor coordinate at this major coordinate, and the wire pixels near it.
      float t = (float(m) + 0.5f - (x_major ? a.x : a.y)) / ((x_major ? b.x - a.x : b.y - a.y));
      float minor = (x_major ? a.y : a.x) + t * (x_major ? b.y - a.y : b.x - a.x);
      bool found = false;
      for (int d = -1; d <= 1; ++d) {
        int n = int(minor) + d;
        int x = x_major ? m : n, y = x_major ? n : m;
        found |= fb.color_at(x, y) == kWire;
      }
      ++steps;
      drawn += found;
    }
    ASSERT_GT(steps, 60) << "view " << view;
    EXPECT_EQ(drawn, steps) << "view " << view << ": the diagonal is dotted";
  }
}

TEST(WireframeOverlay, EdgesBehindASurfaceStayHidden) {
  // A small square behind a large one (same orientation): none of its edges may show.
  Mesh scene = square(1.0f, 0.0f, 0.0f);
  Mesh behind = square(0.4f, -0.05f, 0.0f);
  uint32_t base = uint32_t(scene.positions.size());
  scene.positions.insert(scene.positions.end(), behind.positions.begin(), behind.positions.end());
  scene.normals.insert(scene.normals.end(), behind.normals.begin(), behind.normals.end());
  scene.uvs.insert(scene.uvs.end(), behind.uvs.begin(), behind.uvs.end());
  for (uint32_t i : behind.indices) scene.indices.push_back(base + i);
  Camera camera;
  camera.eye = {0, 0, 3};
  Framebuffer fb(200, 200);
  render_mesh(fb, scene, camera, overlay_options());
  // The small square's outline would be about x, y in [73, 127]; only the large square's own
  // diagonal (x == y) may be red there.
  int hidden_edge_pixels = 0;
  for (int y = 60; y < 140; ++y) {
    for (int x = 60; x < 140; ++x) {
      if (fb.color_at(x, y) == kWire && std::abs(x - (199 - y)) > 2) ++hidden_edge_pixels;
    }
  }
  EXPECT_EQ(hidden_edge_pixels, 0);
}

}  // namespace
}  // namespace softrast
