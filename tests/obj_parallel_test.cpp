// tests/obj_parallel_test.cpp: OBJ files of several pieces (the loader reads 1 MiB pieces and
// parses them in parallel): the mesh equals the one the file describes, whatever the piece
// boundaries cut (relative indices reaching back into earlier pieces, materials named in one
// piece and used in another, faces before their vertices), and errors deep in the file name their
// own line.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "softrast/mesh.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

class ObjParallelTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("softrast_objpar_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  fs::path dir_;
};

// A strip of n quads: each adds two vertices (padded with a comment so the file spans several
// MiB) and a face in relative indices; the faces switch material every 1000 quads.
struct Strip {
  std::string text;
  size_t lines = 0;
  std::vector<glm::vec3> expected;  // three positions per triangle, in order

  void line(const std::string& s) {
    text += s;
    text += '\n';
    ++lines;
  }
};

Strip make_strip(int quads) {
  Strip s;
  s.line("mtllib strip.mtl");
  s.line("v 0 0 0");
  s.line("v 0 1 0");
  for (int i = 1; i <= quads; ++i) {
    if (i % 1000 == 1) s.line(i % 2000 == 1 ? "usemtl red" : "usemtl blue");
    s.line("v " + std::to_string(i) + " 0 0   # padding padding padding padding padding");
    s.line("v " + std::to_string(i) + " 1 0   # padding padding padding padding padding");
    s.line("f -4 -2 -1 -3");  // (i-1,0) (i,0) (i,1) (i-1,1)
    glm::vec3 a(float(i - 1), 0, 0), b(float(i), 0, 0), c(float(i), 1, 0), d(float(i - 1), 1, 0);
    s.expected.insert(s.expected.end(), {a, b, c, a, c, d});
  }
  return s;
}

TEST_F(ObjParallelTest, ManyPiecesGiveTheMeshTheFileDescribes) {
  Strip strip = make_strip(40000);  // about 5 MiB
  ASSERT_GT(strip.text.size(), size_t(4) << 20);
  write("strip.obj", strip.text);
  write("strip.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  Result<Mesh> mesh = load_obj(path("strip.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  ASSERT_EQ(mesh->triangle_count() * 3, strip.expected.size());
  for (size_t i = 0; i < strip.expected.size(); ++i) {
    ASSERT_EQ(mesh->positions[mesh->indices[i]], strip.expected[i]) << "corner " << i;
  }
  // Vertices are shared between neighbouring quads (deduplicated across pieces too).
  EXPECT_EQ(mesh->vertex_count(), 2u * 40001u);
  ASSERT_EQ(mesh->submeshes.size(), 40u);
  for (size_t k = 0; k < mesh->submeshes.size(); ++k) {
    EXPECT_EQ(mesh->submeshes[k].first_index, uint32_t(k * 6000));
    EXPECT_EQ(mesh->submeshes[k].index_count, 6000u);
    EXPECT_EQ(mesh->submeshes[k].material, int(k % 2)) << k;
  }
}

TEST_F(ObjParallelTest, ErrorsDeepInTheFileNameTheirLine) {
  Strip strip = make_strip(30000);
  size_t bad_line = strip.lines + 1;
  std::string bad = strip.text + "v 1 2 x\n" + make_strip(5000).text;
  write("strip.mtl", "newmtl red\nnewmtl blue\n");
  write("a.obj", bad);
  Result<Mesh> mesh = load_obj(path("a.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("a.obj") + ":" + std::to_string(bad_line) + ": 'x' is not a number");
  // A relative index reaching before the first vertex, with the count at its line.
  write("b.obj", strip.text + "f -1 -2 -60003\n" + make_strip(5000).text);
  mesh = load_obj(path("b.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("b.obj") + ":" + std::to_string(bad_line) +
                ": face index -60003 is out of range (1..60002 or -60002..-1)");
  // An index that overflows, with the count at its line.
  write("c.obj", strip.text + "f 1 2 99999999999999999999\n");
  mesh = load_obj(path("c.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("c.obj") + ":" + std::to_string(bad_line) +
                ": face index 99999999999999999999 is out of range (1..60002 or -60002..-1)");
  // A forward index never defined: reported at the end with its line.
  write("d.obj", strip.text + "f 1 2 70000\n" + make_strip(10).text);
  mesh = load_obj(path("d.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("d.obj") + ":" + std::to_string(bad_line) +
                ": face index 70000 is out of range (1..60024 or -60024..-1)");
  // The first error in the file wins, even when a later piece is parsed first.
  write("e.obj", strip.text + "f 1 2\n" + strip.text + "v x\n");
  mesh = load_obj(path("e.obj"));
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.status().message(),
            path("e.obj") + ":" + std::to_string(bad_line) + ": face with fewer than 3 vertices");
}

TEST_F(ObjParallelTest, FacesBeforeTheirVerticesAcrossPieces) {
  // All faces first (positive indices naming vertices read megabytes later), then the vertices.
  std::string text;
  const int quads = 30000;
  for (int i = 1; i <= quads; ++i) {
    int a = 2 * i - 1;  // (i-1,0) is vertex 2i-1, (i-1,1) is 2i
    text += "f " + std::to_string(a) + " " + std::to_string(a + 2) + " " + std::to_string(a + 3) +
            " " + std::to_string(a + 1) + "   # padding padding padding\n";
  }
  for (int i = 0; i <= quads; ++i) {
    text += "v " + std::to_string(i) + " 0 0\nv " + std::to_string(i) + " 1 0\n";
  }
  write("f.obj", text);
  Result<Mesh> mesh = load_obj(path("f.obj"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  Strip strip = make_strip(quads);
  ASSERT_EQ(mesh->triangle_count() * 3, strip.expected.size());
  for (size_t i = 0; i < strip.expected.size(); ++i) {
    ASSERT_EQ(mesh->positions[mesh->indices[i]], strip.expected[i]) << "corner " << i;
  }
  EXPECT_EQ(mesh->vertex_count(), 2u * (quads + 1));
}

}  // namespace
}  // namespace softrast
