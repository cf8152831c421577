// tests/cli_io_test.cpp: the command line's model and image files: JPG output and --quality,
// `-o -` (PNG on the standard output, the same bytes as the file), loader warnings on stderr,
// and models of every format given to `softrast render`.
#ifdef SOFTRAST_CLI_PATH

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

class CliIoTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_cli_io_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }

  // `softrast ARGS` in the test folder; stdout and stderr captured in files, stdin empty.
  CliResult run(const std::string& args) const {
    std::string command = "cd '" + dir_.string() + "' && '" SOFTRAST_CLI_PATH "' " + args +
                          " >stdout.bin 2>stderr.txt </dev/null";
    int status = std::system(command.c_str());
    CliResult r;
    if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    r.out = read_file(dir_ / "stdout.bin");
    r.err = read_file(dir_ / "stderr.txt");
    fs::remove(dir_ / "stdout.bin");
    fs::remove(dir_ / "stderr.txt");
    return r;
  }

  fs::path dir_;
};

TEST_F(CliIoTest, DashWritesThePngToStandardOutputAsTheFileHasIt) {
  CliResult file = run("--size 64x48 -q -o file.png");
  ASSERT_EQ(file.exit_code, 0) << file.err;
  CliResult piped = run("--size 64x48 -o -");
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(piped.out, read_file(dir_ / "file.png"));
  EXPECT_NE(piped.err.find("wrote standard output"), std::string::npos) << piped.err;
  // No temporary file was made for it: only the file output is in the folder.
  size_t entries = size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  EXPECT_EQ(entries, 1u);
}

TEST_F(CliIoTest, JpgOutputWithQuality) {
  CliResult r = run("--size 64x48 -q -o out.jpg --quality 95");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  CliResult low = run("--size 64x48 -q -o low.jpeg --quality 10");
  ASSERT_EQ(low.exit_code, 0) << low.err;
  CliResult png = run("--size 64x48 -q -o ref.png");
  ASSERT_EQ(png.exit_code, 0) << png.err;
  Result<Image> jpg = load_image(path("out.jpg"));
  Result<Image> ref = load_image(path("ref.png"));
  ASSERT_TRUE(jpg.ok() && ref.ok());
  ASSERT_EQ(jpg->rgba.size(), ref->rgba.size());
  // A render has hard edges, so single pixels may differ more; the mean stays within 6/255 (4.3
  // measured at quality 95 with 4:2:0 chroma, before the writer kept full colour resolution at
  // 90 and above; a wrong colour order or a flipped image gives tens).
  double sum = 0.0;
  for (size_t i = 0; i < ref->rgba.size(); ++i) sum += std::abs(jpg->rgba[i] - ref->rgba[i]);
  EXPECT_LE(sum / double(ref->rgba.size()), 6.0);
  EXPECT_LT(fs::file_size(path("low.jpeg")), fs::file_size(path("out.jpg")));
}

TEST_F(CliIoTest, BadOutputRequestsAreOneErrorLine) {
  struct Case {
    const char* args;
    const char* message;
    int exit_code;
  } cases[] = {
      {"-o out.jpg --quality 0", "softrast: error: --quality: must be in 1..100\n", 2},
      {"-o out.jpg --quality 101", "softrast: error: --quality: must be in 1..100\n", 2},
      {"-o out.png --quality 80", "softrast: error: --quality: only for .jpg output\n", 2},
      {"-o - --quality 80", "softrast: error: --quality: only for .jpg output\n", 2},
      {"-o - --frames 2",
       "softrast: error: -o -: cannot be combined with --frames (both write to the standard "
       "output)\n",
       2},
      {"-o out.bmp",
       "softrast: error: out.bmp: unknown image format (the output must end in .png, .jpg or "
       ".tga, or be - for the standard output)\n",
       2},
  };
  for (const Case& c : cases) {
    CliResult r = run(c.args);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args;
    EXPECT_EQ(r.err, c.message) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
  }
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(CliIoTest, LoaderWarningsArePrintedUnlessQuiet) {
  write("m.obj", "mtllib gone.mtl\nmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  write("m.mtl", "newmtl a\nKd 1 0 0\nmap_Kd missing.png\n");
  CliResult r = run("m.obj --size 32x32 -o out.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string expected =
      "softrast: warning: m.obj:1: material library 'gone.mtl' not found; its materials get "
      "the default colour\n"
      "softrast: warning: m.obj: material 'a': map_Kd: missing.png: cannot open: No such file "
      "or directory; drawn without this texture\n";
  EXPECT_EQ(r.err.substr(0, expected.size()), expected) << r.err;
  CliResult quiet = run("m.obj --size 32x32 -q -o out.png");
  ASSERT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "");
}

TEST_F(CliIoTest, PlyAndStlModelsRenderAndOtherFilesSayWhatTheyAre) {
  const std::string tetra_stl =
      "solid t\n"
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
      "endfacet\nendsolid t\n";
  write("t.stl", tetra_stl);
  write("t.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n");
  CliResult obj = run("t.obj --size 48x32 -q -o obj.png");
  CliResult stl = run("t.stl --size 48x32 -q -o stl.png");
  CliResult ply = run("t.ply --size 48x32 -q -o ply.png");
  ASSERT_EQ(obj.exit_code, 0) << obj.err;
  ASSERT_EQ(stl.exit_code, 0) << stl.err;
  ASSERT_EQ(ply.exit_code, 0) << ply.err;
  EXPECT_EQ(read_file(dir_ / "stl.png"), read_file(dir_ / "obj.png"));
  EXPECT_EQ(read_file(dir_ / "ply.png"), read_file(dir_ / "obj.png"));
  CliResult png = run("obj.png -o x.png");
  EXPECT_EQ(png.exit_code, 1);
  EXPECT_EQ(png.err,
            "softrast: error: obj.png: this is a PNG image, not a model (softrast reads OBJ, PLY, "
            "STL and glTF)\n");
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

}  // namespace
}  // namespace softrast

#endif  // SOFTRAST_CLI_PATH
