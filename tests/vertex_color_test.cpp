// tests/vertex_color_test.cpp: vertex colours of OBJ ("v x y z r g b") and PLY (red, green, blue,
// alpha) files: loaded onto the right vertices (also across the OBJ loader's parallel pieces),
// and drawn by flat, gouraud and phong as the albedo: the same image as the uniform colour they
// replace, where every vertex has that colour; each vertex's own colour near it otherwise;
// decoded from sRGB in the linear workflow, as texels are.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "softrast/framebuffer.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

class VertexColorTest : public testing::Test {
 protected:
  void SetUp() override {
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("softrast_vc_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return (dir_ / name).string();
  }
  fs::path dir_;
};

// A unit quad facing +z, its corners coloured `c[k]` when given (OBJ text).
std::string quad_obj(const char* const c[4]) {
  const char* corners[4] = {"-1 -1 0", "1 -1 0", "1 1 0", "-1 1 0"};
  std::string s;
  for (int k = 0; k < 4; ++k) {
    s += std::string("v ") + corners[k] + (c[k] ? std::string(" ") + c[k] : std::string()) + "\n";
  }
  return s + "f 1 2 3 4\n";
}

Image render(const Mesh& mesh, ShaderKind shader, glm::vec3 color = {0.9f, 0.6f, 0.3f},
             bool srgb = false) {
  Camera camera;
  camera.eye = {0.3f, 0.2f, 3.0f};
  camera.target = {0.0f, 0.0f, 0.0f};
  RenderOptions options;
  options.shader = shader;
  options.color = color;
  options.srgb = srgb;
  options.light_direction = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
  Framebuffer fb(96, 72);
  fb.clear_color(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  fb.clear_depth(1.0f);
  render_mesh(fb, mesh, camera, options);
  return fb.to_image();
}

int worst_difference(const Image& a, const Image& b) {
  int worst = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i)
    worst = std::max(worst, std::abs(a.rgba[i] - b.rgba[i]));
  return worst;
}

TEST_F(VertexColorTest, ObjAndPlyColoursLoadOntoTheirVertices) {
  // OBJ: colours clamped to [0, 1]; a position without one is white.
  const char* colours[4] = {"1 0 0", "0 0.5 0", "0 0 2", nullptr};
  Result<Mesh> obj = load_obj(write("q.obj", quad_obj(colours)));
  ASSERT_TRUE(obj.ok()) << obj.status().message();
  ASSERT_EQ(obj->colors.size(), obj->positions.size());
  for (size_t i = 0; i < obj->positions.size(); ++i) {
    glm::vec3 p = obj->positions[i];
    glm::vec4 want = p.x < 0 && p.y < 0   ? glm::vec4(1, 0, 0, 1)
                     : p.x > 0 && p.y < 0 ? glm::vec4(0, 0.5f, 0, 1)
                     : p.x > 0 && p.y > 0 ? glm::vec4(0, 0, 1, 1)
                                          : glm::vec4(1, 1, 1, 1);
    EXPECT_EQ(obj->colors[i], want) << p.x << "," << p.y;
  }
  const char* none[4] = {nullptr, nullptr, nullptr, nullptr};
  Result<Mesh> plain = load_obj(write("plain.obj", quad_obj(none)));
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->colors.empty());

  // PLY: uchar channels over 255, float channels as they are, alpha when given.
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "property uchar alpha\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 255 0 0 255\n1 0 0 0 128 0 64\n0 1 0 0 0 51 0\n3 0 1 2\n";
  Result<Mesh> a = load_model(write("a.ply", ply));
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_EQ(a->colors.size(), 3u);
  EXPECT_EQ(a->colors[0], glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  EXPECT_FLOAT_EQ(a->colors[1].g, float(128.0 / 255.0));
  EXPECT_FLOAT_EQ(a->colors[1].a, float(64.0 / 255.0));
  EXPECT_FLOAT_EQ(a->colors[2].b, float(51.0 / 255.0));
  std::string ply_float =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty float r\nproperty float g\nproperty float b\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0.25 0.5 0.75\n1 0 0 1.5 -1 0\n0 1 0 0 0 0\n3 0 1 2\n";
  Result<Mesh> f = load_model(write("f.ply", ply_float));
  ASSERT_TRUE(f.ok()) << f.status().message();
  ASSERT_EQ(f->colors.size(), 3u);
  EXPECT_EQ(f->colors[0], glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
  EXPECT_EQ(f->colors[1], glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));  // clamped; opaque without alpha
}

// An OBJ over 1 MiB is parsed in pieces in parallel: colours given to some positions only, none
// in the first pieces (about 1.7 MB without), then every third, still land on their own
// vertices.
TEST_F(VertexColorTest, ObjColoursAcrossPiecesStayWithTheirPositions) {
  std::ostringstream obj;
  const int kPositions = 150000, kFirstColoured = 100000;  // about 2.6 MB of text
  auto coloured = [&](int i) { return i >= kFirstColoured && i % 3 == 0; };
  for (int i = 0; i < kPositions; ++i) {
    obj << "v " << i << " " << (i % 7) << " 0.5";
    if (coloured(i)) obj << " " << float(i % 11) / 10.0f << " 0.25 " << float(i % 5) / 4.0f;
    obj << "\n";
  }
  for (int i = 1; i + 2 <= kPositions; i += 3)
    obj << "f " << i << " " << i + 1 << " " << i + 2 << "\n";
  Result<Mesh> mesh = load_obj(write("big.obj", obj.str()));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->colors.size(), mesh->positions.size());
  int checked = 0;
  for (size_t v = 0; v < mesh->positions.size(); ++v) {
    int i = int(mesh->positions[v].x);
    glm::vec4 want = coloured(i)
                         ? glm::vec4(float(i % 11) / 10.0f, 0.25f, float(i % 5) / 4.0f, 1.0f)
                         : glm::vec4(1.0f);
    ASSERT_EQ(mesh->colors[v], want) << "position " << i;
    ++checked;
  }
  EXPECT_EQ(checked, kPositions);
}

// Every vertex red: flat, gouraud and phong draw what they draw with the uniform colour red
// (within 1/255: the interpolated colour may differ from the constant in its last bit).
// Vertices of different colours: each corner of the image shows its vertex's colour. In the linear
// workflow (--srgb) a vertex colour of 0.5 is decoded (to 0.214) and encoded back: 128, not 188.
TEST_F(VertexColorTest, FlatGouraudAndPhongDrawVertexColoursAsTheAlbedo) {
  const char* red[4] = {"1 0 0", "1 0 0", "1 0 0", "1 0 0"};
  const char* none[4] = {nullptr, nullptr, nullptr, nullptr};
  Result<Mesh> coloured = load_obj(write("red.obj", quad_obj(red)));
  Result<Mesh> plain = load_obj(write("plain.obj", quad_obj(none)));
  ASSERT_TRUE(coloured.ok() && plain.ok());
  for (ShaderKind kind : {ShaderKind::kFlat, ShaderKind::kGouraud, ShaderKind::kPhong}) {
    Image a = render(*coloured, kind), b = render(*plain, kind, {1.0f, 0.0f, 0.0f});
    Image orange = render(*plain, kind);
    EXPECT_LE(worst_difference(a, b), 1) << int(kind);
    EXPECT_GT(worst_difference(a, orange), 50) << int(kind);  // the colour is not ignored
  }
  const char* four[4] = {"1 0 0", "0 1 0", "0 0 1", "1 1 0"};
  Result<Mesh> mixed = load_obj(write("mixed.obj", quad_obj(four)));
  ASSERT_TRUE(mixed.ok());
  for (ShaderKind kind : {ShaderKind::kFlat, ShaderKind::kGouraud, ShaderKind::kPhong}) {
    Image image = render(*mixed, kind);
    // Sample near each projected corner along the quad's diagonal towards the centre.
    Camera camera;
    camera.eye = {0.3f, 0.2f, 3.0f};
    glm::mat4 mvp = camera.view_projection(96.0f / 72.0f);
    const glm::vec3 corners[4] = {
        {-0.8f, -0.8f, 0}, {0.8f, -0.8f, 0}, {0.8f, 0.8f, 0}, {-0.8f, 0.8f, 0}};
    const int dominant[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};
    for (int k = 0; k < 4; ++k) {
      glm::vec4 c = mvp * glm::vec4(corners[k], 1.0f);
      int x = int((c.x / c.w * 0.5f + 0.5f) * 96), y = int((0.5f - c.y / c.w * 0.5f) * 72);
      const uint8_t* p = image.pixel(x, y);
      // Each of the vertex's channels well above each of the others (phong adds a white
      // highlight to all three).
      for (int d = 0; d < 3; ++d) {
        for (int o = 0; o < 3; ++o) {
          if (dominant[k][d] && !dominant[k][o]) {
            EXPECT_GT(int(p[d]), int(p[o]) + 40)
                << "shader " << int(kind) << " corner " << k << ": " << int(p[0]) << ","
                << int(p[1]) << "," << int(p[2]);
          }
        }
      }
    }
  }
  const char* grey[4] = {"0.5 0.5 0.5", "0.5 0.5 0.5", "0.5 0.5 0.5", "0.5 0.5 0.5"};
  Result<Mesh> mid = load_obj(write("grey.obj", quad_obj(grey)));
  ASSERT_TRUE(mid.ok());
  Image linear = render(*mid, ShaderKind::kFlat, {0.9f, 0.6f, 0.3f}, true);
  EXPECT_NEAR(linear.pixel(48, 36)[0], 128, 1);
  Image stored = render(*mid, ShaderKind::kFlat);
  EXPECT_NEAR(stored.pixel(48, 36)[0], 128, 1);  // without --srgb: as stored
}

}  // namespace
}  // namespace softrast
