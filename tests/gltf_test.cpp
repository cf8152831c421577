// glTF 2.0: files the tests write (tests/gltf_util.hpp) loaded through load_model and drawn with
// the pbr shader. The .gltf and .glb forms of one scene give the same image; node transforms put
// vertices where the matrices say (mirroring reverses the winding and the tangent handedness); a
// sphere grid of metallic x roughness matches its golden image; every bad input of issue 6 is one
// error line, a non-zero exit and no output file.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "cli_util.hpp"
#include "gltf_util.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using test::GltfParts;

class GltfTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_gltf_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    png_ = test::checker_png((dir_ / "checker.png").string());
    ASSERT_FALSE(png_.empty());
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& bytes) {
    std::ofstream((dir_ / name), std::ios::binary) << bytes;
    return (dir_ / name).string();
  }
  fs::path dir_;
  std::string png_;
};

Image render(const Mesh& mesh, int size, ShaderKind shader = ShaderKind::kPbr) {
  Camera camera;
  camera.eye = {1.2f, 1.0f, 2.2f};
  camera.target = {0.2f, 0.0f, 0.0f};
  camera.near_plane = 0.1f;
  camera.far_plane = 20.0f;
  RenderOptions options;
  options.shader = shader;
  options.light_direction = glm::normalize(glm::vec3(0.4f, 0.8f, 0.6f));
  Framebuffer fb(size, size);
  fb.clear_color(glm::vec4(0.1f, 0.1f, 0.1f, 1.0f));
  fb.clear_depth(1.0f);
  render_mesh(fb, mesh, camera, options);
  return fb.to_image();
}

TEST_F(GltfTest, GltfAndGlbOfOneSceneRenderIdentically) {
  GltfParts cube = test::textured_cube(png_);
  Result<Mesh> text = load_model(write("cube.gltf", test::as_gltf(cube)));
  Result<Mesh> binary = load_model(write("cube.glb", test::as_glb(cube)));
  ASSERT_TRUE(text.ok()) << text.status().message();
  ASSERT_TRUE(binary.ok()) << binary.status().message();
  EXPECT_EQ(text->triangle_count(), 12u);
  ASSERT_EQ(text->materials.size(), 1u);
  ASSERT_TRUE(text->materials[0].pbr.has_value());
  ASSERT_TRUE(text->materials[0].pbr->base_color_map);    // the data-URI image was decoded
  ASSERT_TRUE(binary->materials[0].pbr->base_color_map);  // and the bufferView one
  EXPECT_TRUE(text->warnings.empty()) << text->warnings[0];
  Image a = render(*text, 96), b = render(*binary, 96);
  ASSERT_EQ(a.rgba, b.rgba);
  // Not trivially equal: the cube covers a good part of the image and shows both the checker's
  // reddish and white texels.
  int covered = 0, red = 0, white = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4) {
    int r = a.rgba[i], g = a.rgba[i + 1];
    if (r != a.rgba[0] || g != a.rgba[1]) ++covered;
    if (r > g + 60) ++red;
    if (r > 120 && g > 120 && std::abs(r - g) < 20) ++white;
  }
  EXPECT_GT(covered, 96 * 96 / 8);
  EXPECT_GT(red, 50);
  EXPECT_GT(white, 50);
}

// KHR_texture_transform, the extension's own example: offset (0, 1), rotation pi/2 and scale 0.5
// "utilizes only the lower left quadrant of the source image, rotated clockwise 90 degrees". In
// glTF's uvs (v down) the surface's point (u, v) reads the image at (v / 2, 1 - u / 2): the
// surface's top-left corner shows the quadrant's bottom-left one. (Khronos's
// TextureTransformTest model turns the same way: its arrows point at the green markers.)
// softrast's uvs have v up: (u, v) here is glTF's (u, 1 - v).
TEST_F(GltfTest, TextureTransformTurnsAsTheExtensionsExampleSays) {
  GltfParts cube = test::textured_cube(png_);
  cube.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
      {"KHR_texture_transform",
       {{"offset", {0.0, 1.0}}, {"rotation", 1.5707963267948966}, {"scale", {0.5, 0.5}}}}};
  cube.json["extensionsUsed"] = {"KHR_texture_transform"};
  Result<Mesh> mesh = load_model(write("transformed.gltf", test::as_gltf(cube)));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_TRUE(mesh->materials[0].pbr.has_value());
  const TextureSlot& slot = mesh->materials[0].pbr->base_color_map;
  ASSERT_TRUE(slot.transformed);
  for (float u : {0.0f, 0.25f, 1.0f}) {
    for (float v : {0.0f, 0.5f, 0.9f}) {
      const float gu = u, gv = 1.0f - v;  // glTF's uv of the surface point
      const float image_u = gv / 2.0f, image_v = 1.0f - gu / 2.0f;  // where it reads, glTF's uv
      const glm::vec3 p(u, v, 1.0f);
      EXPECT_NEAR(glm::dot(slot.u_row, p), image_u, 1e-5f) << u << ", " << v;
      EXPECT_NEAR(glm::dot(slot.v_row, p), 1.0f - image_v, 1e-5f) << u << ", " << v;
    }
  }
}

// The line and point modes: the cube's 36 indices as LINES (18 segments), LINE_STRIP (35),
// LINE_LOOP (36, the last back to the first) and POINTS (36), each index where the triangles would
// have it.
TEST_F(GltfTest, LineAndPointModesBecomeLinesAndPoints) {
  Result<Mesh> triangles = load_model(write("tri.gltf", test::as_gltf(test::textured_cube(png_))));
  ASSERT_TRUE(triangles.ok()) << triangles.status().message();
  struct Mode {
    int mode;
    size_t segments, points;
  };
  for (Mode m : {Mode{1, 18, 0}, Mode{3, 35, 0}, Mode{2, 36, 0}, Mode{0, 0, 36}}) {
    GltfParts g = test::textured_cube(png_);
    g.json["meshes"][0]["primitives"][0]["mode"] = m.mode;
    Result<Mesh> mesh = load_model(write("mode.gltf", test::as_gltf(g)));
    ASSERT_TRUE(mesh.ok()) << m.mode << ": " << mesh.status().message();
    EXPECT_EQ(mesh->triangle_count(), 0u) << m.mode;
    ASSERT_EQ(mesh->line_indices.size(), 2 * m.segments) << m.mode;
    ASSERT_EQ(mesh->point_indices.size(), m.points) << m.mode;
    // The file's index order, on vertices placed as the triangles' were (the node transforms).
    std::vector<glm::vec3> file_order;
    for (uint32_t i : triangles->indices) file_order.push_back(triangles->positions[i]);
    // Corner k of the list: where the triangles' corner k is (LINES pairs the list, the strip and
    // the loop join each corner to the next).
    auto at = [&](uint32_t i) { return mesh->positions[i]; };
    for (size_t k = 0; k < m.points; ++k) EXPECT_EQ(at(mesh->point_indices[k]), file_order[k]) << k;
    for (size_t j = 0; j < m.segments; ++j) {
      size_t a = m.mode == 1 ? 2 * j : j, b = (a + 1) % file_order.size();
      EXPECT_EQ(at(mesh->line_indices[2 * j]), file_order[a]) << m.mode << " " << j;
      EXPECT_EQ(at(mesh->line_indices[2 * j + 1]), file_order[b]) << m.mode << " " << j;
    }
  }
}

// Node 0 translates by (0.25, 0, 0); its child node 1 turns by 30 degrees about y and scales by
// 0.8: every loaded corner is T * R * S of a corner of the unit cube.
TEST_F(GltfTest, NodeTransformsPlaceEveryVertex) {
  Result<Mesh> mesh = load_model(write("cube.gltf", test::as_gltf(test::textured_cube(png_))));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->vertex_count(), 24u);
  const double angle = 30.0 * 3.14159265358979 / 180.0;
  int matched = 0;
  for (const glm::vec3& p : mesh->positions) {
    // Undo the transforms in double, by hand: translate back, turn back, unscale.
    double x = p.x - 0.25, y = p.y, z = p.z;
    double ux = std::cos(angle) * x - std::sin(angle) * z;
    double uz = std::sin(angle) * x + std::cos(angle) * z;
    double cx = ux / 0.8, cy = y / 0.8, cz = uz / 0.8;
    bool corner = std::abs(std::abs(cx) - 0.5) < 1e-5 && std::abs(std::abs(cy) - 0.5) < 1e-5 &&
                  std::abs(std::abs(cz) - 0.5) < 1e-5;
    matched += corner;
    EXPECT_TRUE(corner) << p.x << "," << p.y << "," << p.z;
  }
  EXPECT_EQ(matched, 24);
  // The +x face's normal turned by 30 degrees about y: (cos 30, 0, -sin 30).
  bool found = false;
  for (const glm::vec3& n : mesh->normals) {
    if (glm::length(n - glm::vec3(std::cos(angle), 0.0f, -std::sin(angle))) < 1e-5f) found = true;
  }
  EXPECT_TRUE(found);
}

// Adds to accessor `accessor` a sparse block of `indices` (uint8, 5121; uint16, 5123; uint32,
// 5125) and `values` (the accessor's element type, tightly packed), each in a bufferView of its
// own.
void add_sparse(GltfParts& g, int accessor, int index_type, const std::vector<uint32_t>& indices,
                const std::string& values) {
  std::string index_bytes;
  for (uint32_t i : indices) {
    int width = index_type == 5121 ? 1 : index_type == 5123 ? 2 : 4;
    index_bytes.append(reinterpret_cast<const char*>(&i), size_t(width));  // little-endian
  }
  auto view_of = [&](const std::string& bytes) {
    while (g.bin.size() % 4) g.bin += '\0';
    int view = int(g.json["bufferViews"].size());
    g.json["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", g.bin.size()}, {"byteLength", bytes.size()}});
    g.bin += bytes;
    return view;
  };
  int index_view = view_of(index_bytes), value_view = view_of(values);
  g.json["accessors"][size_t(accessor)]["sparse"] = {
      {"count", indices.size()},
      {"indices", {{"bufferView", index_view}, {"componentType", index_type}}},
      {"values", {{"bufferView", value_view}}}};
}

void expect_same_mesh(const Mesh& a, const Mesh& b, const char* what) {
  EXPECT_EQ(a.positions, b.positions) << what;
  EXPECT_EQ(a.normals, b.normals) << what;
  EXPECT_EQ(a.uvs, b.uvs) << what;
  EXPECT_EQ(a.indices, b.indices) << what;
}

// Sparse accessors (glTF 2.0, 3.6.2.3): the elements their strictly increasing indices name take
// their values, the others the bufferView's, or zeros where the accessor has no bufferView (also
// without sparse). Each file is loaded beside the same scene with the values written directly
// into its buffer: the meshes must be equal, element for element. Before, a sparse accessor
// refused the whole file.
TEST_F(GltfTest, SparseAccessorsAndAccessorsWithoutAViewReadAsWritten) {
  const GltfParts cube = test::textured_cube(png_);
  auto load = [&](const GltfParts& g, const char* name) {
    Result<Mesh> mesh = load_model(write(name, test::as_gltf(g)));
    EXPECT_TRUE(mesh.ok()) << name << ": " << mesh.status().message();
    return mesh.ok() ? *mesh : Mesh();
  };
  auto floats_of = [](const GltfParts& g, int accessor) {
    const nlohmann::json& a = g.json["accessors"][size_t(accessor)];
    const nlohmann::json& v = g.json["bufferViews"][size_t(a["bufferView"].get<int>())];
    return g.bin.substr(v["byteOffset"].get<size_t>(), v["byteLength"].get<size_t>());
  };
  // Positions (accessor 0): vertices 2, 7 and 23 moved, by uint8, uint16 and uint32 indices.
  for (int index_type : {5121, 5123, 5125}) {
    GltfParts sparse = cube, direct = cube;
    std::vector<float> moved = {0.7f, -0.6f, 0.5f, 0.1f, 0.9f, -0.3f, -0.8f, 0.2f, 0.6f};
    add_sparse(sparse, 0, index_type, {2, 7, 23}, test::float_bytes(moved));
    std::string positions = floats_of(direct, 0);
    const size_t offset = direct.json["bufferViews"][0]["byteOffset"].get<size_t>();
    for (int k = 0; k < 3; ++k) {
      size_t vertex = std::vector<size_t>{2, 7, 23}[size_t(k)];
      std::memcpy(&direct.bin[offset + vertex * 12], &moved[size_t(3 * k)], 12);
    }
    ASSERT_EQ(positions.size(), 288u);
    expect_same_mesh(load(sparse, "sparse.gltf"), load(direct, "direct.gltf"), "positions");
  }
  // Texture coordinates (accessor 2) with no bufferView: zeros, then all 24 given sparsely.
  {
    GltfParts zeros = cube, zeros_direct = cube;
    zeros.json["accessors"][2].erase("bufferView");
    const size_t offset = zeros_direct.json["bufferViews"][2]["byteOffset"].get<size_t>();
    std::memset(&zeros_direct.bin[offset], 0, 24 * 8);
    expect_same_mesh(load(zeros, "zeros.gltf"), load(zeros_direct, "zeros_direct.gltf"), "zeros");
    GltfParts filled = cube;
    std::string uvs = floats_of(cube, 2);
    filled.json["accessors"][2].erase("bufferView");
    std::vector<uint32_t> all(24);
    for (uint32_t i = 0; i < 24; ++i) all[i] = i;
    add_sparse(filled, 2, 5121, all, uvs);
    expect_same_mesh(load(filled, "filled.gltf"), load(cube, "cube.gltf"), "filled");
  }
  // Indices (accessor 3, uint16): triangle 1's corners given sparsely as triangle 0's.
  {
    GltfParts sparse = cube, direct = cube;
    add_sparse(sparse, 3, 5123, {3, 4, 5}, test::u16_bytes({0, 2, 3}));
    uint16_t corners[3] = {0, 2, 3};
    std::memcpy(&direct.bin[direct.index_offset + 6], corners, 6);
    expect_same_mesh(load(sparse, "sparse_i.gltf"), load(direct, "direct_i.gltf"), "indices");
  }
}

// With a mirroring scale the triangles are rewound so that they still face outwards, and the
// tangents (computed for the normal map) change handedness.
TEST_F(GltfTest, MirroringNodeKeepsFacesOutwardAndFlipsTangentHandedness) {
  auto load = [&](double sx, const std::string& name) {
    GltfParts g = test::textured_cube(png_);
    g.json["nodes"][1]["scale"] = {sx, 0.8, 0.8};
    g.json["materials"][0]["normalTexture"] = {{"index", 0}};  // any map: tangents are needed
    Result<Mesh> mesh = load_model(write(name, test::as_gltf(g)));
    EXPECT_TRUE(mesh.ok()) << mesh.status().message();
    return mesh.ok() ? *mesh : Mesh{};
  };
  Mesh plain = load(0.8, "plain.gltf"), mirrored = load(-0.8, "mirrored.gltf");
  ASSERT_EQ(plain.tangents.size(), 24u);
  ASSERT_EQ(mirrored.tangents.size(), 24u);
  for (const Mesh* m : {&plain, &mirrored}) {
    for (size_t t = 0; t < m->indices.size(); t += 3) {
      glm::vec3 a = m->positions[m->indices[t]], b = m->positions[m->indices[t + 1]],
                c = m->positions[m->indices[t + 2]];
      glm::vec3 face = glm::cross(b - a, c - a);
      EXPECT_GT(glm::dot(face, m->normals[m->indices[t]]), 0.0f) << "triangle " << t / 3;
      EXPECT_GT(glm::dot(face, a - glm::vec3(0.25f, 0.0f, 0.0f)), 0.0f) << "faces inwards";
    }
  }
  for (size_t i = 0; i < 24; ++i) {
    EXPECT_EQ(plain.tangents[i].w, -mirrored.tangents[i].w) << i;
    for (const Mesh* m : {&plain, &mirrored}) {
      EXPECT_NEAR(glm::dot(glm::vec3(m->tangents[i]), m->normals[i]), 0.0f, 1e-5f);
    }
  }
}

// Golden image: 5 x 5 spheres, roughness 0 to 1 from left to right, metallic 0 to 1 from top to
// bottom, a gold-like base colour. Tolerance: every channel within 2 of 255 at every pixel; on
// failure a diff image (red where out of tolerance) is written and its path printed. Re-create
// with SOFTRAST_UPDATE_GOLDEN=1, then look at the image before committing it.
TEST_F(GltfTest, SphereGridMatchesGolden) {
  Result<Mesh> mesh =
      load_model(write("spheres.glb", test::as_glb(test::sphere_grid(5, 5, 1.0f, 0.78f, 0.34f))));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  Camera camera;
  camera.eye = {0.0f, 0.0f, 9.0f};
  camera.fov_y_degrees = 30.0f;
  camera.near_plane = 1.0f;
  camera.far_plane = 20.0f;
  RenderOptions options;
  options.shader = ShaderKind::kPbr;
  options.light_direction = glm::normalize(glm::vec3(-0.4f, 0.6f, 0.7f));
  Framebuffer fb(256, 256);
  fb.clear_color(glm::vec4(0.1f, 0.1f, 0.1f, 1.0f));
  fb.clear_depth(1.0f);
  render_mesh(fb, *mesh, camera, options);
  Image got = fb.to_image();
  std::string path = std::string(SOFTRAST_GOLDEN_DIR) + "/pbr_sphere_grid.png";
  if (std::getenv("SOFTRAST_UPDATE_GOLDEN")) {
    ASSERT_TRUE(save_image(path, got).ok());
    GTEST_SKIP() << "wrote " << path;
  }
  Result<Image> want = load_image(path);
  ASSERT_TRUE(want.ok()) << want.status().message();
  ASSERT_EQ(want->width, got.width);
  ASSERT_EQ(want->height, got.height);
  Image diff(want->width, want->height);
  int bad = 0;
  for (size_t i = 0; i < want->rgba.size(); i += 4) {
    int worst = 0;
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, std::abs(got.rgba[i + c] - want->rgba[i + c]));
    }
    bool out = worst > 2;
    bad += out;
    for (int c = 0; c < 3; ++c) diff.rgba[i + c] = out ? (c == 0 ? 255 : 0) : want->rgba[i + c] / 3;
    diff.rgba[i + 3] = 255;
  }
  std::string diff_path = (fs::current_path() / "pbr_sphere_grid_diff.png").string();
  if (bad) {
    EXPECT_TRUE(save_image(diff_path, diff).ok());
  }
  EXPECT_EQ(bad, 0) << bad << " pixels differ by more than 2; diff image: " << diff_path;
}

// Physical sense of the grid, independent of the golden file: a rough dielectric sphere's centre
// is lit (not black), and the smooth full metal one reflects the sky above and the ground below
// (its top is brighter than its bottom).
TEST_F(GltfTest, SphereGridLooksPhysical) {
  Result<Mesh> mesh =
      load_model(write("spheres.gltf", test::as_gltf(test::sphere_grid(2, 2, 0.9f, 0.9f, 0.9f))));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  Camera camera;
  camera.eye = {0.0f, 0.0f, 6.0f};
  camera.fov_y_degrees = 30.0f;
  RenderOptions options;
  options.shader = ShaderKind::kPbr;
  options.light_direction = glm::vec3(0.0f, 0.0f, 1.0f);
  Framebuffer fb(128, 128);
  fb.clear_color(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  fb.clear_depth(1.0f);
  render_mesh(fb, *mesh, camera, options);
  Image im = fb.to_image();
  auto grey = [&](int x, int y) {
    const uint8_t* p = &im.rgba[size_t(y * 128 + x) * 4];
    return (p[0] + p[1] + p[2]) / 3;
  };
  // Sphere (1, 0): rough dielectric, upper right; (0, 1): smooth metal, lower left.
  int cx = 64 + 20, cy = 64 - 20;  // about one unit at this distance and field of view
  EXPECT_GT(grey(cx, cy), 100);
  int mx = 64 - 20, my = 64 + 20;
  EXPECT_GT(grey(mx, my - 9), grey(mx, my + 9) + 20);
}

// ---- Bad input --------------------------------------------------------------------------------

struct BadCase {
  const char* name;
  const char* file;
  std::function<std::string(GltfParts, const std::string& dir)> make;
  const char* message;  // the part of the error after "path: "
};

std::vector<BadCase> bad_cases() {
  return {
      {"TruncatedJson", "cut.gltf",
       [](GltfParts g, const std::string&) {
         std::string text = test::as_gltf(g);
         return text.substr(0, text.size() / 2);
       },
       "invalid JSON: parse error"},
      {"AccessorPastItsBufferView", "long.gltf",
       [](GltfParts g, const std::string&) {
         g.json["accessors"][0]["count"] = 25;
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: 25 elements of 12 bytes (stride 12) from byte 0 run past "
       "bufferView 0's 288 bytes"},
      {"IndexPastTheVertexCount", "index.gltf",
       [](GltfParts g, const std::string&) {
         uint16_t big = 99;
         std::memcpy(&g.bin[g.index_offset + 4], &big, 2);
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: index 99 is past the vertex count 24 (accessor 3)"},
      {"NoPrimitiveMode", "mode9.gltf",
       [](GltfParts g, const std::string&) {
         g.json["meshes"][0]["primitives"][0]["mode"] = 9;  // past TRIANGLE_FAN (6)
         return test::as_gltf(g);
       },
       "nothing to draw: its 1 primitive has no glTF primitive mode"},
      {"PositionsAsMatrices", "mat4.gltf",
       [](GltfParts g, const std::string&) {
         g.json["accessors"][0]["type"] = "MAT4";
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: is MAT4 where VEC3 is expected"},
      {"IndicesAsVectors", "vec3_indices.gltf",
       [](GltfParts g, const std::string&) {
         g.json["accessors"][3]["type"] = "VEC3";
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 3: is VEC3 where SCALAR is expected"},
      {"CountOf2To31", "huge.gltf",
       [](GltfParts g, const std::string&) {
         g.json["accessors"][0]["count"] = 2147483648u;
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: count 2147483648 is over the limit of 16777216"},
      {"MissingBufferFile", "missing.gltf",
       [](GltfParts g, const std::string&) {
         std::string text = test::as_gltf(g);
         nlohmann::json j = nlohmann::json::parse(text);
         j["buffers"][0]["uri"] = "cube.bin";
         return j.dump();
       },
       "buffer 0: cannot open 'cube.bin': No such file or directory"},
      {"UnsupportedRequiredExtension", "draco.gltf",
       [](GltfParts g, const std::string&) {
         g.json["extensionsUsed"] = {"KHR_draco_mesh_compression"};
         g.json["extensionsRequired"] = {"KHR_draco_mesh_compression"};
         return test::as_gltf(g);
       },
       "requires the extension 'KHR_draco_mesh_compression', which softrast does not support (it "
       "reads KHR_texture_transform, KHR_materials_emissive_strength and KHR_mesh_quantization)"},
      {"DataUriNotBase64", "uri.gltf",
       [](GltfParts g, const std::string&) {
         nlohmann::json j = nlohmann::json::parse(test::as_gltf(g));
         j["buffers"][0]["uri"] = "data:application/octet-stream,hello";
         return j.dump();
       },
       "buffer 0: the data URI is not base64 ('data:application/octet-stream,hello')"},
      {"SparseIndexPastTheCount", "sparse_range.gltf",
       [](GltfParts g, const std::string&) {
         add_sparse(g, 0, 5123, {3, 24}, test::float_bytes(std::vector<float>(6, 0.0f)));
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: sparse: index 24 at 1 is out of range or not increasing "
       "(count 24)"},
      {"SparseIndicesNotIncreasing", "sparse_order.gltf",
       [](GltfParts g, const std::string&) {
         add_sparse(g, 0, 5125, {5, 5}, test::float_bytes(std::vector<float>(6, 0.0f)));
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: sparse: index 5 at 1 is out of range or not increasing "
       "(count 24)"},
      {"SparseValuesPastTheirView", "sparse_values.gltf",
       [](GltfParts g, const std::string&) {
         add_sparse(g, 0, 5121, {1, 2}, test::float_bytes(std::vector<float>(5, 0.0f)));
         return test::as_gltf(g);
       },
       "mesh 0 primitive 0: accessor 0: sparse values: bytes 0 + 24 run past bufferView 5's 20 "
       "bytes"},
      {"Gltf1", "v1.gltf",  // glTF 1.0's shape: asset version "1.0", meshes by name
       [](GltfParts g, const std::string&) {
         nlohmann::json j = nlohmann::json::parse(test::as_gltf(g));
         j["asset"]["version"] = "1.0";
         j["meshes"] = {{"box", j["meshes"][0]}};
         return j.dump();
       },
       "a glTF 1.0 file (its meshes, nodes and materials are named objects, with shader "
       "techniques); softrast reads glTF 2.0: convert it first"},
      {"Gltf1WithoutAsset", "v1_no_asset.gltf",
       [](GltfParts g, const std::string&) {
         nlohmann::json j = nlohmann::json::parse(test::as_gltf(g));
         j.erase("asset");
         j["meshes"] = {{"box", j["meshes"][0]}};
         return j.dump();
       },
       "a glTF 1.0 file"},
      {"Glb1", "v1.glb",
       [](GltfParts g, const std::string&) {
         std::string glb = test::as_glb(g);
         glb[4] = 1;  // the header's version
         return glb;
       },
       "GLB version 1, a glTF 1.0 file; softrast reads glTF 2.0: convert it first"},
      {"TruncatedGlb", "cut.glb",
       [](GltfParts g, const std::string&) {
         std::string glb = test::as_glb(g);
         return glb.substr(0, glb.size() - 100);
       },
       "truncated GLB: the header declares"},
  };
}

TEST_F(GltfTest, BadInputIsOneClearErrorInTheLoader) {
  for (const BadCase& c : bad_cases()) {
    std::string path = write(c.file, c.make(test::textured_cube(png_), dir_.string()));
    Result<Mesh> mesh = load_model(path);
    ASSERT_FALSE(mesh.ok()) << c.name;
    EXPECT_EQ(mesh.status().message().rfind(path + ": " + c.message, 0), 0u)
        << c.name << ": " << mesh.status().message();
    EXPECT_EQ(mesh.status().message().find('\n'), std::string::npos) << c.name;
  }
}

#ifdef SOFTRAST_CLI_PATH
TEST_F(GltfTest, BadInputFailsTheCliWithOneLineAndNoOutput) {
  test::CliFolder folder;
  for (const BadCase& c : bad_cases()) {
    folder.write(c.file, c.make(test::textured_cube(png_), folder.dir().string()));
    test::CliResult r = folder.run(std::string("render ") + c.file + " -o out.png");
    EXPECT_NE(r.exit_code, 0) << c.name;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": " << r.err;
    EXPECT_FALSE(fs::exists(folder.dir() / "out.png")) << c.name;
    for (const auto& entry : fs::directory_iterator(folder.dir())) {
      EXPECT_EQ(entry.path().string().find("out.png"), std::string::npos) << entry.path();
    }
  }
}

// `softrast render model.glb` with no other flag: framed, pbr by default, written.
TEST_F(GltfTest, CliRendersGltfAndGlbWithNoFlags) {
  test::CliFolder folder;
  GltfParts cube = test::textured_cube(png_);
  folder.write("cube.gltf", test::as_gltf(cube));
  folder.write("cube.glb", test::as_glb(cube));
  for (const char* name : {"cube.gltf", "cube.glb"}) {
    test::CliResult r =
        folder.run(std::string("render ") + name + " --size 64x64 -o out.png --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"shader\":\"pbr\""), std::string::npos) << r.out;
    Result<Image> image = load_image(folder.path("out.png"));
    ASSERT_TRUE(image.ok());
    int covered = 0;
    for (size_t i = 0; i < image->rgba.size(); i += 4) covered += image->rgba[i] != image->rgba[0];
    EXPECT_GT(covered, 64 * 64 / 10) << name;
  }
  test::CliResult bad = folder.run("render cube.glb --exposure nan -o out2.png");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--exposure: must be in [-20, 20] stops"), std::string::npos) << bad.err;
}
#endif

}  // namespace
}  // namespace softrast
