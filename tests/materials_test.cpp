// Materials and lighting: MTL Kd, Ks, Ns, d and maps (map_Kd, map_Ks, map_d, norm, map_Bump with
// -bm, a grey bump map as heights), the maps' placement (-s, -o, -clamp) against uvs moved in
// the file, the tutorial models' <model>_*.tga convention, a flat quad
// with a known tangent-space normal map lit as the analytic normal in five orientations (one
// with mirrored uvs), an object-space map, a point light against its analytic cosine, the
// default specular keeping the old look, and the CLI's --light-pos, --maps and --srgb.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "cli_util.hpp"
#include "softrast/image.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

// A folder of its own per test, removed at the end.
class Folder {
 public:
  Folder() {
    std::string pattern = (fs::temp_directory_path() / "softrast_mat_XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) root_ = pattern;
  }
  ~Folder() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  std::string path(const std::string& name) const { return (root_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(root_ / name, std::ios::binary) << text;
  }
  void image(const std::string& name, int w, int h, auto&& rgba_at) const {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        std::array<uint8_t, 4> c = rgba_at(x, y);
        std::copy(c.begin(), c.end(), image.pixel(x, y));
      }
    }
    ASSERT_TRUE(save_image(path(name), image).ok());
  }

 private:
  fs::path root_;
};

std::array<uint8_t, 4> rgba(int r, int g, int b, int a = 255) {
  return {uint8_t(r), uint8_t(g), uint8_t(b), uint8_t(a)};
}

constexpr const char* kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n";

TEST(Materials, MtlStatementsAndMapsAreRead) {
  Folder f;
  f.write("a.obj", std::string("mtllib a.mtl\n") + kQuadObj +
                       "usemtl m\nf 1/1/1 2/2/1 3/3/1\nusemtl plain\nf 1/1/1 3/3/1 4/4/1\n");
  f.write("a.mtl",
          "newmtl m\nKd 0.5 0.25 1\nKs 0.1 0.2 0.3\nNs 64\nd 0.5\nmap_Kd c.png\nmap_Ks s.png\n"
          "map_Bump -bm 0.5 n.png\nmap_d o.png\n"
          "newmtl plain\nKd 1 1 1\n"
          "newmtl heights\nbump h.png\n"
          "newmtl normed\nnorm n.png\nTr 0.25\n");
  f.image("c.png", 2, 2, [](int, int) { return rgba(255, 0, 0); });
  f.image("s.png", 2, 2, [](int, int) { return rgba(10, 20, 30); });
  f.image("n.png", 2, 2, [](int, int) { return rgba(128, 160, 230); });
  f.image("o.png", 2, 2, [](int, int) { return rgba(100, 100, 100); });
  // Heights rising to the right (u): the normal leans towards -u.
  f.image("h.png", 8, 8, [](int x, int) { return rgba(x * 20, x * 20, x * 20); });
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(mesh->warnings.empty()) << mesh->warnings[0];
  ASSERT_EQ(mesh->materials.size(), 4u);
  const Material& m = mesh->materials[0];
  EXPECT_EQ(m.diffuse, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_EQ(m.specular, glm::vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(m.shininess, 64.0f);
  EXPECT_EQ(m.opacity, 0.5f);
  ASSERT_TRUE(m.diffuse_map && m.specular_map && m.normal_map && m.alpha_map);
  EXPECT_EQ(m.diffuse_map->color_space(), ColorSpace::kSrgb);  // colour data
  EXPECT_EQ(m.specular_map->color_space(), ColorSpace::kLinear);
  EXPECT_EQ(m.normal_map->color_space(), ColorSpace::kLinear);
  EXPECT_EQ(m.normal_space, NormalSpace::kTangent);
  EXPECT_EQ(m.normal_scale, 0.5f);  // -bm on a normal map scales its slope in the shader
  EXPECT_EQ(glm::round(m.normal_map->texel(0, 0) * 255.0f), glm::vec4(128, 160, 230, 255));
  // A material that says nothing about its highlight keeps SCENES.md's.
  const Material& plain = mesh->materials[1];
  EXPECT_EQ(plain.specular, glm::vec3(0.4f));
  EXPECT_EQ(plain.shininess, 32.0f);
  EXPECT_EQ(plain.opacity, 1.0f);
  EXPECT_FALSE(plain.diffuse_map || plain.specular_map || plain.normal_map || plain.alpha_map);
  // A grey bump map is heights, turned into a normal map (x < 0 where heights rise with u).
  const Material& heights = mesh->materials[2];
  ASSERT_TRUE(heights.normal_map);
  EXPECT_EQ(heights.normal_scale, 1.0f);
  glm::vec4 n = heights.normal_map->texel(4, 4);
  EXPECT_LT(n.r, 0.4f);
  EXPECT_NEAR(n.g, 0.5f, 0.01f);
  EXPECT_GT(n.b, 0.7f);
  EXPECT_TRUE(mesh->materials[3].normal_map);    // norm
  EXPECT_EQ(mesh->materials[3].opacity, 0.75f);  // Tr 0.25
  // Tangent-space normal maps get tangents.
  EXPECT_EQ(mesh->tangents.size(), mesh->positions.size());
}

// Material names with spaces (assimp's space_in_material_name.obj, from LightWave): newmtl's name
// is the rest of its line, and usemtl names it with the same words, however spaced; a usemtl of
// more words than a one-word newmtl still finds it by its first word, as before.
TEST(Materials, NamesWithSpacesAreFound) {
  Folder f;
  f.write("a.obj", std::string("mtllib a.mtl\n") + kQuadObj +
                       "usemtl  Hard Shiny   Plastic White \nf 1/1/1 2/2/1 3/3/1\n"
                       "usemtl red extra words\nf 1/1/1 3/3/1 4/4/1\n");
  f.write(
      "a.mtl",
      "newmtl red\nKd 1 0 0\nnewmtl Hard Shiny Plastic White \nKd 0.141176 0.184314 0.411765\n");
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(mesh->warnings.empty()) << mesh->warnings[0];
  ASSERT_EQ(mesh->submeshes.size(), 2u);
  ASSERT_GE(mesh->submeshes[0].material, 0);
  ASSERT_GE(mesh->submeshes[1].material, 0);
  EXPECT_EQ(mesh->materials[size_t(mesh->submeshes[0].material)].diffuse,
            glm::vec3(0.141176f, 0.184314f, 0.411765f));
  EXPECT_EQ(mesh->materials[size_t(mesh->submeshes[1].material)].diffuse, glm::vec3(1, 0, 0));
}

// A library whose file name holds spaces ("mtllib my model.mtl", as Blender writes it) is that one
// file when it is there; otherwise the words are several libraries, as before.
TEST(Materials, LibraryNameWithSpacesIsOneFile) {
  Folder f;
  f.write("my model.mtl", "newmtl red\nKd 1 0 0\n");
  f.write("a.obj",
          std::string("mtllib my model.mtl\n") + kQuadObj + "usemtl red\nf 1/1/1 2/2/1 3/3/1\n");
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(mesh->warnings.empty()) << mesh->warnings[0];
  ASSERT_EQ(mesh->materials.size(), 1u);
  EXPECT_EQ(mesh->materials[0].diffuse, glm::vec3(1, 0, 0));
  // Two libraries on one line still load both.
  f.write("one.mtl", "newmtl a\nKd 0 1 0\n");
  f.write("two.mtl", "newmtl b\nKd 0 0 1\n");
  f.write("b.obj", std::string("mtllib one.mtl two.mtl\n") + kQuadObj +
                       "usemtl a\nf 1/1/1 2/2/1 3/3/1\nusemtl b\nf 1/1/1 3/3/1 4/4/1\n");
  Result<Mesh> two = load_obj(f.path("b.obj"));
  ASSERT_TRUE(two.ok()) << two.status().message();
  EXPECT_TRUE(two->warnings.empty()) << two->warnings[0];
  EXPECT_EQ(two->materials.size(), 2u);
}

// illum 0 and 1 have no specular term, and Ns 0 means no highlight (3ds Max's Max2Mtl writes Ks 0.9
// with Ns 0 for a material without one; Blinn-Phong would light the whole side white): their Ks
// becomes 0. illum 2 with an exponent keeps its Ks, and a material that gives neither keeps the
// default.
TEST(Materials, IllumAndZeroShininessTurnTheHighlightOff) {
  Folder f;
  f.write("a.obj", std::string("mtllib a.mtl\n") + kQuadObj + "usemtl flat\nf 1/1/1 2/2/1 3/3/1\n");
  f.write("a.mtl",
          "newmtl flat\nKs 0.9 0.9 0.9\nillum 1\n"
          "newmtl dull\nKs 0.9 0.9 0.9\nNs 0.0\nillum 2\n"
          "newmtl shiny\nKs 0.9 0.9 0.9\nNs 10\nillum 2\n"
          "newmtl plain\nKd 1 1 1\n");
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 4u);
  EXPECT_EQ(mesh->materials[0].specular, glm::vec3(0.0f));
  EXPECT_EQ(mesh->materials[1].specular, glm::vec3(0.0f));
  EXPECT_EQ(mesh->materials[2].specular, glm::vec3(0.9f));
  EXPECT_EQ(mesh->materials[2].shininess, 10.0f);
  EXPECT_EQ(mesh->materials[3].specular, glm::vec3(0.4f));
}

TEST(Materials, BadMtlValuesAreErrorsAndMissingMapsWarnings) {
  Folder f;
  f.write("a.obj", std::string("mtllib a.mtl\n") + kQuadObj + "usemtl m\nf 1/1/1 2/2/1 3/3/1\n");
  f.write("a.mtl", "newmtl m\nNs 5000\n");
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            f.path("a.obj") + ": Ns of material 'm' is 5000.000000; it must be in [0, 1000]");
  f.write("a.mtl", "newmtl m\nmap_Ks nowhere.png\n");
  mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_NE(mesh->warnings[0].find("material 'm': map_Ks: "), std::string::npos)
      << mesh->warnings[0];
  EXPECT_FALSE(mesh->materials[0].specular_map);
}

TEST(Materials, TutorialConventionMapsBesideTheObjArePickedUp) {
  Folder f;
  f.write("m.obj", std::string(kQuadObj) + "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
  f.image("m_diffuse.tga", 4, 4, [](int, int) { return rgba(200, 100, 50); });
  f.image("m_spec.tga", 4, 4, [](int, int) { return rgba(30, 30, 30); });
  f.image("m_nm_tangent.tga", 4, 4, [](int, int) { return rgba(128, 128, 255); });
  f.image("m_nm.tga", 4, 4, [](int, int) { return rgba(128, 128, 255); });
  Result<Mesh> mesh = load_obj(f.path("m.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 1u);
  const Material& m = mesh->materials[0];
  EXPECT_EQ(m.name, "m");
  EXPECT_TRUE(m.diffuse_map && m.specular_map && m.normal_map);
  EXPECT_EQ(m.normal_space, NormalSpace::kTangent);  // _nm_tangent wins over _nm
  for (const SubMesh& run : mesh->submeshes) EXPECT_EQ(run.material, 0);
  EXPECT_EQ(mesh->tangents.size(), mesh->positions.size());
  // Only the object-space map: object space, no tangents needed.
  fs::remove(f.path("m_nm_tangent.tga"));
  mesh = load_obj(f.path("m.obj"));
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->materials[0].normal_space, NormalSpace::kObject);
  EXPECT_TRUE(mesh->tangents.empty());
  // A model with an MTL of its own uses that, not the convention.
  f.write("m.mtl", "newmtl own\nKd 1 0 0\n");
  f.write("m.obj", std::string("mtllib m.mtl\n") + kQuadObj + "usemtl own\nf 1/1/1 2/2/1 3/3/1\n");
  mesh = load_obj(f.path("m.obj"));
  ASSERT_TRUE(mesh.ok());
  ASSERT_EQ(mesh->materials.size(), 1u);
  EXPECT_EQ(mesh->materials[0].name, "own");
  EXPECT_FALSE(mesh->materials[0].diffuse_map);
}

// ------------------------------------------------------------------------------------------
// Lighting against analytic values.

// A 2x2 quad centred at the origin, spanning `a` and `b` (uv (0, 0) at -a - b, u along a, v
// along b), its vertex normal `n`, one white diffuse-only material.
Mesh quad(glm::vec3 a, glm::vec3 b, glm::vec3 n) {
  Mesh mesh;
  mesh.positions = {-a - b, a - b, a + b, -a + b};
  mesh.normals.assign(4, n);
  mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  Material m;
  m.diffuse = glm::vec3(1.0f);
  m.specular = glm::vec3(0.0f);
  mesh.materials.push_back(m);
  mesh.submeshes.push_back({0, 6, 0});
  return mesh;
}

RenderOptions diffuse_only(glm::vec3 light) {
  RenderOptions options;
  options.shader = ShaderKind::kPhong;
  options.ambient = 0.0f;
  options.light_direction = light;
  options.state.cull = CullMode::kNone;
  options.two_sided_lighting = false;
  return options;
}

// The red of the pixels in the middle of the image (the quad fills it), as 0..255.
std::vector<int> middle_reds(const Framebuffer& fb) {
  std::vector<int> reds;
  for (int y = fb.height() / 3; y < 2 * fb.height() / 3; ++y) {
    for (int x = fb.width() / 3; x < 2 * fb.width() / 3; ++x)
      reds.push_back(fb.color_at(x, y) & 0xff);
  }
  return reds;
}

Framebuffer render_facing(const Mesh& mesh, glm::vec3 n, const RenderOptions& options) {
  Camera camera;
  camera.eye = n * 4.0f;
  camera.target = glm::vec3(0.0f);
  camera.up = std::abs(n.y) > 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  Framebuffer fb(96, 96);
  fb.clear();
  render_mesh(fb, mesh, camera, options);
  return fb;
}

// The maps' placement options: -s and -o (u and v, with or without v and w) and -clamp, from
// map_Kd, else from the first map that has any; maps placed differently are a warning; a number
// out of float's range an error.
TEST(Materials, MapPlacementOptionsAreRead) {
  Folder f;
  f.write("a.obj", std::string("mtllib a.mtl\n") + kQuadObj + "usemtl m\nf 1/1/1 2/2/1 3/3/1\n");
  f.image("c.png", 2, 2, [](int, int) { return rgba(255, 0, 0); });
  f.image("s.png", 2, 2, [](int, int) { return rgba(10, 20, 30); });
  f.write("a.mtl",
          "newmtl m\nmap_Kd -s 2 3 -o 0.25 -0.5 0 -clamp on c.png\n"
          "newmtl plain\nmap_Kd c.png\n"
          "newmtl spec\nmap_Ks -o 0.5 0.75 s.png\n"
          "newmtl differ\nmap_Kd c.png\nmap_Ks -s 4 4 s.png\n");
  Result<Mesh> mesh = load_obj(f.path("a.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 4u);
  const Material& m = mesh->materials[0];
  EXPECT_EQ(m.uv_scale, glm::vec2(2.0f, 3.0f));
  EXPECT_EQ(m.uv_offset, glm::vec2(0.25f, -0.5f));
  EXPECT_TRUE(m.clamp_maps);
  const Material& plain = mesh->materials[1];
  EXPECT_EQ(plain.uv_scale, glm::vec2(1.0f));
  EXPECT_EQ(plain.uv_offset, glm::vec2(0.0f));
  EXPECT_FALSE(plain.clamp_maps);
  EXPECT_TRUE(m.diffuse_map);
  // No map_Kd: the first map with options places them all. (Two numbers: tinyobj alone would
  // take the file's name for w and lose the map.)
  EXPECT_EQ(mesh->materials[2].uv_offset, glm::vec2(0.5f, 0.75f));
  EXPECT_TRUE(mesh->materials[2].specular_map);
  // map_Kd without options wins over a map_Ks with some; the difference is a warning.
  EXPECT_EQ(mesh->materials[3].uv_scale, glm::vec2(1.0f));
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_NE(mesh->warnings[0].find("material 'differ': map_Ks: its -s, -o or -clamp differ from "
                                   "map_Kd's"),
            std::string::npos)
      << mesh->warnings[0];
  f.write("a.mtl", "newmtl m\nmap_Kd -s 1e999 1 c.png\n");
  mesh = load_obj(f.path("a.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), f.path("a.mtl") + ":2: number 1e999 is out of range");
}

// A material's -s and -o move its texture as the same change of the file's uvs does, in every
// shader that reads maps, and -clamp on clamps it as the clamp-to-edge sampler does: the images
// are the same bit for bit, and differ from the unplaced texture's.
TEST(Materials, MapPlacementMovesTheTextureAsTheUvsWould) {
  Folder f;
  // 4x4 texels of distinct colours: a repeat or a shift shows.
  f.image("c.png", 4, 4, [](int x, int y) { return rgba(60 * x + 10, 60 * y + 10, 90); });
  const std::string faces = "usemtl m\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  const std::string quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\n";
  // The same quad with uv * (2, 1.5) + (0.25, -0.5) written out: exact in float.
  f.write("placed.obj", "mtllib placed.mtl\n" + quad + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" + faces);
  f.write("placed.mtl", "newmtl m\nmap_Kd -s 2 1.5 1 -o 0.25 -0.5 0 c.png\n");
  f.write("moved.obj", "mtllib moved.mtl\n" + quad +
                           "vt 0.25 -0.5\nvt 2.25 -0.5\nvt 2.25 1\nvt 0.25 1\n" + faces);
  f.write("moved.mtl", "newmtl m\nmap_Kd c.png\n");
  f.write("clamped.mtl", "newmtl m\nmap_Kd -s 2 1.5 1 -o 0.25 -0.5 0 -clamp on c.png\n");
  f.write("clamped.obj",
          "mtllib clamped.mtl\n" + quad + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" + faces);
  f.write("unplaced.mtl", "newmtl m\nmap_Kd c.png\n");
  f.write("unplaced.obj",
          "mtllib unplaced.mtl\n" + quad + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" + faces);
  Result<Mesh> placed = load_obj(f.path("placed.obj")), moved = load_obj(f.path("moved.obj"));
  Result<Mesh> clamped = load_obj(f.path("clamped.obj"));
  Result<Mesh> unplaced = load_obj(f.path("unplaced.obj"));
  ASSERT_TRUE(placed.ok() && moved.ok() && clamped.ok() && unplaced.ok());
  auto same = [](const Framebuffer& a, const Framebuffer& b) {
    for (int y = 0; y < a.height(); ++y) {
      for (int x = 0; x < a.width(); ++x) {
        if (a.color_at(x, y) != b.color_at(x, y)) return false;
      }
    }
    return true;
  };
  for (ShaderKind shader : {ShaderKind::kTexture, ShaderKind::kPhong, ShaderKind::kPbr}) {
    SCOPED_TRACE(int(shader));
    RenderOptions options;
    options.shader = shader;
    options.state.cull = CullMode::kNone;
    const glm::vec3 facing(0, 0, 1);
    Framebuffer a = render_facing(*placed, facing, options);
    Framebuffer b = render_facing(*moved, facing, options);
    EXPECT_TRUE(same(a, b)) << "-s and -o should read the texture where the moved uvs do";
    EXPECT_FALSE(same(a, render_facing(*unplaced, facing, options)));
    Framebuffer c = render_facing(*clamped, facing, options);
    EXPECT_FALSE(same(c, b)) << "-clamp on should not repeat the texture";
    RenderOptions clamping = options;
    clamping.sampler.wrap_u = clamping.sampler.wrap_v = Wrap::kClampToEdge;
    EXPECT_TRUE(same(c, render_facing(*moved, facing, clamping)));
  }
}

// A flat quad with a constant tangent-space normal map m, in five orientations: rotated in its
// plane by 0, 90 and 180 degrees, turned to face +x, and with mirrored u (tangent handedness
// -1). Every pixel is lit as the analytic normal T m.x + B m.y + N m.z (T along u, B along v),
// within 2/255, and that differs from the unmapped normal's light by far more.
TEST(NormalMapping, TangentSpaceQuadIsLitAsTheAnalyticNormalInEveryOrientation) {
  const uint8_t mr = 200, mg = 90, mb = 215;  // the map's texel
  glm::vec3 m = glm::vec3(mr, mg, mb) / 255.0f * 2.0f - 1.0f;
  Image texel(2, 2);
  for (size_t p = 0; p < 4; ++p) {
    texel.rgba[p * 4] = mr, texel.rgba[p * 4 + 1] = mg, texel.rgba[p * 4 + 2] = mb;
    texel.rgba[p * 4 + 3] = 255;
  }
  auto map = std::make_shared<const Texture>(Texture::from_image(texel));
  const glm::vec3 light = glm::normalize(glm::vec3(0.3f, -0.4f, 0.8f) + glm::vec3(0.5f, 0, 0));
  struct Orientation {
    const char* name;
    glm::vec3 a, b, n;
  };
  const Orientation cases[] = {
      {"facing +z", {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
      {"rotated 90", {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}},
      {"rotated 180", {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}},
      {"facing +x", {0, 0, -1}, {0, 1, 0}, {1, 0, 0}},
      {"mirrored u", {-1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
  };
  for (const Orientation& o : cases) {
    SCOPED_TRACE(o.name);
    Mesh mesh = quad(o.a, o.b, o.n);
    mesh.materials[0].normal_map = map;
    compute_tangents(mesh);
    glm::vec3 mapped = glm::normalize(o.a * m.x + o.b * m.y + o.n * m.z);
    int expect = int(0.85f * std::max(glm::dot(mapped, light), 0.0f) * 255.0f + 0.5f);
    int flat = int(0.85f * std::max(glm::dot(o.n, light), 0.0f) * 255.0f + 0.5f);
    ASSERT_GT(std::abs(expect - flat), 25) << "the map must make a visible difference";
    Framebuffer fb = render_facing(mesh, o.n, diffuse_only(light));
    for (int red : middle_reds(fb)) ASSERT_NEAR(red, expect, 2);
  }
}

// An object-space map: the normal is the map's value itself, whatever the geometry's normal.
TEST(NormalMapping, ObjectSpaceMapReplacesTheNormal) {
  Image texel(1, 1);
  texel.rgba = {230, 128, 160, 255};
  Mesh mesh = quad({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  mesh.materials[0].normal_map = std::make_shared<const Texture>(Texture::from_image(texel));
  mesh.materials[0].normal_space = NormalSpace::kObject;
  glm::vec3 n = glm::normalize(glm::vec3(230, 128, 160) / 255.0f * 2.0f - 1.0f);
  glm::vec3 light = glm::normalize(glm::vec3(1, 0.2f, 0.5f));
  int expect = int(0.85f * glm::dot(n, light) * 255.0f + 0.5f);
  Framebuffer fb = render_facing(mesh, {0, 0, 1}, diffuse_only(light));
  for (int red : middle_reds(fb)) ASSERT_NEAR(red, expect, 2);
}

// A point light 0.6 above the middle of a quad seen straight on (orthographic): every pixel is
// 0.85 cos(angle to the light) of its own position, within 2/255 (the light does not fall off).
TEST(Lighting, PointLightMatchesTheAnalyticCosine) {
  Mesh mesh = quad({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  RenderOptions options = diffuse_only({0, 0, 1});
  const glm::vec3 lamp(0.2f, -0.1f, 0.6f);
  options.light_position = lamp;
  Camera camera;
  camera.eye = {0, 0, 5};
  camera.orthographic = true;
  Framebuffer fb(64, 64);
  fb.clear();
  render_mesh(fb, mesh, camera, options);
  int lo = 255, hi = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      glm::vec3 p(-1.0f + (x + 0.5f) / 32.0f, 1.0f - (y + 0.5f) / 32.0f, 0.0f);
      float c = glm::normalize(lamp - p).z;
      int expect = int(0.85f * c * 255.0f + 0.5f), red = int(fb.color_at(x, y) & 0xff);
      ASSERT_NEAR(red, expect, 2) << "pixel " << x << "," << y;
      lo = std::min(lo, red), hi = std::max(hi, red);
    }
  }
  EXPECT_GT(hi - lo, 100);  // the light is local: far brighter below it than at the corners
}

// A material that gives no Ks or Ns looks exactly as a mesh without materials (SCENES.md's 0.4
// and 32); Ks 0 removes the highlight, Ns 8 widens it.
TEST(Lighting, DefaultSpecularKeepsTheOldLookAndKsNsChangeIt) {
  Mesh plain = quad({1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  plain.materials.clear();
  plain.submeshes.clear();
  Mesh with_material = plain;
  Material m;  // Kd is SCENES.md's albedo, as the options' colour
  with_material.materials.push_back(m);
  with_material.submeshes.push_back({0, 6, 0});
  RenderOptions options;
  options.light_direction = {0.1f, 0.2f, 1.0f};
  auto render = [&](const Mesh& mesh) { return render_facing(mesh, {0, 0, 1}, options); };
  Framebuffer a = render(plain), b = render(with_material);
  int highlight_a = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      ASSERT_EQ(a.color_at(x, y), b.color_at(x, y)) << x << "," << y;
      highlight_a = std::max(highlight_a, int((a.color_at(x, y) >> 16) & 0xff));
    }
  }
  with_material.materials[0].specular = glm::vec3(0.0f);
  Framebuffer dull = render(with_material);
  int highlight_dull = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      highlight_dull = std::max(highlight_dull, int((dull.color_at(x, y) >> 16) & 0xff));
    }
  }
  EXPECT_GT(highlight_a, highlight_dull + 40);  // blue: 0.3 albedo, the highlight adds 0.4
  with_material.materials[0].specular = glm::vec3(0.4f);
  with_material.materials[0].shininess = 8.0f;
  Framebuffer wide = render(with_material);
  int bright_a = 0, bright_wide = 0;
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 96; ++x) {
      bright_a += ((a.color_at(x, y) >> 16) & 0xff) > 150;
      bright_wide += ((wide.color_at(x, y) >> 16) & 0xff) > 150;
    }
  }
  EXPECT_GT(bright_wide, 2 * bright_a);
}

// The African head comes with the same detail baked twice: a tangent-space map (_nm_tangent)
// and an object-space one (_nm). Lit from the side, both render the same image (mean difference
// under 0.5/255, 99 % of channels within 2): the tangent frame (MikkTSpace's convention, the
// bitangent w (n x t), green = +v) agrees with the tool that baked the maps.
TEST(NormalMapping, TangentAndObjectSpaceMapsOfTheHeadAgree) {
  const fs::path dir = fs::path(SOFTRAST_SHARED_DIR) / "models/african_head";
  if (!fs::exists(dir / "african_head.obj")) GTEST_SKIP() << dir << " not found";
  Result<Mesh> tangent = load_obj((dir / "african_head.obj").string());
  ASSERT_TRUE(tangent.ok()) << tangent.status().message();
  ASSERT_EQ(tangent->materials[0].normal_space, NormalSpace::kTangent);
  Result<Image> object_map = load_image((dir / "african_head_nm.tga").string());
  ASSERT_TRUE(object_map.ok());
  Mesh object = *tangent;
  object.materials[0].normal_map =
      std::make_shared<const Texture>(Texture::from_image(*object_map));
  object.materials[0].normal_space = NormalSpace::kObject;
  RenderOptions options;
  options.light_direction = {1.0f, 0.2f, 0.3f};
  options.state.cull = CullMode::kNone;
  Camera camera;
  camera.eye = {0, 0, 3.2f};
  auto render = [&](const Mesh& mesh) {
    auto fb = std::make_unique<Framebuffer>(200, 200);
    fb->clear();
    render_mesh(*fb, mesh, camera, options);
    return fb;
  };
  auto a = render(*tangent), b = render(object);
  std::vector<int> diffs;
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      for (int c = 0; c < 24; c += 8) {
        diffs.push_back(
            std::abs(int((a->color_at(x, y) >> c) & 0xff) - int((b->color_at(x, y) >> c) & 0xff)));
      }
    }
  }
  double mean = 0.0;
  for (int d : diffs) mean += d;
  mean /= double(diffs.size());
  std::sort(diffs.begin(), diffs.end());
  EXPECT_LT(mean, 0.5);
  EXPECT_LE(diffs[diffs.size() * 99 / 100], 2);
  // And the map matters: without it the image is far from both.
  Mesh bare = *tangent;
  bare.materials[0].normal_map = nullptr;
  auto c = render(bare);
  double bare_mean = 0.0;
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      bare_mean += std::abs(int(a->color_at(x, y) & 0xff) - int(c->color_at(x, y) & 0xff));
    }
  }
  EXPECT_GT(bare_mean / (200.0 * 200.0), 4 * mean);
}

#ifdef SOFTRAST_CLI_PATH

TEST(MaterialsCli, LightPosMapsAndSrgbFlags) {
  test::CliFolder folder;
  test::CliResult both = folder.run("--light 0,0,1 --light-pos 1,2,3 -o x.png");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.err.find("--light-pos: a point light has no direction"), std::string::npos)
      << both.err;
  EXPECT_FALSE(fs::exists(folder.path("x.png")));
  test::CliResult maps = folder.run("--maps some -o x.png");
  EXPECT_NE(maps.exit_code, 0);
  EXPECT_NE(maps.err.find("--maps"), std::string::npos) << maps.err;
  test::CliResult bad_pos = folder.run("--light-pos 1,2 -o x.png");
  EXPECT_NE(bad_pos.exit_code, 0);
  EXPECT_NE(bad_pos.err.find("--light-pos"), std::string::npos) << bad_pos.err;
  // --srgb encodes the output: linear 0.5 is written as 188 (sRGB 0.7354).
  folder.write("q.obj", std::string(kQuadObj) + "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
  Image linear = folder.render("q.obj --shader flat --color 0.5,0.5,0.5 --size 32x32");
  Image srgb = folder.render("q.obj --shader flat --color 0.5,0.5,0.5 --size 32x32 --srgb");
  ASSERT_FALSE(linear.rgba.empty() || srgb.rgba.empty());
  EXPECT_EQ(linear.pixel(16, 16)[0], 128);
  EXPECT_EQ(srgb.pixel(16, 16)[0], 188);
  EXPECT_EQ(folder.run("q.obj --light-pos 0,0,2 --maps diffuse -q -o p.png").exit_code, 0);
}

// The real models render with every map by the plain command, and the maps change the image.
TEST(MaterialsCli, SharedModelsPickUpTheirMapsWithNoFlag) {
  const fs::path head = fs::path(SOFTRAST_SHARED_DIR) / "models/african_head/african_head.obj";
  if (!fs::exists(head)) GTEST_SKIP() << head << " not found";
  Result<Mesh> mesh = load_obj(head.string());
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 1u);
  const Material& m = mesh->materials[0];
  EXPECT_TRUE(m.diffuse_map && m.specular_map && m.normal_map);
  EXPECT_EQ(m.normal_space, NormalSpace::kTangent);
  test::CliFolder folder;
  Image all = folder.render(test::shell_quote(head.string()) + " --size 160x160", "all.png");
  Image diffuse =
      folder.render(test::shell_quote(head.string()) + " --size 160x160 --maps diffuse", "d.png");
  ASSERT_EQ(all.rgba.size(), diffuse.rgba.size());
  size_t differ = 0;
  for (size_t k = 0; k < all.rgba.size(); ++k) differ += all.rgba[k] != diffuse.rgba[k];
  EXPECT_GT(differ, all.rgba.size() / 20);
}

#endif  // SOFTRAST_CLI_PATH

}  // namespace
}  // namespace softrast
