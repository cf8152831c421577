// scene/demo_scene.cpp: the built-in demo scene, made in code so it needs no files: a checkered
// floor that runs under and behind the camera (so it crosses the near plane), a textured sphere,
// a torus, a box cut by the image border, all lit by the phong shader.
#include <cmath>
#include <functional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr float kPi = glm::pi<float>();

// A procedural texture: colour as a function of (u, v) in [0, 1). A texel is the pattern's mean
// over its square: 4 x 4 samples where the pattern changes inside it (its four corners and its
// centre are not all one colour), else that one colour. The patterns' edges then come out
// anti-aliased, as a painted texture's would, instead of as steps one texel wide (which the
// bilinear filter magnified into jagged stripes on the sphere and the torus).
Texture make_texture(int size, const std::function<glm::vec3(float, float)>& f) {
  constexpr int kSub = 4;
  const int side = size + 1;
  // Row 0 of the image is the top, v = 1; corner (x, y) is the top-left corner of texel (x, y).
  std::vector<glm::vec3> corners(std::size_t(side) * side);
  const auto corner = [&](int x, int y) -> glm::vec3& {
    return corners[std::size_t(y) * side + x];
  };
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) corner(x, y) = f(float(x) / size, 1.0f - float(y) / size);
  }
  Image image(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      glm::vec3 c = f((x + 0.5f) / size, 1.0f - (y + 0.5f) / size);
      if (corner(x, y) != c || corner(x + 1, y) != c || corner(x, y + 1) != c ||
          corner(x + 1, y + 1) != c) {
        glm::vec3 sum(0.0f);
        bool uniform = true;  // a texel that an edge only touches keeps its colour exactly
        for (int j = 0; j < kSub; ++j) {
          for (int i = 0; i < kSub; ++i) {
            glm::vec3 v = f((x + (i + 0.5f) / kSub) / size, 1.0f - (y + (j + 0.5f) / kSub) / size);
            uniform = uniform && v == c;
            sum += v;
          }
        }
        if (!uniform) c = sum / float(kSub * kSub);
      }
      uint8_t* p = image.pixel(x, y);
      p[0] = to_unorm8(c.r), p[1] = to_unorm8(c.g), p[2] = to_unorm8(c.b), p[3] = 255;
    }
  }
  // Colour data: decoded from sRGB under --srgb, its mip chain built in linear space.
  return Texture::from_image(image, ColorSpace::kSrgb);
}

// `diffuse` is the material's colour for the untextured shaders (flat, gouraud, wireframe).
int add_material(Mesh& mesh, const char* name, glm::vec3 diffuse, Texture texture) {
  Material m;
  m.name = name;
  m.diffuse = diffuse;
  m.diffuse_map = std::make_shared<const Texture>(std::move(texture));
  mesh.materials.push_back(std::move(m));
  return int(mesh.materials.size()) - 1;
}

// Starts a new submesh for the triangles appended next.
void begin_run(Mesh& mesh, int material) {
  mesh.submeshes.push_back({uint32_t(mesh.indices.size()), 0, material});
}
void end_run(Mesh& mesh) {
  SubMesh& s = mesh.submeshes.back();
  s.index_count = uint32_t(mesh.indices.size()) - s.first_index;
}

uint32_t add_vertex(Mesh& mesh, glm::vec3 p, glm::vec3 n, glm::vec2 uv) {
  mesh.positions.push_back(p);
  mesh.normals.push_back(n);
  mesh.uvs.push_back(uv);
  return uint32_t(mesh.positions.size()) - 1;
}

// A (cols+1) x (rows+1) vertex grid over (s, t) in [0, 1]^2, triangulated counter-clockwise as
// seen from the side the normals face. `at` returns position and normal for (s, t).
void add_grid(Mesh& mesh, int cols, int rows, glm::vec2 uv_scale,
              const std::function<void(float, float, glm::vec3&, glm::vec3&)>& at) {
  uint32_t base = uint32_t(mesh.positions.size());
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= cols; ++i) {
      float s = float(i) / cols, t = float(j) / rows;
      glm::vec3 p, n;
      at(s, t, p, n);
      add_vertex(mesh, p, n, glm::vec2(s, t) * uv_scale);
    }
  }
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      uint32_t a = base + uint32_t(j * (cols + 1) + i), b = a + 1;
      uint32_t c = a + uint32_t(cols + 1), d = c + 1;
      mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
    }
  }
}

void add_sphere(Mesh& mesh, glm::vec3 centre, float r) {
  add_grid(mesh, 48, 32, {2.0f, 1.0f}, [&](float s, float t, glm::vec3& p, glm::vec3& n) {
    float phi = s * 2.0f * kPi, theta = (1.0f - t) * kPi;  // t = 0 at the south pole
    n = {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
    p = centre + r * n;
  });
}

void add_torus(Mesh& mesh, glm::vec3 centre, float major, float minor) {
  add_grid(mesh, 64, 24, {4.0f, 1.0f}, [&](float s, float t, glm::vec3& p, glm::vec3& n) {
    float a = s * 2.0f * kPi, b = t * 2.0f * kPi;
    glm::vec3 ring(std::cos(a), 0.0f, -std::sin(a));
    n = std::cos(b) * ring + std::sin(b) * glm::vec3(0.0f, 1.0f, 0.0f);
    p = centre + major * ring + minor * n;
  });
}

// An axis-aligned box, each face its own 1x1 grid with its own normal and uvs.
void add_box(Mesh& mesh, glm::vec3 lo, glm::vec3 hi) {
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      if (side == 0) std::swap(u, v);  // keep counter-clockwise winding seen from outside
      glm::vec3 n(0.0f);
      n[axis] = side ? 1.0f : -1.0f;
      add_grid(mesh, 1, 1, {1.0f, 1.0f}, [&](float s, float t, glm::vec3& p, glm::vec3& nn) {
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = lo[u] + s * (hi[u] - lo[u]);
        p[v] = lo[v] + t * (hi[v] - lo[v]);
        nn = n;
      });
    }
  }
}

glm::vec3 checker(float u, float v) {
  bool odd = (int(u * 8.0f) + int(v * 8.0f)) % 2 != 0;
  return odd ? glm::vec3(0.85f, 0.85f, 0.8f) : glm::vec3(0.25f, 0.3f, 0.38f);
}

glm::vec3 stripes(float u, float v) {
  float band = std::fmod(u * 6.0f + v * 2.0f, 1.0f);
  return band < 0.5f ? glm::vec3(0.9f, 0.35f, 0.2f) : glm::vec3(0.95f, 0.8f, 0.3f);
}

glm::vec3 bricks(float u, float v) {
  float row = std::floor(v * 4.0f);
  float x = u * 2.0f + (int(row) % 2 ? 0.25f : 0.0f);
  float fx = x - std::floor(x), fy = v * 4.0f - row;
  bool mortar = fx < 0.05f || fy < 0.08f;
  return mortar ? glm::vec3(0.8f, 0.78f, 0.72f) : glm::vec3(0.6f, 0.22f, 0.15f);
}

glm::vec3 rings(float u, float v) {
  float d = std::hypot(u - 0.5f, v - 0.5f);
  return std::fmod(d * 10.0f, 1.0f) < 0.5f ? glm::vec3(0.2f, 0.55f, 0.85f)
                                           : glm::vec3(0.9f, 0.95f, 1.0f);
}

}  // namespace

DemoScene make_demo_scene() {
  DemoScene scene;
  Mesh& mesh = scene.mesh;
  int floor_mat = add_material(mesh, "floor", {0.55f, 0.58f, 0.6f}, make_texture(256, checker));
  int stripe_mat = add_material(mesh, "stripes", {0.92f, 0.58f, 0.25f}, make_texture(256, stripes));
  int brick_mat = add_material(mesh, "bricks", {0.65f, 0.3f, 0.22f}, make_texture(256, bricks));
  int ring_mat = add_material(mesh, "rings", {0.45f, 0.7f, 0.92f}, make_texture(256, rings));

  // Floor: y = 0 from z = +12 (behind the camera) to z = -30, 4 x 4 quads so that some triangles
  // straddle the near plane and some lie wholly behind the camera.
  begin_run(mesh, floor_mat);
  add_grid(mesh, 4, 4, {10.0f, 10.0f}, [](float s, float t, glm::vec3& p, glm::vec3& n) {
    p = {-20.0f + 40.0f * s, 0.0f, 12.0f - 42.0f * t};
    n = {0.0f, 1.0f, 0.0f};
  });
  end_run(mesh);
  begin_run(mesh, stripe_mat);
  add_sphere(mesh, {-1.3f, 1.0f, -1.0f}, 1.0f);
  end_run(mesh);
  begin_run(mesh, ring_mat);
  add_torus(mesh, {1.4f, 0.45f, 0.2f}, 0.8f, 0.35f);
  end_run(mesh);
  begin_run(mesh, brick_mat);
  add_box(mesh, {2.6f, 0.0f, -3.0f}, {4.6f, 2.0f, -1.2f});  // crosses the right image border
  add_box(mesh, {-4.0f, 0.0f, -6.0f}, {-2.5f, 3.0f, -4.5f});
  end_run(mesh);

  scene.camera.eye = {0.0f, 1.6f, 4.2f};
  scene.camera.target = {0.2f, 0.7f, -1.0f};
  scene.camera.up = {0.0f, 1.0f, 0.0f};
  scene.camera.fov_y_degrees = 50.0f;
  scene.camera.near_plane = 0.5f;
  scene.camera.far_plane = 60.0f;
  return scene;
}

}  // namespace softrast
