// Robustness: broken files of every kind give an error or a valid result, never a crash, a hang
// or an invalid mesh. Deterministic mutations (flipped bytes, truncations, spliced garbage) of
// small valid OBJ, MTL, PNG and TGA files; run under the debug preset's sanitizers as well.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

std::string mutate(const std::string& input, std::mt19937& rng) {
  std::string s = input;
  std::uniform_int_distribution<int> kind(0, 3), byte(0, 255);
  int edits = 1 + int(rng() % 4);
  for (int e = 0; e < edits && !s.empty(); ++e) {
    size_t at = rng() % s.size();
    switch (kind(rng)) {
      case 0:
        s[at] = char(byte(rng));
        break;  // flip a byte
      case 1:
        s.resize(at);
        break;  // truncate
      case 2:
        s.insert(at, std::string(1 + rng() % 8, char(byte(rng))));
        break;  // splice
      default:
        s[at] = "0123456789-./ \n"[rng() % 15];
        break;  // plausible text
    }
  }
  return s;
}

void write_file(const fs::path& path, const std::string& data) {
  std::ofstream(path, std::ios::binary) << data;
}

// Every index in range, every float finite, submeshes inside the index array.
void expect_valid(const Mesh& mesh) {
  ASSERT_FALSE(mesh.indices.empty());
  ASSERT_EQ(mesh.indices.size() % 3, 0u);
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  for (uint32_t i : mesh.indices) ASSERT_LT(i, mesh.positions.size());
  for (const glm::vec3& p : mesh.positions) {
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
  for (const SubMesh& s : mesh.submeshes) {
    ASSERT_LE(size_t(s.first_index) + s.index_count, mesh.indices.size());
    ASSERT_LT(s.material, int(mesh.materials.size()));
  }
}

class Robustness : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("softrast_robust_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(Robustness, MutatedObjAndMtlFilesLoadOrFailCleanly) {
  const std::string obj =
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "vn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl b\nf -4/-4 -2/-2 -1/-1\n";
  const std::string mtl = "newmtl a\nKd 0.5 0.25 1\nmap_Kd t.tga\nnewmtl b\nKd 1 1 1\n";
  Image tex(2, 2);
  ASSERT_TRUE(save_image((dir_ / "t.tga").string(), tex).ok());
  std::mt19937 rng(2024);
  int loaded = 0, failed = 0;
  for (int n = 0; n < 1500; ++n) {
    write_file(dir_ / "x.obj", mutate(obj, rng));
    write_file(dir_ / "m.mtl", n % 3 == 0 ? mutate(mtl, rng) : mtl);
    Result<Mesh> mesh = load_obj((dir_ / "x.obj").string());
    if (!mesh.ok()) {
      EXPECT_FALSE(mesh.status().message().empty());
      ++failed;
      continue;
    }
    ++loaded;
    expect_valid(*mesh);
    if (n % 50 == 0) {  // and it renders
      Framebuffer fb(32, 32);
      Camera camera;
      render_mesh(fb, *mesh, camera, RenderOptions{});
    }
  }
  EXPECT_GT(loaded, 0);
  EXPECT_GT(failed, 0);
}

TEST_F(Robustness, MutatedImagesDecodeOrFailCleanly) {
  Image image(5, 3);
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = uint8_t(i * 37);
  for (const char* ext : {".png", ".tga"}) {
    fs::path path = dir_ / (std::string("i") + ext);
    ASSERT_TRUE(save_image(path.string(), image).ok());
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::mt19937 rng(7);
    for (int n = 0; n < 1500; ++n) {
      std::string m = mutate(bytes, rng);
      Result<Image> r = decode_image(reinterpret_cast<const uint8_t*>(m.data()), m.size(), ext);
      if (!r.ok()) continue;
      ASSERT_GT(r->width, 0);
      ASSERT_GT(r->height, 0);
      ASSERT_LE(r->width, kMaxImageSize);
      ASSERT_LE(r->height, kMaxImageSize);
      ASSERT_EQ(r->rgba.size(), size_t(r->width) * size_t(r->height) * 4);
    }
  }
}

}  // namespace
}  // namespace softrast
