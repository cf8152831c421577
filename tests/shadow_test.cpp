// tests/shadow_test.cpp: shadow maps (RenderOptions::shadows). A unit cube on a plane, seen from
// straight above through an orthographic camera, lit by a directional light from several
// directions: the shadowed pixels of the plane are those whose ray towards the light hits the
// cube (computed analytically, by a slab test), up to a one-pixel band along the silhouette; lit
// pixels outside that band equal the image without shadows exactly (no acne); the shadow starts
// at the cube's base (no peter-panning).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "softrast/framebuffer.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr int kSize = 256;
constexpr float kHalfExtent = 4.0f;  // the plane and the view span [-4, 4] in x and z
constexpr float kPixelsPerUnit = kSize / (2 * kHalfExtent);

void add_quad(Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 n) {
  uint32_t base = uint32_t(m.positions.size());
  for (glm::vec3 p : {a, b, c, d}) {
    m.positions.push_back(p);
    m.normals.push_back(n);
    m.uvs.push_back(glm::vec2(0.0f));
  }
  m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

// The plane y = 0 over [-4, 4]^2 and the cube [-0.5, 0.5] x [0, 1] x [-0.5, 0.5] standing on it,
// counter-clockwise seen from outside.
Mesh cube_on_plane() {
  Mesh m;
  const float e = kHalfExtent;
  add_quad(m, {-e, 0, e}, {e, 0, e}, {e, 0, -e}, {-e, 0, -e}, {0, 1, 0});
  const float h = 0.5f;
  add_quad(m, {-h, 1, h}, {h, 1, h}, {h, 1, -h}, {-h, 1, -h}, {0, 1, 0});     // top
  add_quad(m, {-h, 0, h}, {h, 0, h}, {h, 1, h}, {-h, 1, h}, {0, 0, 1});       // +z
  add_quad(m, {h, 0, -h}, {-h, 0, -h}, {-h, 1, -h}, {h, 1, -h}, {0, 0, -1});  // -z
  add_quad(m, {h, 0, h}, {h, 0, -h}, {h, 1, -h}, {h, 1, h}, {1, 0, 0});       // +x
  add_quad(m, {-h, 0, -h}, {-h, 0, h}, {-h, 1, h}, {-h, 1, -h}, {-1, 0, 0});  // -x
  return m;
}

// Looking straight down at the plane: x to the right, -z up in the image, 32 pixels per unit.
Camera top_camera() {
  Camera c;
  c.eye = {0.0f, 10.0f, 0.0f};
  c.target = {0.0f, 0.0f, 0.0f};
  c.up = {0.0f, 0.0f, -1.0f};
  c.orthographic = true;
  c.ortho_left = c.ortho_bottom = -kHalfExtent;
  c.ortho_right = c.ortho_top = kHalfExtent;
  c.near_plane = 1.0f;
  c.far_plane = 20.0f;
  return c;
}

// The world point of the plane under pixel (x, y)'s centre.
glm::dvec3 plane_point(double x, double y) {
  return {-kHalfExtent + x / kPixelsPerUnit, 0.0, -kHalfExtent + y / kPixelsPerUnit};
}

// Whether the ray from p towards the light hits the cube (slab test).
bool ray_hits_cube(glm::dvec3 p, glm::dvec3 l) {
  const glm::dvec3 lo(-0.5, 0.0, -0.5), hi(0.5, 1.0, 0.5);
  double t0 = 1e-9, t1 = 1e30;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(l[k]) < 1e-12) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - p[k]) / l[k], b = (hi[k] - p[k]) / l[k];
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
  }
  return t0 <= t1;
}

bool under_cube(double x, double y) {
  glm::dvec3 p = plane_point(x, y);
  return std::abs(p.x) <= 0.5 && std::abs(p.z) <= 0.5;
}

Image render(const Mesh& mesh, glm::vec3 light, bool shadows) {
  Framebuffer fb(kSize, kSize);
  fb.clear();
  RenderOptions o;
  o.shader = ShaderKind::kPhong;
  o.color = glm::vec3(1.0f);
  o.light_direction = light;
  o.state.cull = CullMode::kBack;
  o.shadows = shadows;
  render_mesh(fb, mesh, top_camera(), o);
  return fb.to_image();
}

struct ShadowCheck {
  int shadow_interior = 0, shadow_missing = 0;  // analytic shadow away from its edge
  int lit_interior = 0, acne = 0;               // analytic light away from the shadow's edge
  int base_pixels = 0, base_lit = 0;            // next to the cube's base on the shadow side
};

ShadowCheck check_light(glm::vec3 light) {
  Mesh mesh = cube_on_plane();
  Image with = render(mesh, light, true), without = render(mesh, light, false);
  glm::dvec3 l = glm::normalize(glm::dvec3(light));
  ShadowCheck c;
  auto red = [](const Image& im, int x, int y) {
    return int(im.rgba[(size_t(y) * kSize + x) * 4]);
  };
  // Shadowed: nearer the ambient light alone (0.15 of the white albedo) than the lit value.
  auto dark = [&](int x, int y) { return 2 * red(with, x, y) < 38 + red(without, x, y); };
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      double cx = x + 0.5, cy = y + 0.5;
      if (under_cube(cx, cy)) {  // the cube's top face: lit, no self-shadowing
        c.lit_interior += 1;
        c.acne += red(with, x, y) != red(without, x, y);
        continue;
      }
      // The analytic state at the pixel's centre and at points one pixel around it: a pixel is
      // judged only when all agree (away from the silhouette's edge, and from the cube's).
      bool state = ray_hits_cube(plane_point(cx, cy), l), uniform = true;
      for (int k = 0; k < 8 && uniform; ++k) {
        double a = k * std::acos(-1.0) / 4;
        double px = cx + 1.5 * std::cos(a), py = cy + 1.5 * std::sin(a);
        uniform = ray_hits_cube(plane_point(px, py), l) == state && !under_cube(px, py);
      }
      if (!uniform) continue;
      if (state) {
        c.shadow_interior += 1;
        c.shadow_missing += !dark(x, y);
      } else {
        c.lit_interior += 1;
        c.acne += red(with, x, y) != red(without, x, y);
      }
    }
  }
  // No peter-panning: the pixels just outside the cube's base, on the sides the light leaves
  // (the shadow side), are shadowed. Base edge x = -0.5 when the light comes from +x, etc.
  for (int side = 0; side < 2; ++side) {
    double toward = side == 0 ? l.x : l.z;
    if (std::abs(toward) < 0.05) continue;
    double edge = toward > 0 ? -0.5 : 0.5;  // the base edge the shadow leaves from
    int line = int(std::lround((edge + kHalfExtent) * kPixelsPerUnit)) - (toward > 0 ? 1 : 0);
    for (int k = 8; k < kSize - 8; ++k) {
      int x = side == 0 ? line : k, y = side == 0 ? k : line;
      glm::dvec3 p = plane_point(x + 0.5, y + 0.5);
      double along = side == 0 ? p.z : p.x;
      if (std::abs(along) > 0.45) continue;  // away from the corners
      c.base_pixels += 1;
      c.base_lit += !dark(x, y);
    }
  }
  return c;
}

TEST(Shadows, CubeOnPlaneCastsItsAnalyticShadow) {
  const glm::vec3 lights[] = {
      {0.5f, 1.0f, 0.3f}, {-0.8f, 0.6f, 0.4f}, {0.3f, 0.9f, -0.7f}, {1.0f, 0.5f, 0.0f}};
  for (glm::vec3 light : lights) {
    SCOPED_TRACE("light " + std::to_string(light.x) + "," + std::to_string(light.y) + "," +
                 std::to_string(light.z));
    ShadowCheck c = check_light(light);
    EXPECT_GT(c.shadow_interior, 300);  // the shadow is there, and large
    EXPECT_EQ(c.shadow_missing, 0) << "of " << c.shadow_interior;
    EXPECT_GT(c.lit_interior, 40000);
    EXPECT_EQ(c.acne, 0) << "of " << c.lit_interior;
    EXPECT_GT(c.base_pixels, 20);
    EXPECT_EQ(c.base_lit, 0) << "of " << c.base_pixels << " pixels along the cube's base";
  }
}

}  // namespace
}  // namespace softrast
