// tests/cli_scene_test.cpp: what `softrast render` shows of a model, checked on the images it
// writes: two-sided lighting, the light's strength, the depth view's range, the overlay's edge
// colour, scenes of several files, automatic framing for every view and aspect, the background.
#ifdef SOFTRAST_CLI_PATH

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "cli_util.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"

namespace softrast {
namespace {

using test::CliFolder;
using test::CliResult;

// A 2 x 2 square facing +z (counter-clockwise seen from +z), with uvs: single-sided geometry.
constexpr const char* kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "f 1/1 2/2 3/3 4/4\n";

// A texture symmetric left to right (seen from behind, the quad shows it mirrored) whose top
// and bottom halves differ.
Image symmetric_texture() {
  Image image(8, 8);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      int from_edge = std::min(x, 7 - x);
      uint8_t* p = image.pixel(x, y);
      p[0] = uint8_t(40 + 60 * from_edge), p[1] = y < 4 ? 200 : 60, p[2] = 90, p[3] = 255;
    }
  }
  return image;
}

int channel(const Image& image, int x, int y, int c) {
  return image.pixel(x, y)[c];
}

// The largest channel difference between two images of the same size.
int worst_difference(const Image& a, const Image& b) {
  int worst = 0;
  for (size_t i = 0; i < a.rgba.size(); ++i)
    worst = std::max(worst, std::abs(a.rgba[i] - b.rgba[i]));
  return worst;
}

bool is_background(const Image& image, int x, int y, const std::vector<int>& background) {
  for (int c = 0; c < 3; ++c) {
    if (channel(image, x, y, c) != background[size_t(c)]) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Two-sided lighting: the quad seen from behind gives the same image as the quad seen from the
// front, within 1/255, for every built-in lit shader and for the unlit ones. The two set-ups are
// mirror images of each other through the quad's plane (camera, headlight, flipped normal, and
// the texture, which is symmetric left to right), so every pixel must match. With one-sided
// lighting the back is lit by the ambient term only.

TEST(CliTwoSided, QuadSeenFromBothSidesIsLitTheSame) {
  CliFolder folder;
  folder.write("quad.obj", kQuadObj);
  ASSERT_TRUE(save_image(folder.path("texture.png"), symmetric_texture()).ok());
  const std::string kCamera = " --size 64x64 --target 0,0,0 --up 0,1,0 --fov 50";
  for (const char* shading :
       {"--shader gouraud", "--shader phong", "--shader phong --texture texture.png",
        "--shader texture --texture texture.png", "--shader flat",
        "--shader phong --reference-path", "--shader gouraud --raster scanline"}) {
    SCOPED_TRACE(shading);
    Image front = folder.render(std::string("quad.obj ") + shading + kCamera + " --eye 0,0,4");
    Image back = folder.render(std::string("quad.obj ") + shading + kCamera + " --eye 0,0,-4");
    ASSERT_FALSE(front.rgba.empty());
    ASSERT_FALSE(back.rgba.empty());
    // The quad covers the middle of the image, lit (not the clear colour) from both sides.
    EXPECT_GT(channel(front, 32, 32, 0), 60);
    ASSERT_EQ(front.rgba.size(), back.rgba.size());
    EXPECT_LE(worst_difference(front, back), 1);
  }
}

TEST(CliTwoSided, CullBackStillRemovesTheBackFace) {
  CliFolder folder;
  folder.write("quad.obj", kQuadObj);
  Image back = folder.render("quad.obj --size 32x32 --eye 0,0,-4 --target 0,0,0 --cull back");
  ASSERT_FALSE(back.rgba.empty());
  for (size_t i = 0; i < back.rgba.size(); i += 4) {
    ASSERT_EQ(back.rgba[i], to_unorm8(0.1f)) << "pixel " << i / 4;  // the background only
  }
}

// ---------------------------------------------------------------------------------------------
// The light's terms: albedo * (ambient + 0.85 * intensity * n.l).

TEST(CliLight, AmbientAndIntensityScaleTheTerms) {
  CliFolder folder;
  folder.write("quad.obj", kQuadObj);
  const std::string kBase = "quad.obj --size 32x32 --shader gouraud --color 0.8,0.8,0.8";
  auto red = [&](const std::string& flags) {
    Image image = folder.render(kBase + " " + flags);
    return image.rgba.empty() ? -1 : channel(image, 16, 16, 0);
  };
  EXPECT_EQ(red("--light 0,0,1 --ambient 0.3 --light-intensity 0.5"),
            to_unorm8(0.8f * (0.3f + 0.85f * 0.5f)));
  EXPECT_EQ(red("--light 0,0,1 --ambient 0 --light-intensity 0"), 0);
  EXPECT_EQ(red("--light 0,0,1 --ambient 0.05 --light-intensity 1"),
            to_unorm8(0.8f * (0.05f + 0.85f)));
  // Lit from behind, with --cull back so that the face is not flipped: ambient only.
  EXPECT_EQ(red("--light 0,0,-1 --ambient 0.4 --light-intensity 3 --cull back"),
            to_unorm8(0.8f * 0.4f));
}

// ---------------------------------------------------------------------------------------------
// The depth view spreads its ramp over the depths in the image: a floor seen at a slant has
// its nearest pixels (bottom rows) white and its farthest (top rows) black, whatever the near
// and far planes.

TEST(CliDepthView, RampSpansTheVisibleDepths) {
  CliFolder folder;
  folder.write("floor.obj", "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 3 2 1\nf 4 3 1\n");
  // Near and far planes far beyond the floor: the camera's range would leave it mid-grey.
  Image image = folder.render(
      "floor.obj --shader depth --size 160x120 --background 0,0,1 --eye 0,1.5,2.5 "
      "--target 0,0,0 --near 0.1 --far 100");
  ASSERT_FALSE(image.rgba.empty());
  int top = -1, bottom = -1;  // the first and last rows with floor pixels
  int lightest = 0, darkest = 255;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (is_background(image, x, y, {0, 0, 255})) continue;
      if (top < 0) top = y;
      bottom = y;
      lightest = std::max(lightest, channel(image, x, y, 0));
      darkest = std::min(darkest, channel(image, x, y, 0));
    }
  }
  ASSERT_GE(top, 0);
  EXPECT_GE(lightest, 250);
  EXPECT_LE(darkest, 5);
  // Row by row: the bottom (near) row near white, the top (far) row near black.
  auto row_mean = [&](int y) {
    int sum = 0, n = 0;
    for (int x = 0; x < image.width; ++x) {
      if (!is_background(image, x, y, {0, 0, 255})) sum += channel(image, x, y, 0), ++n;
    }
    return n ? sum / n : -1;
  };
  EXPECT_GE(row_mean(bottom), 240);
  EXPECT_LE(row_mean(top), 15);
}

// ---------------------------------------------------------------------------------------------
// The overlay's colour.

TEST(CliEdgeColor, OverlayDrawsInTheGivenColour) {
  CliFolder folder;
  folder.write("floor.obj", "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 3 2 1\nf 4 3 1\n");
  auto red_pixels = [&](const std::string& flags) {
    Image image = folder.render("floor.obj --shader flat --size 160x120 --wireframe " + flags);
    int n = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        n += channel(image, x, y, 0) == 255 && channel(image, x, y, 1) == 0 &&
             channel(image, x, y, 2) == 0;
      }
    }
    return n;
  };
  EXPECT_EQ(red_pixels(""), 0);
  EXPECT_GT(red_pixels("--edge-color 1,0,0"), 300);  // four sides and a diagonal
}

// ---------------------------------------------------------------------------------------------
// Scenes of several files: each file with its own materials (both name theirs "paint"), drawn
// and framed together exactly as one file that merges them.

TEST(CliScene, TwoFilesRenderAsTheirMerge) {
  CliFolder folder;
  folder.write("parts/a.obj",
               "mtllib a.mtl\nv -2 -1 0\nv 0 -1 0\nv 0 1 0\nv -2 1 0\nvn 0 0 1\n"
               "usemtl paint\nf 1//1 2//1 3//1 4//1\n");
  folder.write("parts/a.mtl", "newmtl paint\nKd 1 0 0\n");
  folder.write("parts/b.obj",
               "mtllib b.mtl\nv 0.5 -1 -1\nv 3 -1 -1\nv 1.5 2 -1\nvn 0 0.3 1\n"
               "usemtl paint\nf 1//1 2//1 3//1\n");
  folder.write("parts/b.mtl", "newmtl paint\nKd 0 0 1\n");
  folder.write("merged.obj",
               "mtllib merged.mtl\nv -2 -1 0\nv 0 -1 0\nv 0 1 0\nv -2 1 0\nvn 0 0 1\n"
               "usemtl paint_a\nf 1//1 2//1 3//1 4//1\n"
               "v 0.5 -1 -1\nv 3 -1 -1\nv 1.5 2 -1\nvn 0 0.3 1\n"
               "usemtl paint_b\nf 5//2 6//2 7//2\n");
  folder.write("merged.mtl", "newmtl paint_a\nKd 1 0 0\nnewmtl paint_b\nKd 0 0 1\n");
  const std::string kFlags = " --size 160x90 --view iso";
  Image merged = folder.render("merged.obj" + kFlags, "merged.png");
  Image two = folder.render("parts/a.obj parts/b.obj" + kFlags, "two.png");
  Image from_folder = folder.render("parts" + kFlags, "folder.png");
  ASSERT_FALSE(merged.rgba.empty());
  EXPECT_TRUE(two.rgba == merged.rgba);
  EXPECT_TRUE(from_folder.rgba == merged.rgba);
  // Both materials are there: a red pixel and a blue one.
  bool red = false, blue = false;
  for (size_t i = 0; i < two.rgba.size(); i += 4) {
    red |= two.rgba[i] > 40 && two.rgba[i + 1] < 10 && two.rgba[i + 2] < 10;
    blue |= two.rgba[i + 2] > 40 && two.rgba[i] < 10 && two.rgba[i + 1] < 10;
  }
  EXPECT_TRUE(red);
  EXPECT_TRUE(blue);
}

// ---------------------------------------------------------------------------------------------
// Framing: for every view and for wide, square and tall images, the model's pixels fill at
// least 85% of the image's width or height and touch no border (nothing cut off).

// A long, lopsided part far from the origin: a 6 x 1 x 2 box with a spike at one end.
std::string long_part_obj() {
  std::ostringstream obj;
  const float x0 = 3, x1 = 9, y0 = 2, y1 = 3, z0 = -7, z1 = -5;
  for (int i = 0; i < 8; ++i) {
    obj << "v " << (i & 1 ? x1 : x0) << " " << (i & 2 ? y1 : y0) << " " << (i & 4 ? z1 : z0)
        << "\n";
  }
  obj << "v 9 2.5 -9\n";  // the spike's tip
  // Faces wound counter-clockwise seen from outside.
  obj << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  obj << "f 2 1 9\nf 4 2 9\nf 3 4 9\nf 1 3 9\n";
  return obj.str();
}

struct Extent {
  int left, right, top, bottom;  // model pixels, inclusive; left > right when none
};

Extent model_extent(const Image& image) {
  Extent e{image.width, -1, image.height, -1};
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (is_background(image, x, y, {0, 0, 0})) continue;
      e.left = std::min(e.left, x), e.right = std::max(e.right, x);
      e.top = std::min(e.top, y), e.bottom = std::max(e.bottom, y);
    }
  }
  return e;
}

void expect_framed(const Image& image, const std::string& what) {
  Extent e = model_extent(image);
  ASSERT_LE(e.left, e.right) << what << ": no model pixel";
  double width_share = double(e.right - e.left + 1) / image.width;
  double height_share = double(e.bottom - e.top + 1) / image.height;
  EXPECT_GE(std::max(width_share, height_share), 0.85)
      << what << ": fills " << width_share << " of the width, " << height_share << " of the height";
  EXPECT_GT(e.left, 0) << what << ": cut off on the left";
  EXPECT_GT(e.top, 0) << what << ": cut off at the top";
  EXPECT_LT(e.right, image.width - 1) << what << ": cut off on the right";
  EXPECT_LT(e.bottom, image.height - 1) << what << ": cut off at the bottom";
}

TEST(CliFraming, EveryViewFillsTheLimitingSide) {
  CliFolder folder;
  folder.write("part.obj", long_part_obj());
  for (const char* size : {"192x108", "128x128", "108x192"}) {
    for (const char* view : {"front", "back", "left", "right", "top", "bottom", "iso"}) {
      std::string args = std::string("part.obj --shader flat --background 0,0,0 --size ") + size +
                         " --view " + view;
      expect_framed(folder.render(args), args);
    }
  }
}

// A model flat across the view (a square in the plane x = 0) is seen from the right unless a view
// is asked for: from the front it is an edge, a line or no pixel at all (assimp's
// concave_polygon.obj, a ring in such a plane, drew an empty image).
TEST(CliFraming, ModelFlatAcrossTheViewIsSeenFaceOn) {
  CliFolder folder;
  folder.write("wall.obj", "v 0 -1 -1\nv 0 -1 1\nv 0 1 1\nv 0 1 -1\nf 1 2 3 4\n");
  for (const char* up : {"+y", "+z"}) {
    std::string args =
        std::string("wall.obj --shader flat --background 0,0,0 --size 120x120 --up-axis ") + up;
    expect_framed(folder.render(args), args);
  }
  Extent edge = model_extent(
      folder.render("wall.obj --shader flat --background 0,0,0 --size 120x120 --view front"));
  EXPECT_LE(edge.right - edge.left, 2) << "--view front is still the front";
}

// The demo scene is drawn mipmapped unless --filter says otherwise (its floor reaches the horizon,
// where bilinear filtering draws moire); a model keeps bilinear, SCENES.md's filter.
TEST(CliFilter, DemoSceneDefaultsToTrilinearAndModelsToBilinear) {
  CliFolder folder;
  Image plain = folder.render("--size 160x120", "demo.png");
  Image trilinear = folder.render("--size 160x120 --filter trilinear", "tri.png");
  Image bilinear = folder.render("--size 160x120 --filter bilinear", "bi.png");
  EXPECT_EQ(plain.rgba, trilinear.rgba);
  EXPECT_NE(plain.rgba, bilinear.rgba);
  folder.write("quad.obj", kQuadObj);
  Image stripes(64, 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      uint8_t v = x % 2 ? 255 : 0;
      uint8_t* p = stripes.pixel(x, y);
      p[0] = p[1] = p[2] = v, p[3] = 255;
    }
  }
  ASSERT_TRUE(save_image(folder.path("stripes.png"), stripes).ok());
  // Minified 64 texels to ~20 pixels: bilinear and trilinear differ, and the default is bilinear.
  const std::string model = "quad.obj --shader texture --texture stripes.png --size 24x24";
  EXPECT_EQ(folder.render(model, "m.png").rgba,
            folder.render(model + " --filter bilinear", "mb.png").rgba);
  EXPECT_NE(folder.render(model, "m2.png").rgba,
            folder.render(model + " --filter trilinear", "mt.png").rgba);
}

TEST(CliFraming, AnglesUpAxesAndZoom) {
  CliFolder folder;
  folder.write("part.obj", long_part_obj());
  for (const char* flags :
       {"--azimuth 30 --elevation 20", "--azimuth -150 --elevation -60", "--up-axis +z",
        "--up-axis -x --view iso", "--fov 20 --view right", "--fov 100 --view top"}) {
    std::string args =
        std::string("part.obj --shader flat --background 0,0,0 --size 160x90 ") + flags;
    expect_framed(folder.render(args), args);
  }
  // --zoom 0.5 halves the extent along the limiting side (within a pixel or two).
  Extent full = model_extent(
      folder.render("part.obj --shader flat --background 0,0,0 --size 200x200 --view front"));
  Extent half = model_extent(folder.render(
      "part.obj --shader flat --background 0,0,0 --size 200x200 --view front --zoom 0.5"));
  EXPECT_NEAR(half.right - half.left + 1, (full.right - full.left + 1) * 0.5, 3.0);
}

// A model in units of 1e30 or 1e-9 is framed and drawn as the same model in units of 1. At 1e30
// a float's square overflows (past 1.8e19): the camera's lengths, view and projection fall back to
// double; it was an error ("up is parallel to the view direction"), then an empty image. At 1e-9
// the clipper's smallest w (1e-6) and the framing's absolute floors (depths of 1e-6, a far plane
// of at least 1e-3 with the near plane a thousandth of it) removed or misplaced everything. Flat
// shading, so that only the coverage is compared.
TEST(CliFraming, HugeAndTinyUnitsAreFramedLikeUnitOnes) {
  CliFolder folder;
  const std::string unit = long_part_obj();
  folder.write("unit.obj", unit);
  for (float scale : {1e30f, 1e-9f}) {
    std::string scaled_obj;
    std::istringstream lines(unit);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("v ", 0) == 0) {
        std::istringstream v(line.substr(2));
        float x, y, z;
        v >> x >> y >> z;
        std::ostringstream scaled;
        scaled.precision(9);
        scaled << "v " << x * scale << " " << y * scale << " " << z * scale;
        line = scaled.str();
      }
      scaled_obj += line + "\n";
    }
    folder.write("scaled.obj", scaled_obj);
    std::ostringstream label_text;
    label_text << "scale " << scale;
    const std::string label = label_text.str();
    std::ostringstream box;  // the orthographic box scales with the model
    box.precision(9);
    box << "--view top --ortho " << -12 * scale << "," << 12 * scale << "," << -9 * scale << ","
        << 9 * scale;
    // Framed automatically from two sides, and in an orthographic box with the eye and the depth
    // range automatic.
    const std::pair<std::string, std::string> kFlags[] = {
        {"--view front", "--view front"},
        {"--view iso", "--view iso"},
        {"--view top --ortho -12,12,-9,9", box.str()}};
    for (const auto& [unit_flags, scaled_flags] : kFlags) {
      const std::string what = label + " " + scaled_flags;
      const std::string common = " --shader flat --background 0,0,0 --size 160x90 ";
      Image a = folder.render("unit.obj" + common + unit_flags, "unit.png");
      Image b = folder.render("scaled.obj" + common + scaled_flags, "scaled.png");
      ASSERT_FALSE(a.rgba.empty());
      ASSERT_FALSE(b.rgba.empty());
      Extent ea = model_extent(a), eb = model_extent(b);
      ASSERT_LE(eb.left, eb.right) << what << ": no model pixel";
      EXPECT_NEAR(eb.left, ea.left, 1) << what;
      EXPECT_NEAR(eb.right, ea.right, 1) << what;
      EXPECT_NEAR(eb.top, ea.top, 1) << what;
      EXPECT_NEAR(eb.bottom, ea.bottom, 1) << what;
      // Pixel by pixel: at most a few pixels along the edges differ in coverage.
      int differ = 0;
      for (int y = 0; y < a.height; ++y) {
        for (int x = 0; x < a.width; ++x) {
          differ += is_background(a, x, y, {0, 0, 0}) != is_background(b, x, y, {0, 0, 0});
        }
      }
      EXPECT_LE(differ, 8) << what;
    }
  }
}

// A UV sphere (24 x 16, normals and uvs) of radius `scale` at (scale, 0, 0), as OBJ text.
std::string sphere_obj(float scale) {
  std::ostringstream obj;
  obj.precision(9);
  const int kSlices = 24, kStacks = 16;
  for (int j = 0; j <= kStacks; ++j) {
    float theta = float(M_PI) * float(j) / kStacks;
    for (int i = 0; i <= kSlices; ++i) {
      float phi = 2.0f * float(M_PI) * float(i) / kSlices;
      float x = std::sin(theta) * std::cos(phi), y = std::cos(theta),
            z = std::sin(theta) * std::sin(phi);
      obj << "v " << (x + 1.0f) * scale << " " << y * scale << " " << z * scale << "\n";
      obj << "vn " << x << " " << y << " " << z << "\n";
      obj << "vt " << float(i) / kSlices * 2.0f << " " << float(j) / kStacks << "\n";
    }
  }
  auto at = [&](int i, int j) { return std::to_string(j * (kSlices + 1) + i + 1); };
  for (int j = 0; j < kStacks; ++j) {
    for (int i = 0; i < kSlices; ++i) {
      std::string a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      obj << "f " << a << "/" << a << "/" << a << " " << d << "/" << d << "/" << d << " " << c
          << "/" << c << "/" << c << " " << b << "/" << b << "/" << b << "\n";
    }
  }
  return obj.str();
}

// A model in units of 1e30, 1e9, 1e-9 or 1e-30 is shaded as the same model in units of 1: every
// lit shader, a point light (placed in the same units), shadows, a texture, the depth and normals
// views, colours within 2/255 where both images cover the pixel. Three things broke this: 1/w of
// vertices 1e30 away fell under the fragment stage's floor of 1e-30, so interpolated values came
// out 0.37 times too small (gouraud's colours, phong's positions, pbr's vertex colour); phong's
// eye - p and pbr's view rays overflowed float when squared, which lost the highlight; and the
// depth view's range (near times far) overflowed too, and the image was black.
TEST(CliFraming, HugeAndTinyUnitsAreShadedLikeUnitOnes) {
  CliFolder folder;
  Image checker(8, 8);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      uint8_t* p = checker.pixel(x, y);
      bool light = (x + y) % 2 == 0;
      p[0] = light ? 230 : uint8_t(30 * x), p[1] = light ? 230 : uint8_t(30 * y), p[2] = 90;
      p[3] = 255;
    }
  }
  ASSERT_TRUE(save_image(folder.path("tex.png"), checker).ok());
  folder.write("unit.obj", sphere_obj(1.0f));
  const std::string kCommon = " --background 0,0,0 --size 96x72 --view iso ";
  for (float scale : {1e30f, 1e9f, 1e-9f, 1e-30f}) {
    folder.write("scaled.obj", sphere_obj(scale));
    std::ostringstream light;
    light.precision(9);
    light << "--shader phong --light-pos " << 3 * scale << "," << 4 * scale << "," << 5 * scale;
    const std::pair<std::string, std::string> kShaders[] = {
        {"--shader gouraud", "--shader gouraud"},
        {"--shader phong", "--shader phong"},
        {"--shader phong --light-pos 3,4,5", light.str()},
        {"--shader phong --shadows", "--shader phong --shadows"},
        {"--shader pbr", "--shader pbr"},
        {"--shader texture --texture tex.png", "--shader texture --texture tex.png"},
        {"--shader phong --texture tex.png", "--shader phong --texture tex.png"},
        {"--shader depth", "--shader depth"},
        {"--shader normals", "--shader normals"}};
    for (const auto& [unit_flags, scaled_flags] : kShaders) {
      std::ostringstream what;
      what << "scale " << scale << " " << scaled_flags;
      Image a = folder.render("unit.obj" + kCommon + unit_flags, "unit.png");
      Image b = folder.render("scaled.obj" + kCommon + scaled_flags, "scaled.png");
      ASSERT_EQ(a.rgba.size(), b.rgba.size()) << what.str();
      int coverage_differs = 0, compared = 0, worst = 0;
      for (int y = 0; y < a.height; ++y) {
        for (int x = 0; x < a.width; ++x) {
          bool in_a = !is_background(a, x, y, {0, 0, 0}), in_b = !is_background(b, x, y, {0, 0, 0});
          coverage_differs += in_a != in_b;
          if (!in_a || !in_b) continue;
          ++compared;
          for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(int(a.pixel(x, y)[c]) - int(b.pixel(x, y)[c])));
          }
        }
      }
      EXPECT_GT(compared, 1000) << what.str();
      EXPECT_LE(coverage_differs, 8) << what.str();
      EXPECT_LE(worst, 2) << what.str();
    }
  }
}

// A view preset is its azimuth and elevation.
TEST(CliFraming, ViewPresetsAreAngles) {
  CliFolder folder;
  folder.write("part.obj", long_part_obj());
  const std::string kBase = "part.obj --size 96x72";
  EXPECT_TRUE(folder.render(kBase + " --view right", "a.png").rgba ==
              folder.render(kBase + " --azimuth 90 --elevation 0", "b.png").rgba);
  EXPECT_TRUE(folder.render(kBase + " --view top", "a.png").rgba ==
              folder.render(kBase + " --elevation 90", "b.png").rgba);
}

// An --eye straight above or below the --target, without --up: the model's up axis names no
// direction in that image, so the model's front takes its place as in the top and bottom views
// (the front at the image's bottom from above, at its top from below) instead of the camera's
// "up is parallel" error, which an --up given along the view still gets.
TEST(CliFraming, EyeStraightAboveOrBelowTakesTheFrontAsUp) {
  CliFolder folder;
  folder.write("part.obj", long_part_obj());
  const std::string kBase = "part.obj --size 96x72 --shader flat --target 6,2.5,-6";
  Image above = folder.render(kBase + " --eye 6,12,-6", "a.png");
  ASSERT_FALSE(above.rgba.empty());
  EXPECT_LE(model_extent(above).left, model_extent(above).right) << "no model pixel";
  EXPECT_TRUE(above.rgba == folder.render(kBase + " --eye 6,12,-6 --up 0,0,-1", "b.png").rgba);
  // The spike makes the part lopsided: the opposite up is another image.
  EXPECT_FALSE(above.rgba == folder.render(kBase + " --eye 6,12,-6 --up 0,0,1", "c.png").rgba);
  EXPECT_TRUE(folder.render(kBase + " --eye 6,-7,-6", "a.png").rgba ==
              folder.render(kBase + " --eye 6,-7,-6 --up 0,0,1", "b.png").rgba);
  // With --up-axis +z, looking along -z is looking down: the front is -y, so +y is up.
  EXPECT_TRUE(folder.render(kBase + " --up-axis +z --eye 6,2.5,4", "a.png").rgba ==
              folder.render(kBase + " --up-axis +z --eye 6,2.5,4 --up 0,1,0", "b.png").rgba);
  CliResult given = folder.run(kBase + " --eye 6,12,-6 --up 0,1,0 -q -o d.png");
  EXPECT_EQ(given.exit_code, 1);
  EXPECT_NE(given.err.find("up is parallel to the view direction"), std::string::npos) << given.err;
}

// The same part made Z-up ((x, y, z) -> (x, -z, y)) and framed with --up-axis +z looks as the
// Y-up part does by default: up is up and the front is the front.
TEST(CliFraming, UpAxisZShowsAZUpModelUpright) {
  CliFolder folder;
  std::string y_up = long_part_obj(), z_up;
  std::istringstream in(y_up);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream v(line.substr(2));
      float x, y, z;
      v >> x >> y >> z;
      std::ostringstream out;
      out << "v " << x << " " << -z << " " << y;
      z_up += out.str() + "\n";
    } else {
      z_up += line + "\n";
    }
  }
  folder.write("y_up.obj", y_up);
  folder.write("z_up.obj", z_up);
  for (const char* view : {"front", "iso", "left"}) {
    SCOPED_TRACE(view);
    const std::string kFlags = std::string(" --shader flat --size 120x90 --view ") + view;
    Image a = folder.render("y_up.obj" + kFlags, "y.png");
    Image b = folder.render("z_up.obj --up-axis +z" + kFlags, "z.png");
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    int differing = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4) differing += a.rgba[i] != b.rgba[i];
    EXPECT_LE(differing, 120 * 90 / 100);  // rounding on a few edge pixels at most
  }
}

// ---------------------------------------------------------------------------------------------
// Background and opacity, read back from the PNG's alpha channel.

TEST(CliBackground, AlphaZeroGivesATransparentPng) {
  CliFolder folder;
  folder.write("quad.obj", kQuadObj);
  Image image = folder.render("quad.obj --size 48x32 --background 1,0.5,0,0");
  ASSERT_FALSE(image.rgba.empty());
  EXPECT_EQ(std::vector<int>(image.pixel(0, 0), image.pixel(0, 0) + 4),
            (std::vector<int>{255, to_unorm8(0.5f), 0, 0}));
  EXPECT_EQ(channel(image, 24, 16, 3), 255);  // the model is opaque
  Image faint = folder.render("quad.obj --size 48x32 --background 0,0,0,0 --alpha 0.5");
  ASSERT_FALSE(faint.rgba.empty());
  EXPECT_EQ(channel(faint, 24, 16, 3), to_unorm8(0.5f));  // --alpha: the model's opacity
  EXPECT_EQ(channel(faint, 0, 0, 3), 0);
  Image opaque = folder.render("quad.obj --size 48x32 --background 0.2,0.4,0.6");
  ASSERT_FALSE(opaque.rgba.empty());
  EXPECT_EQ(std::vector<int>(opaque.pixel(0, 0), opaque.pixel(0, 0) + 4),
            (std::vector<int>{to_unorm8(0.2f), to_unorm8(0.4f), to_unorm8(0.6f), 255}));
}

}  // namespace
}  // namespace softrast

#endif  // SOFTRAST_CLI_PATH
