// tests/cli_test.cpp: the softrast command line, run as a separate process in a fresh folder.
// Checks the images it writes, --help, --version, the --frames JSON line, and that every bad
// input fails with exactly one "softrast: error: " line and leaves no file behind (not even a
// temporary one).
#ifdef SOFTRAST_CLI_PATH

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/simd_level.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

// Files every test folder starts with.
const std::set<std::string> kFixtures = {"quad.obj", "empty.obj", "bad_index.obj", "garbage.png",
                                         "texture.png"};

// A 2 x 2 square facing +z (counter-clockwise seen from +z), with uvs.
constexpr const char* kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "f 1/1 2/2 3/3 4/4\n";
constexpr const char* kBadIndexObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";

struct CliRun {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Single quotes for sh; a single quote inside becomes '\''.
std::string quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

size_t count_lines(const std::string& text) {
  return size_t(std::count(text.begin(), text.end(), '\n'));
}

// A 4 x 4 image with four differently coloured quadrants.
Image quadrant_texture() {
  Image image(4, 4);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      uint8_t* p = image.pixel(x, y);
      p[0] = x < 2 ? 255 : 0;
      p[1] = y < 2 ? 255 : 0;
      p[2] = 128;
      p[3] = 255;
    }
  }
  return image;
}

// Each test gets a fresh folder: work/ is the program's current directory (and must hold only
// the fixtures and the expected outputs afterwards), logs/ receives stdout and stderr.
class CliTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_cli_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    fs::create_directories(work_dir());
    fs::create_directories(root_ / "logs");
    write("quad.obj", kQuadObj);
    write("empty.obj", "");
    write("bad_index.obj", kBadIndexObj);
    write("garbage.png", "this is not an image\n");
    ASSERT_TRUE(save_image(path("texture.png"), quadrant_texture()).ok());
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path work_dir() const { return root_ / "work"; }
  std::string path(const std::string& name) const { return (work_dir() / name).string(); }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(work_dir() / name, std::ios::binary) << bytes;
  }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(work_dir())) {
      names.insert(entry.path().filename().string());
    }
    return names;
  }
  std::set<std::string> fixtures_and(const std::set<std::string>& outputs) const {
    std::set<std::string> names = kFixtures;
    names.insert(outputs.begin(), outputs.end());
    return names;
  }

  // Runs `softrast ARGS` (ARGS as typed in a shell) in the work folder.
  // `env`: variable assignments for the program's environment ("NAME=value ...").
  CliRun run(const std::string& args, const std::string& env = "") const {
    fs::path out = root_ / "logs" / "stdout", err = root_ / "logs" / "stderr";
    std::string command = "cd " + quote(work_dir().string()) + " && " + env + " " +
                          quote(SOFTRAST_CLI_PATH) + " " + args + " >" + quote(out.string()) +
                          " 2>" + quote(err.string()) + " </dev/null";
    int status = std::system(command.c_str());
    CliRun result;
    if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
    result.out = read_file(out);
    result.err = read_file(err);
    return result;
  }

  // The image `name` in the work folder, checked to decode at the given size.
  Image load(const std::string& name, int width, int height) const {
    Result<Image> image = load_image(path(name));
    EXPECT_TRUE(image.ok()) << image.status().message();
    if (!image) return {};
    EXPECT_EQ(image->width, width);
    EXPECT_EQ(image->height, height);
    return *image;
  }

  fs::path root_;
};

bool all_one_colour(const Image& image) {
  for (size_t i = 4; i < image.rgba.size(); i += 4) {
    if (!std::equal(&image.rgba[i], &image.rgba[i + 4], &image.rgba[0])) return false;
  }
  return true;
}

std::vector<int> pixel(const Image& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  return {p[0], p[1], p[2], p[3]};
}

TEST_F(CliTest, NoArgumentsRendersTheDemoSceneToSoftrastPng) {
  CliRun r = run("");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(files(), fixtures_and({"softrast.png"}));
  Image image = load("softrast.png", 800, 600);
  EXPECT_FALSE(all_one_colour(image));
  EXPECT_NE(r.err.find("wrote softrast.png"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(CliTest, RenderWithoutModelRendersTheDemoScene) {
  CliRun r = run("render --size 64x48 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_FALSE(all_one_colour(load("softrast.png", 64, 48)));
}

TEST_F(CliTest, SizeAndOutputChooseTheImage) {
  CliRun png = run("render --size 160x90 -o small.png");
  ASSERT_EQ(png.exit_code, 0) << png.err;
  CliRun tga = run("--size 33x17 --out small.TGA");
  ASSERT_EQ(tga.exit_code, 0) << tga.err;
  EXPECT_EQ(files(), fixtures_and({"small.png", "small.TGA"}));
  EXPECT_FALSE(all_one_colour(load("small.png", 160, 90)));
  load("small.TGA", 33, 17);
}

TEST_F(CliTest, ModelIsFramedAutomatically) {
  CliRun r = run("quad.obj --size 64x48 --shader flat -o quad.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("quad.obj: 2 triangles"), std::string::npos) << r.err;
  Image image = load("quad.png", 64, 48);
  // The albedo (0.9, 0.6, 0.3) in the middle, the clear colour (0.1, 0.1, 0.1) in the corners.
  int clear = to_unorm8(0.1f);
  EXPECT_EQ(pixel(image, 32, 24),
            (std::vector<int>{to_unorm8(0.9f), to_unorm8(0.6f), to_unorm8(0.3f), 255}));
  EXPECT_EQ(pixel(image, 0, 0), (std::vector<int>{clear, clear, clear, 255}));
  EXPECT_EQ(pixel(image, 63, 47), (std::vector<int>{clear, clear, clear, 255}));
}

TEST_F(CliTest, ExplicitCameraOverridesTheFraming) {
  // From behind, the square is back-facing: drawn by default (--cull none), culled with
  // --cull back, leaving only the clear colour.
  CliRun r = run("quad.obj --size 32x32 --eye 0,0,-5 --target 0,0,0 --up 0,1,0 -o both.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(all_one_colour(load("both.png", 32, 32)));
  CliRun back = run("quad.obj --size 32x32 --eye 0,0,-5 --cull back -o back.png");
  ASSERT_EQ(back.exit_code, 0) << back.err;
  EXPECT_TRUE(all_one_colour(load("back.png", 32, 32)));
}

TEST_F(CliTest, EveryRenderFlagIsAccepted) {
  const char* kRuns[] = {
      "quad.obj --shader gouraud --cull none --front-face cw --depth lequal --blend alpha "
      "--alpha 0.5 --raster scanline --filter nearest --wrap clamp --wireframe --threads 1 "
      "--color 0.2,0.4,0.6 --fov 60 --near 0.5 --far 50 --eye 0,0,5 --target 0,0,0 --up 0,1,0",
      "quad.obj --ortho -2,2,-1.5,1.5 --near -1 --far 10 --shader normals --depth off",
      "quad.obj --shader texture --texture texture.png --wrap mirror --blend add",
      "quad.obj --shader phong --texture texture.png --depth always --cull front",
      "--shader depth --depth gequal",
      "--shader wireframe --depth notequal",
      "--shader flat --depth greater --raster edge --filter bilinear --wrap repeat",
      "--shader phong --depth equal --cull back --front-face ccw --blend opaque",
      "--depth never",
  };
  for (const char* args : kRuns) {
    CliRun r = run(std::string(args) + " --size 40x30 -o flags.png");
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    load("flags.png", 40, 30);
  }
}

TEST_F(CliTest, TextureShaderShowsTheTexture) {
  CliRun r = run("quad.obj --size 64x64 --shader texture --texture texture.png -o t.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Image image = load("t.png", 64, 64);
  EXPECT_FALSE(all_one_colour(image));
  // Texture row 0 (top) has green; v = 1 is the top of the square (which fills 90% of the
  // image: the middle of its top-left quarter is at pixel 17, 17).
  EXPECT_EQ(pixel(image, 17, 17)[1], 255);
}

TEST_F(CliTest, LightFlagSetsTheWorldSpaceLightDirection) {
  // The quad faces +z: lit head-on it is brighter than lit from the side, and a light from
  // behind leaves only the ambient term (albedo * 0.15).
  CliRun front = run("quad.obj --size 32x32 --shader gouraud --light 0,0,1 -o front.png");
  CliRun side = run("quad.obj --size 32x32 --shader gouraud --light 1,0,0.2 -o side.png");
  CliRun back = run("quad.obj --size 32x32 --shader gouraud --light 0,0,-1 -o back.png");
  ASSERT_EQ(front.exit_code, 0) << front.err;
  ASSERT_EQ(side.exit_code, 0) << side.err;
  ASSERT_EQ(back.exit_code, 0) << back.err;
  int r_front = pixel(load("front.png", 32, 32), 16, 16)[0];
  int r_side = pixel(load("side.png", 32, 32), 16, 16)[0];
  int r_back = pixel(load("back.png", 32, 32), 16, 16)[0];
  EXPECT_EQ(r_front, to_unorm8(0.9f * (0.15f + 0.85f)));
  EXPECT_EQ(r_back, to_unorm8(0.9f * 0.15f));
  EXPECT_GT(r_front, r_side);
  EXPECT_GT(r_side, r_back);
}

TEST_F(CliTest, UnsupportedTextureFormatIsOneErrorLine) {
  // A 16-bit PGM header with no data: the old texture decoder (stb_image) read past its buffer
  // converting it and the program died of SIGSEGV.
  write("deep.pgm", "P5\n1000 1000\n65535\n");
  CliRun r = run("quad.obj --texture deep.pgm -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err,
            "softrast: error: deep.pgm: unsupported image format (PNG, TGA and JPG are "
            "supported)\n");
  EXPECT_EQ(files(), fixtures_and({"deep.pgm"}));
}

// The wireframe overlay over a floor seen from above (the framing of flat models): the shared
// diagonal has a wire pixel in every column it crosses. With a constant depth bias instead of a
// slope-scaled polygon offset it came out dotted (every other pixel hidden by its own surface).
TEST_F(CliTest, WireframeOverlayDiagonalIsSolid) {
  write("floor.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 -1 1\nv -1 -1 1\nf 3 2 1\nf 4 3 1\n");
  CliRun r = run("floor.obj --wireframe --shader flat --size 400x300 -o wire.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Image image = load("wire.png", 400, 300);
  int wire = to_unorm8(0.05f);
  auto is_wire = [&](int x, int y) { return pixel(image, x, y)[0] == wire; };
  auto is_surface = [&](int x, int y) { return pixel(image, x, y)[0] == to_unorm8(0.9f); };
  // The columns the diagonal crosses, from the floor's top-left corner (its leftmost pixel in
  // its top row) to its bottom-right one (the rightmost in its bottom row), and in the middle
  // 60 % of them (away from the corners the diagonal ends in) a wire pixel with the surface
  // three rows above and below.
  int top = -1, bottom = -1;
  for (int y = 0; y < 300; ++y) {
    for (int x = 0; x < 400; ++x) {
      if (is_surface(x, y)) bottom = y, top = top < 0 ? y : top;
    }
  }
  ASSERT_GE(top, 0);
  int left = 400, right = -1;
  for (int x = 0; x < 400; ++x) {
    if (is_surface(x, top)) left = std::min(left, x);
    if (is_surface(x, bottom)) right = std::max(right, x);
  }
  int columns = 0, with_wire = 0;
  for (int x = left + (right - left) / 5; x <= right - (right - left) / 5; ++x) {
    bool interior_wire = false;
    for (int y = 3; y < 297; ++y) {
      if (is_wire(x, y) && is_surface(x, y - 3) && is_surface(x, y + 3)) interior_wire = true;
    }
    ++columns;
    with_wire += interior_wire;
  }
  ASSERT_GT(columns, 100);
  EXPECT_EQ(with_wire, columns);
}

// Without --light the light follows the camera: (0.3, 0.5, 0.8) in the camera's frame (x right,
// y up, z towards the viewer), so a surface facing the viewer is lit from any side.
TEST_F(CliTest, DefaultLightIsAHeadlight) {
  for (glm::vec3 eye : {glm::vec3(0, 0, 5), glm::vec3(3, 1, 4), glm::vec3(-2, -3, 1)}) {
    glm::vec3 forward = glm::normalize(-eye), up(0, 1, 0);
    glm::vec3 right = glm::normalize(glm::cross(forward, up));
    glm::vec3 true_up = glm::cross(right, forward);
    glm::vec3 light = glm::normalize(0.3f * right + 0.5f * true_up - 0.8f * forward);
    float lit = 0.15f + 0.85f * std::max(light.z, 0.0f);  // the quad's normal is +z
    std::string flags = "quad.obj --size 32x32 --shader gouraud --eye " + std::to_string(eye.x) +
                        "," + std::to_string(eye.y) + "," + std::to_string(eye.z) +
                        " --target 0,0,0 -o lit.png";
    CliRun r = run(flags);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NEAR(pixel(load("lit.png", 32, 32), 16, 16)[0], to_unorm8(0.9f * lit), 1)
        << "eye " << eye.x << "," << eye.y << "," << eye.z;
  }
}

// The headlight lights a sphere the same from six directions: seen from the front, back, left,
// right, top and bottom, the sphere's mean brightness agrees within 2 % and its brightest pixel
// is up and to the right of the centre every time: (0.3, 0.5, 0.8) in the camera's frame, x to the
// right, y up, comes from the viewer's upper right.
TEST_F(CliTest, HeadlightLightsASphereEquallyFromSixDirections) {
  std::string obj;
  const int kSlices = 48, kStacks = 32;
  for (int j = 0; j <= kStacks; ++j) {
    for (int i = 0; i <= kSlices; ++i) {
      float theta = 3.14159265f * float(j) / kStacks, phi = 6.2831853f * float(i) / kSlices;
      obj += "v " + std::to_string(std::sin(theta) * std::cos(phi)) + " " +
             std::to_string(std::cos(theta)) + " " +
             std::to_string(std::sin(theta) * std::sin(phi)) + "\n";
    }
  }
  for (int j = 0; j < kStacks; ++j) {
    for (int i = 0; i < kSlices; ++i) {
      int a = j * (kSlices + 1) + i + 1, b = a + kSlices + 1;
      obj += "f " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(b) +
             "\nf " + std::to_string(a + 1) + " " + std::to_string(b + 1) + " " +
             std::to_string(b) + "\n";
    }
  }
  write("sphere.obj", obj);
  std::vector<double> means;
  for (const char* view : {"front", "back", "left", "right", "top", "bottom"}) {
    CliRun r = run(std::string("sphere.obj --size 96x96 --shader gouraud --view ") + view +
                   " -o lit_" + view + ".png");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    Image image = load(std::string("lit_") + view + ".png", 96, 96);
    int clear = pixel(image, 0, 0)[0];
    double sum = 0;
    int count = 0, best = -1, best_x = 0, best_y = 0;
    for (int y = 0; y < 96; ++y) {
      for (int x = 0; x < 96; ++x) {
        int red = pixel(image, x, y)[0];
        if (red == clear) continue;
        sum += red, ++count;
        if (red > best) best = red, best_x = x, best_y = y;
      }
    }
    ASSERT_GT(count, 96 * 96 / 3) << view;
    means.push_back(sum / count);
    EXPECT_GT(best_x, 48) << view << ": the brightest pixel is right of the centre";
    EXPECT_LT(best_y, 48) << view << ": the brightest pixel is above the centre";
  }
  for (double m : means) EXPECT_NEAR(m, means[0], 0.02 * means[0]);
}

TEST_F(CliTest, HelpMentionsEveryFlag) {
  for (const char* args : {"--help", "render --help", "-h"}) {
    CliRun r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args;
    EXPECT_EQ(r.err, "") << args;
    for (const char* flag :
         {"--size",   "--eye",        "--target", "--up",        "--fov",     "--ortho",
          "--near",   "--far",        "--shader", "--wireframe", "--texture", "--color",
          "--cull",   "--front-face", "--depth",  "--blend",     "--alpha",   "--raster",
          "--filter", "--wrap",       "--frames", "--threads",   "--quiet",   "--help",
          "--light",  "--version",    "-o",       "MODEL",       "flat",      "gouraud",
          "phong",    "normals",      "scanline", "notequal",    "mirror",    "--msaa",
          "--shadows"}) {
      EXPECT_NE(r.out.find(flag), std::string::npos) << args << " does not mention " << flag;
    }
  }
  EXPECT_EQ(files(), kFixtures);
}

TEST_F(CliTest, HelpMentionsTheFramingAndLightFlags) {
  CliRun r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  const char* kFlags[] = {
      "--ambient", "--light-intensity", "--edge-color", "--background", "--up-axis", "--view",
      "--azimuth", "--elevation",       "--zoom",       "iso",          "+z",        "MODEL..."};
  for (const char* flag : kFlags) {
    EXPECT_NE(r.out.find(flag), std::string::npos) << "--help does not mention " << flag;
  }
}

TEST_F(CliTest, VersionPrintsTheProgramName) {
  CliRun r = run("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.rfind("softrast ", 0), 0u) << r.out;
  EXPECT_EQ(files(), kFixtures);
}

// One line of JSON with every field; `triangles` < 0: any count.
void expect_json_line(const std::string& out, const std::string& scene, int triangles) {
  ASSERT_EQ(count_lines(out), 1u) << out;
  ASSERT_EQ(out.front(), '{') << out;
  ASSERT_EQ(out.substr(out.size() - 2), "}\n") << out;
  for (const std::string& field :
       {"\"scene\":\"" + scene + "\"", std::string("\"shader\":\"phong\""),
        std::string("\"width\":64"), std::string("\"height\":48"), std::string("\"frames\":3"),
        "\"triangles\":" + (triangles < 0 ? "" : std::to_string(triangles) + ","),
        std::string("\"median_ms\":"), std::string("\"min_ms\":"), std::string("\"max_ms\":"),
        std::string("\"mtris_per_s\":"), std::string("\"mpix_per_s\":")}) {
    EXPECT_NE(out.find(field), std::string::npos) << field << " missing in " << out;
  }
}

// The line says how texels were gathered: the mode SOFTRAST_GATHER fixes, or the one timed
// fastest ("loads" at SSE2, which has no gather instruction).
TEST_F(CliTest, FramesReportsTheGatherMode) {
  for (const char* mode : {"instruction", "loads"}) {
    CliRun r =
        run("--frames 3 --size 64x48 --shader texture", std::string("SOFTRAST_GATHER=") + mode);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // (A CPU without AVX2 runs SSE, which always loads.)
    const bool has_gathers = cpu_simd_level() >= SimdLevel::kAvx2;
    const std::string want = has_gathers ? mode : "loads";
    EXPECT_NE(r.out.find("\"gathers\":\"" + want + "\""), std::string::npos) << r.out;
  }
  CliRun sse2 = run("--frames 3 --size 64x48", "SOFTRAST_SIMD=sse2");
  ASSERT_EQ(sse2.exit_code, 0) << sse2.err;
  EXPECT_NE(sse2.out.find("\"simd\":\"sse2\",\"gathers\":\"loads\""), std::string::npos)
      << sse2.out;
}

TEST_F(CliTest, FramesPrintsOneJsonLineAndWritesOnlyWithOutput) {
  CliRun r = run("--frames 3 --size 64x48");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_json_line(r.out, "demo", -1);
  EXPECT_EQ(files(), kFixtures);  // no -o: no image

  CliRun model = run("quad.obj --frames 3 --size 64x48 -o bench.png -q");
  ASSERT_EQ(model.exit_code, 0) << model.err;
  expect_json_line(model.out, "quad", 2);
  EXPECT_EQ(model.err, "");
  EXPECT_EQ(files(), fixtures_and({"bench.png"}));
  load("bench.png", 64, 48);
}

TEST_F(CliTest, FailureLeavesAnExistingOutputAlone) {
  write("keep.png", "old contents");
  CliRun r = run("missing.obj -o keep.png");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(read_file(work_dir() / "keep.png"), "old contents");
}

// ---------------------------------------------------------------------------------------------
// Messages, word for word.

TEST_F(CliTest, UnknownFlagSuggestsTheClosestOne) {
  CliRun r = run("quad.obj --shadr phong -o out.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "softrast: error: unknown flag '--shadr'; did you mean --shader? (see softrast "
            "--help)\n");
  CliRun eq = run("quad.obj --backgruond=1,1,1 -o out.png");
  EXPECT_EQ(eq.err,
            "softrast: error: unknown flag '--backgruond'; did you mean --background? (see "
            "softrast --help)\n");
  CliRun far = run("quad.obj --bogus -o out.png");
  EXPECT_EQ(far.err, "softrast: error: unknown flag '--bogus' (see softrast --help)\n");
  EXPECT_EQ(files(), kFixtures);
}

TEST_F(CliTest, MsaaNamesTheSampleCounts) {
  CliRun r = run("quad.obj --msaa 3 -o out.png");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "softrast: error: --msaa: must be 1, 2, 4 or 8, got 3\n");
  EXPECT_EQ(files(), kFixtures);
}

// --eye without --target at the model's centre (the default target: quad.obj's is the origin)
// says so; it said "camera: near must be less than far".
TEST_F(CliTest, EyeAtTheDefaultTargetSaysSo) {
  CliRun r = run("quad.obj --eye 0,0,0 -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err,
            "softrast: error: --eye is at the default --target, the centre of the scene; give "
            "--target, or another --eye\n");
  EXPECT_EQ(files(), kFixtures);
  CliRun moved = run("quad.obj --eye 0,0,0 --target 0,0,-1 -o out.png");  // looking away: empty
  EXPECT_EQ(moved.exit_code, 0) << moved.err;
}

TEST_F(CliTest, HelpCommandPrintsTheHelp) {
  CliRun flag = run("--help");
  ASSERT_EQ(flag.exit_code, 0);
  for (const char* args : {"help", "help render"}) {
    CliRun r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args;
    EXPECT_EQ(r.out, flag.out) << args;
    EXPECT_EQ(r.err, "") << args;
  }
  CliRun unknown = run("help paint");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_EQ(
      unknown.err,
      "softrast: error: help: unknown command 'paint' (commands: render, view, batch, info)\n");
}

TEST_F(CliTest, HelpExplainsMaterialsAndTheTwoDepths) {
  CliRun r = run("--help");
  ASSERT_EQ(r.exit_code, 0);
  for (const char* sentence :
       {"Materials: the MTL files an OBJ names (mtllib) are read, with each material's colour "
        "(Kd) and texture (map_Kd); --texture overrides their maps.",
        "Depth: --depth sets the depth test (which surface hides which); --shader depth is the "
        "depth view (grey by distance, white nearest, black farthest).",
        "depth is the depth view (grey by distance), not the depth test (--depth)",
        "not the depth view (--shader depth)",
        "The model's opacity, 0 to 1, written to the image's alpha channel",
        "Background colour, alpha 0 for a transparent PNG"}) {
    EXPECT_NE(r.out.find(sentence), std::string::npos) << "missing: " << sentence;
  }
}

TEST_F(CliTest, VectorsAcceptSpacesAfterCommas) {
  CliRun spaced = run("quad.obj --size 32x32 --eye '0, 0.5, 3' --color '0.2, 0.4, 0.6' -o a.png");
  ASSERT_EQ(spaced.exit_code, 0) << spaced.err;
  CliRun tight = run("quad.obj --size 32x32 --eye 0,0.5,3 --color 0.2,0.4,0.6 -o b.png");
  ASSERT_EQ(tight.exit_code, 0) << tight.err;
  EXPECT_EQ(read_file(work_dir() / "a.png"), read_file(work_dir() / "b.png"));
}

// The warning lines come first on stderr, before the progress lines; --quiet silences both.
std::string warning_lines(const std::string& err) {
  std::string lines;
  size_t start = 0;
  while (err.compare(start, 18, "softrast: warning:") == 0) {
    size_t end = err.find('\n', start);
    if (end == std::string::npos) break;
    lines += err.substr(start, end + 1 - start);
    start = end + 1;
  }
  return lines;
}

TEST_F(CliTest, TextureShaderWithoutTextureWarns) {
  CliRun r = run("quad.obj --shader texture --size 16x16 -o out.png");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(warning_lines(r.err),
            "softrast: warning: --shader texture: the model has no texture (no --texture, no "
            "map_Kd in its materials), so it is drawn white\n");
  CliRun quiet = run("quad.obj --shader texture --size 16x16 -q -o out.png");
  EXPECT_EQ(quiet.err, "");
  CliRun textured = run("quad.obj --shader texture --texture texture.png --size 16x16 -o t.png");
  EXPECT_EQ(warning_lines(textured.err), "");
  EXPECT_NE(textured.err, "");  // the progress lines are there
}

TEST_F(CliTest, TextureOnAModelWithoutUvsWarns) {
  write("no_uvs.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
  CliRun r = run("no_uvs.obj --texture texture.png --size 16x16 -o out.png");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(warning_lines(r.err),
            "softrast: warning: no_uvs.obj: the model has no texture coordinates (vt), so its "
            "texture shows as one colour\n");
  CliRun untextured = run("no_uvs.obj --size 16x16 -o plain.png");
  EXPECT_EQ(warning_lines(untextured.err), "");
}

TEST_F(CliTest, EmptyFolderIsAnError) {
  fs::create_directories(work_dir() / "nothing");
  write("nothing/notes.txt", "no models here\n");
  CliRun r = run("nothing -o out.png");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err,
            "softrast: error: nothing: no model files (.obj, .ply, .stl, .gltf, .glb) in this "
            "folder\n");
}

// ---------------------------------------------------------------------------------------------
// Bad input: one error line, non-zero exit, no file written.

// Starts `softrast ARGS` in the work folder with SOFTRAST_TEST_SLOW_WRITE_MS set (the write
// sleeps after each 64 KiB), output to /dev/null; returns its pid.
pid_t start_slow_writer(const fs::path& dir, const std::vector<std::string>& args) {
  std::vector<std::string> env_text = {"SOFTRAST_TEST_SLOW_WRITE_MS=100"};
  for (char** e = environ; *e; ++e) env_text.emplace_back(*e);
  std::vector<char*> env, argv = {const_cast<char*>(SOFTRAST_CLI_PATH)};
  for (std::string& e : env_text) env.push_back(e.data());
  env.push_back(nullptr);
  std::vector<std::string> arg_text = args;
  for (std::string& a : arg_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    int null = open("/dev/null", O_RDWR);
    if (chdir(dir.c_str()) != 0 || null < 0) _exit(127);
    for (int fd = 0; fd < 3; ++fd) dup2(null, fd);
    execve(argv[0], argv.data(), env.data());
    _exit(127);
  }
  return pid;
}

bool has_temporary(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

// Interrupted while writing its image (the temporary file exists), the program removes the
// temporary and dies of the signal: no output, no *.tmp.* file, and a shell sees 130 or 143.
TEST_F(CliTest, SignalWhileWritingLeavesNoTemporaryFile) {
  for (int signal : {SIGINT, SIGTERM}) {
    SCOPED_TRACE(signal);
    // A 512x512 TGA is 1 MiB, 16 chunks: 1.6 s of writing.
    pid_t pid = start_slow_writer(work_dir(), {"--size", "512x512", "-q", "-o", "out.tga"});
    ASSERT_GT(pid, 0);
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!has_temporary(work_dir()) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    bool writing = has_temporary(work_dir());
    kill(pid, signal);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(writing) << "the program never started writing";
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
    EXPECT_EQ(WTERMSIG(status), signal);
    EXPECT_EQ(files(), kFixtures);  // neither out.tga nor out.tga.tmp.<pid>.0
  }
}

struct BadInput {
  const char* name;
  const char* args;
};
// For test listings: the command line rather than the struct's bytes.
void PrintTo(const BadInput& input, std::ostream* os) {
  *os << "softrast " << input.args;
}

const BadInput kBadInputs[] = {
    {"MissingModel", "missing.obj -o out.png"},
    {"EmptyObj", "empty.obj -o out.png"},
    {"FaceIndexOutOfRange", "bad_index.obj -o out.png"},
    {"ModelIsDevZero", "/dev/zero -o out.png"},
    {"ModelIsAFolder", ". -o out.png"},
    {"GarbageTexture", "quad.obj --texture garbage.png -o out.png"},
    {"MissingTexture", "quad.obj --texture missing.png -o out.png"},
    {"TextureIsAnObj", "--texture quad.obj -o out.png"},
    {"TextureIsDevZero", "quad.obj --texture /dev/zero -o out.png"},
    {"ZeroSize", "--size 0x100 -o out.png"},
    {"ZeroHeight", "--size 100x0 -o out.png"},
    {"NegativeSize", "--size=-5x10 -o out.png"},
    {"NegativeSizeSeparate", "--size -5x10 -o out.png"},
    {"HugeSize", "--size 100000x100000 -o out.png"},
    {"JustTooLarge", "--size 16385x16 -o out.png"},
    {"SizeOverflowsInt", "--size 99999999999999999999x10 -o out.png"},
    {"SizeMissingHeight", "--size 12x -o out.png"},
    {"SizeNoSeparator", "--size 1200 -o out.png"},
    {"SizeWithSpaces", "--size '12 x 12' -o out.png"},
    {"SizeFloat", "--size 12.5x10 -o out.png"},
    {"SizeWithoutValue", "--size"},
    {"NearEqualsFar", "--near 5 --far 5 -o out.png"},
    {"NearBeyondFar", "--near 10 --far 1 -o out.png"},
    {"NearZeroPerspective", "--near 0 -o out.png"},
    {"NearNegativePerspective", "--near=-1 -o out.png"},
    {"NearBeyondDemoFar", "--near 100000 -o out.png"},
    {"FovZero", "--fov 0 -o out.png"},
    {"FovNegative", "--fov=-10 -o out.png"},
    {"Fov180", "--fov 180 -o out.png"},
    {"FovHuge", "--fov 400 -o out.png"},
    {"FovNotANumber", "--fov wide -o out.png"},
    {"EyeTwoNumbers", "--eye 1,2 -o out.png"},
    {"EyeFourNumbers", "--eye 1,2,3,4 -o out.png"},
    {"EyeNotNumbers", "--eye a,b,c -o out.png"},
    {"EyeTrailingComma", "--eye 1,2,3, -o out.png"},
    {"EyeNaN", "--eye nan,0,0 -o out.png"},
    {"TargetTwoNumbers", "--target 1,2 -o out.png"},
    {"UpTwoNumbers", "--up 0,1 -o out.png"},
    {"UpZero", "--up 0,0,0 -o out.png"},
    {"UpAlongView", "quad.obj --up 0,0,1 -o out.png"},
    {"ColorTwoNumbers", "--color 1,2 -o out.png"},
    {"ColorOutOfRange", "--color 2,0,0 -o out.png"},
    {"LightZero", "--light 0,0,0 -o out.png"},
    {"LightTwoNumbers", "--light 1,2 -o out.png"},
    {"OrthoThreeNumbers", "--ortho 1,2,3 -o out.png"},
    {"OrthoEmptyBox", "--ortho 1,1,0,1 -o out.png"},
    {"AlphaOutOfRange", "--alpha 1.5 -o out.png"},
    {"EyeEqualsTarget", "--eye 1,1,1 --target 1,1,1 -o out.png"},
    {"ModelEyeEqualsTarget", "quad.obj --eye 0,0,0 --target 0,0,0 -o out.png"},
    {"UnknownFlag", "--bogus -o out.png"},
    {"UnknownShortFlag", "-z -o out.png"},
    {"SecondModelMissing", "render quad.obj missing.obj -o out.png"},
    {"SecondModelEmpty", "render quad.obj empty.obj -o out.png"},
    {"FolderWithoutModels", "render /dev -o out.png"},
    {"UnknownView", "quad.obj --view above -o out.png"},
    {"UnknownUpAxis", "quad.obj --up-axis z -o out.png"},
    {"ElevationOutOfRange", "quad.obj --elevation 91 -o out.png"},
    {"AzimuthNotANumber", "quad.obj --azimuth east -o out.png"},
    {"ZoomZero", "quad.obj --zoom 0 -o out.png"},
    {"ViewWithEye", "quad.obj --view top --eye 0,5,0 -o out.png"},
    {"ZoomWithEye", "quad.obj --zoom 2 --eye 0,0,5 -o out.png"},
    {"ZoomWithOrtho", "quad.obj --zoom 2 --ortho -1,1,-1,1 -o out.png"},
    {"ViewOnTheDemoScene", "--view top -o out.png"},
    {"AmbientOutOfRange", "--ambient 1.5 -o out.png"},
    {"LightIntensityNegative", "--light-intensity=-1 -o out.png"},
    {"EdgeColorOutOfRange", "--edge-color 0,0,2 -o out.png"},
    {"EdgeColorWithAlpha", "--edge-color 0,0,0,1 -o out.png"},
    {"BackgroundFiveNumbers", "--background 0,0,0,0,0 -o out.png"},
    {"BackgroundOutOfRange", "--background 0,0,0,-1 -o out.png"},
    {"HelpTwoCommands", "help render render"},
    {"HelpUnknownCommand", "help paint"},
    {"UnknownShader", "--shader toon -o out.png"},
    {"UnknownCull", "--cull sideways -o out.png"},
    {"UnknownFrontFace", "--front-face up -o out.png"},
    {"UnknownDepth", "--depth sometimes -o out.png"},
    {"UnknownBlend", "--blend multiply -o out.png"},
    {"UnknownRaster", "--raster raytrace -o out.png"},
    {"NegativeThreads", "--threads -1 -o out.png"},
    {"NonNumericThreads", "--threads many -o out.png"},
    {"UnknownFilter", "--filter anisotropic -o out.png"},
    {"MsaaThree", "--msaa 3 -o out.png"},
    {"MsaaNotANumber", "--msaa many -o out.png"},
    {"UnknownWrap", "--wrap border -o out.png"},
    {"FramesZero", "--frames 0 -o out.png"},
    {"FramesNegative", "--frames=-2 -o out.png"},
    {"FramesNotANumber", "--frames many -o out.png"},
    {"OutputFolderMissing", "-o /nonexistent/dir/out.png"},
    {"OutputBesideAFile", "-o quad.obj/out.png"},
    {"OutputExtensionBmp", "-o out.bmp"},
    {"OutputNoExtension", "-o out"},
    {"OutputIsAFolder", "-o ."},
    {"OutputExtensionWithModel", "quad.obj -o out.gif"},
    {"FramesWithBadOutput", "--frames 2 -o /nonexistent/dir/out.png"},
};

class CliBadInputTest : public CliTest, public testing::WithParamInterface<BadInput> {};

TEST_P(CliBadInputTest, FailsWithOneErrorLineAndNoFile) {
  CliRun r = run(GetParam().args);
  EXPECT_NE(r.exit_code, 0) << GetParam().args;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("softrast: error: ", 0), 0u) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(files(), kFixtures);  // no output, no temporary file
}

INSTANTIATE_TEST_SUITE_P(Cli, CliBadInputTest, testing::ValuesIn(kBadInputs),
                         [](const testing::TestParamInfo<BadInput>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace softrast

#endif  // SOFTRAST_CLI_PATH
