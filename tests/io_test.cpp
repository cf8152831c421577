// tests/io_test.cpp: image files, textures and samplers, and the OBJ/MTL loader.
// Every test writes into its own fresh folder under the system's temporary directory.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "io/obj_loader.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"
#include "softrast/texture.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

// A fresh, empty folder per test, removed afterwards.
class IoTest : public testing::Test {
 protected:
  void SetUp() override {
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("softrast_io_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }

  fs::path dir_;
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// An image whose every byte differs from its neighbours, alpha included.
Image pattern(int width, int height) {
  Image image(width, height);
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = uint8_t((i * 37 + i / 7) & 255);
  return image;
}

// An uncompressed true-colour TGA (type 2). `top_down` sets descriptor bit 5; `rows_in_file`
// are the pixel rows (RGBA) in the order they are stored.
std::string make_tga(int width, int height, int bits, bool top_down,
                     const std::vector<std::vector<uint8_t>>& rows_in_file) {
  std::string tga(18, '\0');
  tga[2] = 2;
  tga[12] = char(width & 255), tga[13] = char(width >> 8);
  tga[14] = char(height & 255), tga[15] = char(height >> 8);
  tga[16] = char(bits);
  tga[17] = char((top_down ? 0x20 : 0) | (bits == 32 ? 8 : 0));
  for (const auto& row : rows_in_file) {
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = &row[size_t(x) * 4];
      tga += {char(p[2]), char(p[1]), char(p[0])};  // stored as BGR(A)
      if (bits == 32) tga += char(p[3]);
    }
  }
  return tga;
}

// Two rows of two pixels: top row red, green; bottom row blue, white (alpha varies).
const std::vector<uint8_t> kTop = {255, 0, 0, 255, 0, 255, 0, 200};
const std::vector<uint8_t> kBottom = {0, 0, 255, 100, 255, 255, 255, 255};

void expect_top_first(const Image& image, bool has_alpha) {
  ASSERT_EQ(image.width, 2);
  ASSERT_EQ(image.height, 2);
  std::vector<uint8_t> top = kTop, bottom = kBottom;
  if (!has_alpha) top[3] = top[7] = bottom[3] = bottom[7] = 255;
  EXPECT_EQ(std::vector<uint8_t>(image.rgba.begin(), image.rgba.begin() + 8), top);
  EXPECT_EQ(std::vector<uint8_t>(image.rgba.begin() + 8, image.rgba.end()), bottom);
}

TEST_F(IoTest, PngRoundTripIsExact) {
  Image image = pattern(13, 7);
  ASSERT_TRUE(save_image(path("a.png"), image).ok());
  Result<Image> loaded = load_image(path("a.png"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->width, 13);
  EXPECT_EQ(loaded->height, 7);
  EXPECT_EQ(loaded->rgba, image.rgba);
}

TEST_F(IoTest, TgaRoundTripIsExactAndStoredBottomUp) {
  Image image = pattern(5, 9);
  ASSERT_TRUE(save_image(path("a.TGA"), image).ok());  // extensions are case-insensitive
  std::string bytes = read_bytes(path("a.TGA"));
  ASSERT_GE(bytes.size(), 18u);
  EXPECT_EQ(bytes[17] & 0x20, 0) << "stb writes TGA rows bottom-up";
  Result<Image> loaded = load_image(path("a.TGA"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->rgba, image.rgba);
}

TEST_F(IoTest, HandBuiltTgaLoadsTopRowFirstInBothRowOrders) {
  write("down.tga", make_tga(2, 2, 32, true, {kTop, kBottom}));
  write("up.tga", make_tga(2, 2, 32, false, {kBottom, kTop}));
  write("down24.tga", make_tga(2, 2, 24, true, {kTop, kBottom}));
  write("up24.tga", make_tga(2, 2, 24, false, {kBottom, kTop}));
  for (const char* name : {"down.tga", "up.tga", "down24.tga", "up24.tga"}) {
    SCOPED_TRACE(name);
    Result<Image> image = load_image(path(name));
    ASSERT_TRUE(image.ok()) << image.status().message();
    expect_top_first(*image, std::string(name).find("24") == std::string::npos);
  }
}

TEST_F(IoTest, GarbageFileIsAnErrorNamingTheFile) {
  write("garbage.png", "this is not an image, just some text that goes on for a while");
  Result<Image> image = load_image(path("garbage.png"));
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message().rfind(path("garbage.png") + ": ", 0), 0u)
      << image.status().message();
  EXPECT_EQ(image.status().message().find('\n'), std::string::npos);
}

TEST_F(IoTest, EmptyFileIsAnError) {
  write("empty.png", "");
  EXPECT_FALSE(load_image(path("empty.png")).ok());
}

TEST_F(IoTest, TruncatedPngIsAnError) {
  ASSERT_TRUE(save_image(path("full.png"), pattern(64, 64)).ok());
  std::string bytes = read_bytes(path("full.png"));
  for (size_t keep : {bytes.size() / 2, size_t(40), bytes.size() - 20}) {
    SCOPED_TRACE(keep);
    write("cut.png", bytes.substr(0, keep));
    EXPECT_FALSE(load_image(path("cut.png")).ok());
  }
}

TEST_F(IoTest, OversizedHeaderIsRejectedBeforeDecoding) {
  // A TGA header claiming 20000 x 2 pixels, with no pixel data behind it.
  std::string tga = make_tga(2, 2, 32, true, {});
  tga[12] = char(20000 & 255), tga[13] = char(20000 >> 8);
  write("huge.tga", tga);
  Result<Image> image = load_image(path("huge.tga"));
  ASSERT_FALSE(image.ok());
  EXPECT_NE(image.status().message().find("20000x2"), std::string::npos)
      << image.status().message();
}

TEST_F(IoTest, MissingFileIsAnError) {
  Result<Image> image = load_image(path("nope.png"));
  ASSERT_FALSE(image.ok());
  EXPECT_NE(image.status().message().find("nope.png"), std::string::npos);
}

TEST_F(IoTest, DecodeFromMemory) {
  std::string tga = make_tga(2, 2, 32, true, {kTop, kBottom});
  Result<Image> image =
      decode_image(reinterpret_cast<const uint8_t*>(tga.data()), tga.size(), "memory");
  ASSERT_TRUE(image.ok()) << image.status().message();
  expect_top_first(*image, true);
  EXPECT_FALSE(decode_image(nullptr, 0, "memory").ok());
}

TEST_F(IoTest, SaveToMissingFolderFailsAndWritesNothing) {
  Status s = save_image(path("no/such/dir/a.png"), pattern(2, 2));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("a.png"), std::string::npos) << s.message();
  EXPECT_FALSE(fs::exists(dir_ / "no"));
  EXPECT_TRUE(files().empty());
}

TEST_F(IoTest, SaveWithUnknownExtensionFails) {
  EXPECT_FALSE(save_image(path("a.bmp"), pattern(2, 2)).ok());
  EXPECT_FALSE(save_image(path("a"), pattern(2, 2)).ok());
  EXPECT_TRUE(files().empty());
}

TEST_F(IoTest, SaveRejectsInvalidImages) {
  Image bad = pattern(2, 2);
  bad.rgba.pop_back();
  EXPECT_FALSE(save_image(path("a.png"), bad).ok());
  EXPECT_FALSE(save_image(path("b.png"), Image()).ok());
  EXPECT_TRUE(files().empty());
}

TEST_F(IoTest, SaveLeavesNoTemporaryAndReplacesExistingFile) {
  write("a.png", "old contents");
  ASSERT_TRUE(save_image(path("a.png"), pattern(3, 3)).ok());
  ASSERT_TRUE(save_image(path("b.tga"), pattern(3, 3)).ok());
  std::vector<std::string> names = files();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a.png", "b.tga"}));
  Result<Image> loaded = load_image(path("a.png"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->rgba, pattern(3, 3).rgba);
}

TEST_F(IoTest, SaveOverAFolderFailsAndCleansUp) {
  fs::create_directory(dir_ / "taken.png");
  EXPECT_FALSE(save_image(path("taken.png"), pattern(2, 2)).ok());
  EXPECT_EQ(files(), std::vector<std::string>{"taken.png"});
}

// ---- Textures --------------------------------------------------------------------------------

// A 2 x 2 image: top row (10, 20), bottom row (30, 40) in the red channel.
Texture small_texture() {
  Image image(2, 2);
  const uint8_t red[4] = {10, 20, 30, 40};
  for (int i = 0; i < 4; ++i) {
    uint8_t* p = image.pixel(i % 2, i / 2);
    p[0] = red[i], p[1] = uint8_t(i), p[2] = 0, p[3] = 255;
  }
  return Texture::from_image(image);
}

float red_at(const Texture& t, Filter filter, Wrap wrap, glm::vec2 uv) {
  return t.sample(Sampler{filter, wrap, wrap}, uv).r * 255.0f;
}

TEST(TextureTest, FromImageFlipsRows) {
  Texture t = small_texture();
  EXPECT_EQ(t.width(), 2);
  EXPECT_EQ(t.height(), 2);
  EXPECT_FLOAT_EQ(t.texel(0, 0).r * 255.0f, 30.0f);  // bottom-left pixel of the image
  EXPECT_FLOAT_EQ(t.texel(1, 0).r * 255.0f, 40.0f);
  EXPECT_FLOAT_EQ(t.texel(0, 1).r * 255.0f, 10.0f);  // top-left
  EXPECT_FLOAT_EQ(t.texel(1, 1).r * 255.0f, 20.0f);
  EXPECT_TRUE(Texture::from_image(Image()).empty());
}

TEST(TextureTest, EmptyTextureSamplesWhite) {
  EXPECT_EQ(Texture().sample(Sampler{}, {0.3f, 0.7f}), glm::vec4(1.0f));
}

TEST(TextureTest, TexelCentresReturnExactTexels) {
  Texture t = small_texture();
  for (Filter filter : {Filter::kNearest, Filter::kBilinear}) {
    for (Wrap wrap : {Wrap::kRepeat, Wrap::kClampToEdge, Wrap::kMirroredRepeat}) {
      for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
          glm::vec2 uv((i + 0.5f) / 2.0f, (j + 0.5f) / 2.0f);
          EXPECT_EQ(t.sample(Sampler{filter, wrap, wrap}, uv), t.texel(i, j));
        }
      }
    }
  }
}

TEST(TextureTest, BilinearHalfwayAverages) {
  Texture t = small_texture();
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kClampToEdge, {0.5f, 0.25f}), 35.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kClampToEdge, {0.25f, 0.5f}), 20.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kClampToEdge, {0.5f, 0.5f}), 25.0f, 1e-4f);
  // At the left edge, repeat blends with the opposite column, clamp does not.
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kRepeat, {0.0f, 0.25f}), 35.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kClampToEdge, {0.0f, 0.25f}), 30.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kMirroredRepeat, {0.0f, 0.25f}), 30.0f, 1e-4f);
}

TEST(TextureTest, WrapModesOutsideUnitSquare) {
  Texture t = small_texture();
  // Rounded: 30 / 255 * 255 is not exactly 30 in float.
  auto nearest = [&](Wrap wrap, float u) {
    return std::round(red_at(t, Filter::kNearest, wrap, {u, 0.25f}));
  };
  // Repeat: period 1.
  EXPECT_EQ(nearest(Wrap::kRepeat, 1.25f), 30.0f);
  EXPECT_EQ(nearest(Wrap::kRepeat, 1.75f), 40.0f);
  EXPECT_EQ(nearest(Wrap::kRepeat, -0.25f), 40.0f);
  EXPECT_EQ(nearest(Wrap::kRepeat, -3.75f), 30.0f);
  // Clamp: the edge texel.
  EXPECT_EQ(nearest(Wrap::kClampToEdge, 7.0f), 40.0f);
  EXPECT_EQ(nearest(Wrap::kClampToEdge, -7.0f), 30.0f);
  // Mirrored repeat: [1, 2] is [0, 1] reversed, [-1, 0] likewise.
  EXPECT_EQ(nearest(Wrap::kMirroredRepeat, 1.25f), 40.0f);
  EXPECT_EQ(nearest(Wrap::kMirroredRepeat, 1.75f), 30.0f);
  EXPECT_EQ(nearest(Wrap::kMirroredRepeat, -0.25f), 30.0f);
  EXPECT_EQ(nearest(Wrap::kMirroredRepeat, -0.75f), 40.0f);
  EXPECT_EQ(nearest(Wrap::kMirroredRepeat, 2.25f), 30.0f);
  // v wraps independently of u.
  Sampler s{Filter::kNearest, Wrap::kClampToEdge, Wrap::kRepeat};
  EXPECT_EQ(std::round(t.sample(s, {0.25f, 1.75f}).r * 255.0f), 10.0f);
  // Bilinear outside the square follows the same wrap.
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kRepeat, {1.25f, 0.25f}), 30.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kMirroredRepeat, {1.25f, 0.25f}), 40.0f, 1e-4f);
  EXPECT_NEAR(red_at(t, Filter::kBilinear, Wrap::kClampToEdge, {-5.0f, 0.25f}), 30.0f, 1e-4f);
}

TEST(TextureTest, NonFiniteCoordinatesDoNotCrash) {
  Texture t = small_texture();
  for (float u : {NAN, INFINITY, -INFINITY, 3e38f, -3e38f}) {
    for (Filter filter : {Filter::kNearest, Filter::kBilinear}) {
      glm::vec4 c = t.sample(Sampler{filter, Wrap::kRepeat, Wrap::kMirroredRepeat}, {u, u});
      EXPECT_TRUE(std::isfinite(c.r) && c.r >= 0.0f && c.r <= 1.0f);
    }
  }
}

// ---- OBJ -------------------------------------------------------------------------------------

// A unit quad in the z = 0 plane, counter-clockwise seen from +z.
const char* kQuadPositions =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n";

TEST_F(IoTest, ObjQuadWithMaterialAndTexture) {
  Image image(1, 2);
  image.pixel(0, 0)[0] = 200;  // top
  image.pixel(0, 1)[0] = 50;   // bottom
  ASSERT_TRUE(save_image(path("tex.png"), image).ok());
  write("quad.mtl", "newmtl red\nKd 0.5 0.25 0.125\nmap_Kd tex.png\n");
  write("quad.obj", std::string("mtllib quad.mtl\n") + kQuadPositions +
                        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                        "usemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  Result<Mesh> mesh = load_obj(path("quad.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->vertex_count(), 4u);
  EXPECT_EQ(mesh->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(mesh->uvs[2], glm::vec2(1, 1));
  EXPECT_EQ(mesh->normals[3], glm::vec3(0, 0, 1));
  ASSERT_EQ(mesh->submeshes.size(), 1u);
  EXPECT_EQ(mesh->submeshes[0].first_index, 0u);
  EXPECT_EQ(mesh->submeshes[0].index_count, 6u);
  ASSERT_EQ(mesh->submeshes[0].material, 0);
  ASSERT_EQ(mesh->materials.size(), 1u);
  const Material& m = mesh->materials[0];
  EXPECT_EQ(m.name, "red");
  EXPECT_EQ(m.diffuse, glm::vec3(0.5f, 0.25f, 0.125f));
  ASSERT_NE(m.diffuse_map, nullptr);
  EXPECT_EQ(m.diffuse_map->width(), 1);
  EXPECT_EQ(m.diffuse_map->height(), 2);
  EXPECT_FLOAT_EQ(m.diffuse_map->texel(0, 0).r * 255.0f, 50.0f);  // v = 0 is the bottom
}

// The files a model names, as its author meant them (find_referenced_file): as written; with
// Windows' backslashes; ignoring case in folders and names (the first match in name order); and,
// where the folders do not exist here, the file of that name beside the model. Before, each of
// these left the model untextured or without its materials.
TEST_F(IoTest, ReferencedFilesAreFoundAsTheirAuthorMeantThem) {
  fs::create_directories(dir_ / "Maps" / "Wood");
  write("Maps/Wood/Oak.PNG", "x");
  write("checker.png", "x");
  write("A.tga", "x");
  write("a.tga", "x");
  const std::string folder = dir_.string();
  auto found = [&](const std::string& name) {
    std::optional<std::string> f = find_referenced_file(folder, name);
    return f ? fs::path(*f).lexically_normal().lexically_relative(dir_).generic_string()
             : std::string("(none)");
  };
  EXPECT_EQ(found("checker.png"), "checker.png");
  EXPECT_EQ(found("Maps/Wood/Oak.PNG"), "Maps/Wood/Oak.PNG");
  EXPECT_EQ(found("Maps\\Wood\\Oak.PNG"), "Maps/Wood/Oak.PNG");
  EXPECT_EQ(found("maps/wood/oak.png"), "Maps/Wood/Oak.PNG");
  EXPECT_EQ(found("MAPS\\WOOD\\OAK.png"), "Maps/Wood/Oak.PNG");
  EXPECT_EQ(found("./maps/../Maps/wood/oak.png"), "Maps/Wood/Oak.PNG");
  EXPECT_EQ(found("a.TGA"), "A.tga");  // both match: the first in name order
  EXPECT_EQ(found("C:\\Users\\artist\\CHECKER.PNG"), "checker.png");
  EXPECT_EQ(found("/home/artist/textures/checker.png"), "checker.png");
  EXPECT_EQ(found("missing.png"), "(none)");
  EXPECT_EQ(found("Maps/missing.png"), "(none)");
  EXPECT_EQ(found(""), "(none)");

  // Through load_obj: an MTL named with another case and a folder of the author's machine, its
  // maps with backslashes and another case, and one by an absolute path from elsewhere.
  Image image(2, 2);
  ASSERT_TRUE(save_image(path("Maps/Wood/Oak.PNG"), image).ok());
  ASSERT_TRUE(save_image(path("checker.png"), image).ok());
  write("Model.MTL",
        "newmtl wood\nmap_Kd maps\\wood\\oak.png\nnewmtl check\n"
        "map_Kd D:\\work\\textures\\Checker.png\n");
  write("model.obj", std::string("mtllib C:\\Users\\artist\\model.mtl\n") + kQuadPositions +
                         "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl wood\nf 1/1 2/2 3/3\n"
                         "usemtl check\nf 1/1 3/3 4/4\n");
  Result<Mesh> mesh = load_obj(path("model.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 2u);
  EXPECT_NE(mesh->materials[0].diffuse_map, nullptr);
  EXPECT_NE(mesh->materials[1].diffuse_map, nullptr);
  // Found as written but for separators and case: silent. From another machine's folder: a
  // warning naming the file taken, for the MTL and for the second map.
  ASSERT_EQ(mesh->warnings.size(), 2u);
  EXPECT_NE(mesh->warnings[0].find("material library 'C:\\Users\\artist\\model.mtl' is not "
                                   "there; took "),
            std::string::npos)
      << mesh->warnings[0];
  EXPECT_NE(mesh->warnings[0].find("Model.MTL"), std::string::npos) << mesh->warnings[0];
  EXPECT_NE(mesh->warnings[1].find("material 'check': map_Kd: 'D:\\work\\textures\\Checker.png' "
                                   "is not there; took "),
            std::string::npos)
      << mesh->warnings[1];
}

// `usemtl` of a name that no MTL defines is drawn with the default colour and says so, once per
// name and with its line, when the OBJ's libraries were read; an OBJ without libraries (many
// exporters write "usemtl default" alone) or with a missing one (which has its own warning) adds
// no such line.
TEST_F(IoTest, ObjUsemtlOfAnUndefinedMaterialIsAWarning) {
  write("one.mtl", "newmtl red\nKd 1 0 0\n");
  const std::string faces = std::string(kQuadPositions) + "usemtl red\nf 1 2 3\n" +
                            "usemtl blue\nf 1 3 4\nusemtl blue\nf 1 2 4\nusemtl\nf 2 3 4\n";
  write("with.obj", "mtllib one.mtl\n" + faces);
  write("without.obj", faces);
  write("missing.obj", "mtllib gone.mtl\n" + faces);
  Result<Mesh> with = load_obj(path("with.obj"));
  ASSERT_TRUE(with.ok()) << with.status().message();
  ASSERT_EQ(with->warnings.size(), 1u);
  EXPECT_EQ(with->warnings[0], path("with.obj") +
                                   ":8: usemtl 'blue': no material of that name in the MTL files "
                                   "read; drawn with the default colour");
  Result<Mesh> without = load_obj(path("without.obj"));
  ASSERT_TRUE(without.ok()) << without.status().message();
  EXPECT_TRUE(without->warnings.empty());
  Result<Mesh> missing = load_obj(path("missing.obj"));
  ASSERT_TRUE(missing.ok()) << missing.status().message();
  ASSERT_EQ(missing->warnings.size(), 1u);
  EXPECT_NE(missing->warnings[0].find("material library 'gone.mtl' not found"), std::string::npos);
}

TEST_F(IoTest, ObjMaterialsRunsDefaultsAndSharedTextures) {
  ASSERT_TRUE(save_image(path("shared.png"), pattern(2, 2)).ok());
  write("m.mtl",
        "newmtl a\nmap_Kd shared.png\n"
        "newmtl b\nKd 0 0 0\nmap_Kd ./shared.png\n"
        "newmtl c\nKs 1 1 1\n");
  write("m.obj", std::string("mtllib m.mtl\n") + kQuadPositions +
                     "f 1 2 3\n"
                     "usemtl a\nf 1 2 3\nf 1 3 4\n"
                     "g other\nf 1 2 4\n"  // same material, new group: same run
                     "usemtl b\nf 1 2 3\n"
                     "usemtl c\nf 1 2 3\n");
  Result<Mesh> mesh = load_obj(path("m.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 3u);
  const Material defaults;
  EXPECT_EQ(mesh->materials[0].diffuse, defaults.diffuse);  // no Kd: keep the default
  EXPECT_EQ(mesh->materials[1].diffuse, glm::vec3(0.0f));   // an explicit black Kd
  EXPECT_EQ(mesh->materials[2].diffuse, defaults.diffuse);
  EXPECT_EQ(mesh->materials[2].diffuse_map, nullptr);
  ASSERT_NE(mesh->materials[0].diffuse_map, nullptr);
  EXPECT_EQ(mesh->materials[0].diffuse_map, mesh->materials[1].diffuse_map);
  ASSERT_EQ(mesh->submeshes.size(), 4u);
  const int expected_material[] = {-1, 0, 1, 2};
  const uint32_t expected_count[] = {3, 9, 3, 3};
  uint32_t first = 0;
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(mesh->submeshes[i].material, expected_material[i]);
    EXPECT_EQ(mesh->submeshes[i].first_index, first);
    EXPECT_EQ(mesh->submeshes[i].index_count, expected_count[i]);
    first += expected_count[i];
  }
  EXPECT_EQ(first, mesh->indices.size());
}

TEST_F(IoTest, ObjPentagonIsFanned) {
  write("p.obj", "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n");
  Result<Mesh> mesh = load_obj(path("p.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 3u);
  EXPECT_EQ(mesh->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  ASSERT_EQ(mesh->submeshes.size(), 1u);
  EXPECT_EQ(mesh->submeshes[0].material, -1);
  EXPECT_EQ(mesh->uvs[4], glm::vec2(0.0f));  // no uvs in the file
}

TEST_F(IoTest, ObjMissingNormalsAreUnitAndFaceTheViewer) {
  write("q.obj", std::string(kQuadPositions) + "f 1 2 3\nf 1 3 4\n");
  Result<Mesh> mesh = load_obj(path("q.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->normals.size(), 4u);
  for (const glm::vec3& n : mesh->normals) {
    EXPECT_NEAR(n.x, 0.0f, 1e-6f);
    EXPECT_NEAR(n.y, 0.0f, 1e-6f);
    EXPECT_NEAR(n.z, 1.0f, 1e-6f);
  }
}

TEST_F(IoTest, ObjSmoothNormalsArePerPositionIndex) {
  // Two faces folded along the edge 1-3, each side with its own uvs: positions 1 and 3 have two
  // vertices each, and both must get the same (averaged) normal.
  write("fold.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 1\n"
        "vt 0 0\nvt 1 1\n"
        "f 1/1 2/1 3/1\nf 1/2 3/2 4/2\n");
  Result<Mesh> mesh = load_obj(path("fold.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->vertex_count(), 6u);
  const std::vector<uint32_t>& idx = mesh->indices;
  EXPECT_EQ(mesh->normals[idx[0]], mesh->normals[idx[3]]);  // position 1
  EXPECT_EQ(mesh->normals[idx[2]], mesh->normals[idx[4]]);  // position 3
  EXPECT_NEAR(glm::length(mesh->normals[idx[0]]), 1.0f, 1e-6f);
  EXPECT_NE(mesh->normals[idx[0]], mesh->normals[idx[1]]);  // position 2 sees one face only
  EXPECT_EQ(mesh->normals[idx[1]], glm::vec3(0, 0, 1));
}

TEST_F(IoTest, ObjVerticesAreDeduplicatedAndRelativeIndicesWork) {
  write("r.obj", std::string(kQuadPositions) + "vn 0 0 1\nf -4//1 -3//1 -2//1\nf 1//1 3//1 4//1\n");
  Result<Mesh> mesh = load_obj(path("r.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->vertex_count(), 4u);
  EXPECT_EQ(mesh->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST_F(IoTest, ComputeSmoothNormalsGroupsEqualPositions) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {-1, 0, 1}, {5, 5, 5}};
  mesh.indices = {0, 1, 2, 3, 4, 5};
  compute_smooth_normals(mesh);
  ASSERT_EQ(mesh.normals.size(), 7u);
  EXPECT_EQ(mesh.normals[0], mesh.normals[3]);
  EXPECT_EQ(mesh.normals[2], mesh.normals[4]);
  EXPECT_EQ(mesh.normals[1], glm::vec3(0, 0, 1));
  EXPECT_EQ(mesh.normals[6], glm::vec3(0, 0, 1));  // in no triangle
}

// l (a polyline: each corner to the next) and p elements: indices into the faces' vertices, in
// runs of the material in use; render_mesh draws them one pixel wide, unlit, in its colour.
TEST_F(IoTest, ObjLinesAndPointsAreReadAndDrawn) {
  write("lp.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
  write("lp.obj", std::string("mtllib lp.mtl\n") + kQuadPositions +
                      "f 1 2 3\nusemtl red\nl 1 2 3 4\nusemtl green\np 4 3\nl -1 -3\n");
  Result<Mesh> mesh = load_obj(path("lp.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 1u);
  EXPECT_EQ(mesh->vertex_count(), 4u);  // the face's three, then position 4
  EXPECT_EQ(mesh->line_indices, (std::vector<uint32_t>{0, 1, 1, 2, 2, 3, 3, 1}));
  EXPECT_EQ(mesh->point_indices, (std::vector<uint32_t>{3, 2}));
  ASSERT_EQ(mesh->materials.size(), 2u);
  ASSERT_EQ(mesh->line_submeshes.size(), 2u);
  EXPECT_EQ(mesh->line_submeshes[0].material, 0);
  EXPECT_EQ(mesh->line_submeshes[0].first_index, 0u);
  EXPECT_EQ(mesh->line_submeshes[0].index_count, 6u);
  EXPECT_EQ(mesh->line_submeshes[1].material, 1);
  EXPECT_EQ(mesh->line_submeshes[1].first_index, 6u);
  EXPECT_EQ(mesh->line_submeshes[1].index_count, 2u);
  ASSERT_EQ(mesh->point_submeshes.size(), 1u);
  EXPECT_EQ(mesh->point_submeshes[0].material, 1);

  // Drawn: a red line across the middle of the image and a green point above it, nothing else.
  write("draw.mtl", "newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n");
  write("draw.obj",
        "mtllib draw.mtl\nv -1 0 0\nv 1 0 0\nv 0 0.5 0\nusemtl red\nl 1 2\nusemtl green\np 3\n");
  Result<Mesh> drawn = load_obj(path("draw.obj"));
  ASSERT_TRUE(drawn.ok()) << drawn.status().message();
  Framebuffer fb(64, 64);
  fb.clear_color(glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  fb.clear_depth(1.0f);
  Camera camera;
  camera.eye = {0.0f, 0.0f, 4.0f};
  camera.target = {0.0f, 0.0f, 0.0f};
  render_mesh(fb, *drawn, camera, RenderOptions{});
  Image image = fb.to_image();
  int red = 0, green = 0, other = 0, red_rows_lo = 64, red_rows_hi = -1, green_y = -1;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const uint8_t* p = image.pixel(x, y);
      if (p[0] == 255 && p[1] == 0 && p[2] == 0) {
        ++red, red_rows_lo = std::min(red_rows_lo, y), red_rows_hi = std::max(red_rows_hi, y);
      } else if (p[0] == 0 && p[1] == 255 && p[2] == 0) {
        ++green, green_y = y;
      } else if (p[0] || p[1] || p[2]) {
        ++other;
      }
    }
  }
  EXPECT_EQ(red_rows_lo, red_rows_hi);  // one row
  EXPECT_NEAR(red_rows_lo, 32, 1);
  EXPECT_GT(red, 25);  // 2 units at distance 4 with a 45-degree field: about 39 pixels
  EXPECT_EQ(green, 1);
  EXPECT_LT(green_y, red_rows_lo - 5);
  EXPECT_EQ(other, 0);
}

TEST_F(IoTest, ObjErrors) {
  struct Case {
    const char* name;
    std::string text;
    const char* message_part;
  };
  const Case cases[] = {
      {"empty.obj", "", "no faces"},
      {"vertices.obj", "v 0 0 0\nv 1 0 0\n",
       "no faces: 2 vertices but no face (f), line (l) or points (p) to draw"},
      {"short_line.obj", std::string(kQuadPositions) + "l 1\n",
       ":5: line (l) with fewer than 2 vertices"},
      {"no_point.obj", std::string(kQuadPositions) + "p\n", ":5: points (p) without a vertex"},
      {"line_range.obj", std::string(kQuadPositions) + "l 1 5\n", "out of range"},
      {"big.obj", std::string(kQuadPositions) + "f 1 2 5\n", "out of range"},
      {"neg.obj", std::string(kQuadPositions) + "f 1 2 -5\n", "out of range"},
      {"uv.obj", std::string(kQuadPositions) + "vt 0 0\nf 1/1 2/2 3/1\n", "out of range"},
      {"vn.obj", std::string(kQuadPositions) + "f 1//1 2//1 3//1\n", "out of range"},
      {"zero.obj", std::string(kQuadPositions) + "f 0 1 2\n", "face index 0 is out of range"},
      {"inf.obj", "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"},
      {"line.obj", std::string(kQuadPositions) + "f 1 2\n", "fewer than 3"},
      {"corner.obj", std::string(kQuadPositions) + "f 1 2 3/\n", "bad face corner '3/'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write(c.name, c.text);
    Result<Mesh> mesh = load_obj(path(c.name));
    ASSERT_FALSE(mesh.ok());
    const std::string& message = mesh.status().message();
    EXPECT_EQ(message.rfind(path(c.name) + ":", 0), 0u) << message;
    EXPECT_NE(message.find(c.message_part), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Indices tinyobj read with atoi: past 2^31 they wrapped (4294967299 became 3) or saturated
// (99999999999999999999 became the last vertex), silently. Each is now an error naming the
// file, the line and the valid range.
TEST_F(IoTest, ObjIndicesThatOverflowOrAreZeroAreErrorsWithTheLine) {
  struct Case {
    const char* face;
    const char* message;  // after "x.obj:5: "
  };
  const Case cases[] = {
      {"f 1 2 99999999999999999999",
       "face index 99999999999999999999 is out of range (1..3 or -3..-1)"},
      {"f 1 2 4294967299", "face index 4294967299 is out of range (1..3 or -3..-1)"},
      {"f 1 2 2147483648", "face index 2147483648 is out of range (1..3 or -3..-1)"},
      {"f 1 2 -99999999999999999999",
       "face index -99999999999999999999 is out of range (1..3 or -3..-1)"},
      {"f 1 2 -4294967295", "face index -4294967295 is out of range (1..3 or -3..-1)"},
      {"f 1 2 0", "face index 0 is out of range (1..3 or -3..-1)"},
      {"f 1/4294967297 2/1 3/1",
       "texture coordinate index 4294967297 is out of range (1..1 or -1..-1)"},
      {"f 1//1 2//1 3//-2", "normal index -2 is out of range (1..1 or -1..-1)"},
      {"f 1 2 3/1",
       "texture coordinate index 1 is out of range (there are no texture coordinates)"},
      {"f 1 2 3e0", "bad face corner: '3e0' is not an index"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.face);
    std::string uv = std::string(c.face).find("/4294967297") != std::string::npos ? "vt 0 0\n" : "";
    std::string normal = std::string(c.face).find("//") != std::string::npos ? "vn 0 0 1\n" : "";
    std::string extra = uv + normal;
    write("x.obj",
          "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + (extra.empty() ? "# none\n" : extra) + c.face + "\n");
    Result<Mesh> mesh = load_obj(path("x.obj"));
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.status().message(), path("x.obj") + ":5: " + c.message);
  }
}

TEST_F(IoTest, ObjPositiveIndicesMayReferToLaterVerticesButAreCheckedAtTheEnd) {
  write("later.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  Result<Mesh> mesh = load_obj(path("later.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->positions[2], glm::vec3(0, 1, 0));
  write("later.obj", "f 1 2 3\nf 1 2 7\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  mesh = load_obj(path("later.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("later.obj") + ":2: face index 7 is out of range (1..3 or -3..-1)");
}

// Numbers tinyobj's parser had undefined behaviour on: an exponent past 2^31 overflowed an int,
// and `vw` (its skin weights) cast a float of 1e39 to int. Run under UBSan by the debug preset.
TEST_F(IoTest, ObjNumbersTinyobjOverflowedOnAreErrorsOrSkipped) {
  write("e.obj", "v 1e2147483648 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Result<Mesh> mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("e.obj") + ":1: number 1e2147483648 is not finite as a 32-bit float");
  write("e.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("e.obj") + ":2: number 1e39 is not finite as a 32-bit float");
  write("e.obj", "v 0 0 x\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("e.obj") + ":1: 'x' is not a number");
  // Statements softrast does not use are skipped unread, whatever their numbers.
  write("e.obj", std::string(kQuadPositions) + "vw 0 1e39 0.5\ncurv 1 99999999999999999999\n" +
                     "vp 1e2147483648\nf 1 2 3 # a comment\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 1u);
  // MTL numbers go to tinyobj, so those it would overflow on are refused first.
  write("e.mtl", "newmtl a\nKd 1e2147483648 0 0\n");
  write("e.obj", std::string("mtllib e.mtl\n") + kQuadPositions + "usemtl a\nf 1 2 3\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("e.mtl") + ":2: number 1e2147483648 is out of range");
  write("e.mtl", "newmtl a\nKd 1 1e39 0\n");  // tinyobj would cast it to a float
  mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("e.mtl") + ":2: number 1e39 is out of range");
  // nan and inf, which tinyobj reads as 0 (a black Kd, an invisible d), as the OBJ's own are.
  const std::pair<const char*, const char*> non_finite[] = {{"Kd 1 nan 0", "nan"},
                                                            {"d nan", "nan"},
                                                            {"Ns inf", "inf"},
                                                            {"Ks -Infinity 0 0", "-Infinity"}};
  for (const auto& [statement, word] : non_finite) {
    write("e.mtl", std::string("newmtl a\n") + statement + "\n");
    mesh = load_obj(path("e.obj"));
    ASSERT_FALSE(mesh.ok()) << statement;
    EXPECT_EQ(mesh.status().message(), path("e.mtl") + ":2: number " + std::string(word) +
                                           " is not finite as a 32-bit float");
  }
  // A material named nan is a name, not a number.
  write("e.mtl", "newmtl nan\nKd 1 0 0\n");
  write("e.obj", std::string("mtllib e.mtl\n") + kQuadPositions + "usemtl nan\nf 1 2 3\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
}

TEST_F(IoTest, ObjDevZeroFailsAtOnce) {
  auto start = std::chrono::steady_clock::now();
  Result<Mesh> mesh = load_obj("/dev/zero");
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), "/dev/zero:1: NUL byte: not a text file");
  EXPECT_LT(seconds, 1.0);
  write("nul.obj", std::string(kQuadPositions) + "f 1 2 3\n" + std::string(1, '\0'));
  mesh = load_obj(path("nul.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("nul.obj") + ":6: NUL byte: not a text file");
}

TEST_F(IoTest, ObjOverTheByteLimitIsRefusedBeforeReading) {
  // A sparse file one byte over 2 GiB: refused from its size, so this takes no time or space.
  write("huge.obj", "");
  fs::resize_file(path("huge.obj"), uintmax_t(kMaxObjFileBytes) + 1);
  Result<Mesh> mesh = load_obj(path("huge.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("huge.obj") + ": file is larger than 2 GiB, the limit for OBJ files");
  // The same with lowered limits through the internal entry point, for the OBJ and its MTL.
  write("q.mtl", "newmtl a\nKd 1 1 1\n");
  write("q.obj", std::string("mtllib q.mtl\n") + kQuadPositions + "usemtl a\nf 1 2 3\n");
  int64_t size = int64_t(fs::file_size(path("q.obj")));
  EXPECT_TRUE(detail::load_obj(path("q.obj"), size, 18).ok());
  mesh = detail::load_obj(path("q.obj"), size - 1, 18);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("q.obj") + ": file is larger than " +
                                         std::to_string(size - 1) +
                                         " bytes, the limit for OBJ files");
  mesh = detail::load_obj(path("q.obj"), size, 17);
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("q.mtl") + ": file is larger than 17 bytes, the limit for MTL files");
}

// A pipe has no size to check first: the limit is enforced while reading.
TEST_F(IoTest, ObjFromAPipeIsCutOffAtTheByteLimit) {
  ASSERT_EQ(::mkfifo(path("pipe.obj").c_str(), 0600), 0);
  // One write of under PIPE_BUF bytes is atomic, so it is complete before the loader reads it
  // and the writer never sees the reader close early.
  std::string text = std::string(kQuadPositions) + "f 1 2 3\n";
  for (int i = 0; i < 40; ++i) text += "# padding\n";
  ASSERT_LT(text.size(), size_t(PIPE_BUF));
  std::thread writer([&] { std::ofstream(path("pipe.obj"), std::ios::binary) << text; });
  Result<Mesh> mesh = detail::load_obj(path("pipe.obj"), 100, kMaxMtlFileBytes);
  writer.join();
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("pipe.obj") + ": file is larger than 100 bytes, the limit for OBJ files");
}

TEST_F(IoTest, ObjLineLongerThanOneMebibyteIsAnError) {
  write("long.obj", std::string(kQuadPositions) + "# " + std::string(size_t(1) << 20, 'x'));
  Result<Mesh> mesh = load_obj(path("long.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(), path("long.obj") + ":5: line longer than 1 MiB");
}

TEST_F(IoTest, ObjMissingFileIsAnError) {
  Result<Mesh> mesh = load_obj(path("missing.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_NE(mesh.status().message().find("missing.obj"), std::string::npos);
  EXPECT_FALSE(load_obj(dir_.string()).ok());  // a folder
}

// A texture the model refers to that cannot be loaded is a warning: the material is drawn
// without it (a texture named on the command line is still an error, in the CLI).
TEST_F(IoTest, ObjWithGarbageOrMissingTextureWarnsAndLoads) {
  write("bad.png", "not a png at all, not even close");
  write("g.mtl", "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd bad.png\n");
  write("g.obj", std::string("mtllib g.mtl\n") + kQuadPositions + "usemtl m\nf 1 2 3\n");
  Result<Mesh> mesh = load_obj(path("g.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->materials.size(), 1u);
  EXPECT_EQ(mesh->materials[0].diffuse_map, nullptr);
  EXPECT_EQ(mesh->materials[0].diffuse, glm::vec3(0.5f));
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_EQ(mesh->warnings[0],
            path("g.obj") + ": material 'm': map_Kd: " + path("bad.png") +
                ": unsupported image format (PNG, TGA and JPG are supported); drawn without this "
                "texture");
  write("g.mtl", "newmtl m\nmap_Kd absent.png\n");
  mesh = load_obj(path("g.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_EQ(mesh->warnings[0], path("g.obj") + ": material 'm': map_Kd: " + path("absent.png") +
                                   ": cannot open: No such file or directory; drawn without this "
                                   "texture");
}

// Files a model names that are pipes (FIFOs) are not opened: opening one waits for a writer
// forever. Each is a warning and the model loads with defaults, at once.
TEST_F(IoTest, ObjNamingAPipeAsMtlOrMapWarnsInsteadOfWaiting) {
  ASSERT_EQ(::mkfifo(path("lib.mtl").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo(path("tex.png").c_str(), 0600), 0);
  write("m.mtl", "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd tex.png\n");
  write("p.obj",
        std::string("mtllib lib.mtl\nmtllib m.mtl\n") + kQuadPositions + "usemtl m\nf 1 2 3\n");
  auto start = std::chrono::steady_clock::now();
  Result<Mesh> mesh = load_obj(path("p.obj"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->warnings.size(), 2u);
  EXPECT_EQ(mesh->warnings[0], path("p.obj") +
                                   ":1: material library 'lib.mtl' is not a regular file (a pipe "
                                   "or device); its materials get the default colour");
  EXPECT_EQ(mesh->warnings[1], path("p.obj") + ": material 'm': map_Kd: " + path("tex.png") +
                                   ": not a regular file (a pipe or device); drawn without this "
                                   "texture");
  ASSERT_EQ(mesh->materials.size(), 1u);
  EXPECT_EQ(mesh->materials[0].diffuse_map, nullptr);
}

TEST_F(IoTest, ObjWithMissingMtlLoadsWithoutMaterials) {
  write("n.obj", std::string("mtllib nowhere.mtl\n") + kQuadPositions + "usemtl m\nf 1 2 3\n");
  Result<Mesh> mesh = load_obj(path("n.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_TRUE(mesh->materials.empty());
  ASSERT_EQ(mesh->submeshes.size(), 1u);
  EXPECT_EQ(mesh->submeshes[0].material, -1);
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_EQ(mesh->warnings[0], path("n.obj") +
                                   ":1: material library 'nowhere.mtl' not found; its materials "
                                   "get the default colour");
}

TEST(ObjSharedModels, AfricanHead) {
  const fs::path obj = fs::path(SOFTRAST_SHARED_DIR) / "models/african_head/african_head.obj";
  if (!fs::exists(obj)) GTEST_SKIP() << obj << " not found";
  Result<Mesh> mesh = load_obj(obj.string());
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 2492u);
  for (const glm::vec3& n : mesh->normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-3f);
}

}  // namespace
}  // namespace softrast
