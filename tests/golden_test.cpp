// Golden images: the demo scene through every built-in shader, compared with images in
// tests/golden/ that were rendered once, looked at, and committed.
//
// Tolerance, per pixel: every channel within kTolerance (2 of 255) of the golden image, and no
// pixel may exceed it. On failure a diff image (red where a pixel is out of tolerance, the golden
// image dimmed elsewhere) is written next to the test binary and its path printed.
// To re-create the goldens after a deliberate change: SOFTRAST_UPDATE_GOLDEN=1 softrast_tests
// --gtest_filter='Golden*', then look at every image before committing it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "softrast/renderer.hpp"

namespace softrast {
namespace {

constexpr int kTolerance = 2;
constexpr int kWidth = 320, kHeight = 240;

Image render_demo(const RenderOptions& options) {
  static const DemoScene scene = make_demo_scene();
  Framebuffer fb(kWidth, kHeight);
  render_mesh(fb, scene.mesh, scene.camera, options);
  return fb.to_image();
}

// Counts pixels whose channels differ by more than the tolerance, writing the diff image.
int compare(const Image& got, const Image& want, const std::string& diff_path) {
  Image diff(want.width, want.height);
  int bad = 0;
  for (size_t i = 0; i < want.rgba.size(); i += 4) {
    int worst = 0;
    for (int c = 0; c < 4; ++c)
      worst = std::max(worst, std::abs(got.rgba[i + c] - want.rgba[i + c]));
    bool out = worst > kTolerance;
    bad += out;
    for (int c = 0; c < 3; ++c) diff.rgba[i + c] = out ? (c == 0 ? 255 : 0) : want.rgba[i + c] / 3;
    diff.rgba[i + 3] = 255;
  }
  if (bad) {
    EXPECT_TRUE(save_image(diff_path, diff).ok());
  }
  return bad;
}

void check_golden(const std::string& name, const Image& got) {
  std::string path = std::string(SOFTRAST_GOLDEN_DIR) + "/" + name + ".png";
  if (std::getenv("SOFTRAST_UPDATE_GOLDEN")) {
    ASSERT_TRUE(save_image(path, got).ok());
    GTEST_SKIP() << "wrote " << path;
  }
  Result<Image> want = load_image(path);
  ASSERT_TRUE(want.ok()) << want.status().message();
  ASSERT_EQ(want->width, got.width);
  ASSERT_EQ(want->height, got.height);
  std::string diff_path = (std::filesystem::current_path() / (name + "_diff.png")).string();
  int bad = compare(got, *want, diff_path);
  EXPECT_EQ(bad, 0) << bad << " pixels of " << name << " differ by more than " << kTolerance
                    << "; diff image: " << diff_path;
}

class GoldenShader : public ::testing::TestWithParam<ShaderKind> {};

TEST_P(GoldenShader, DemoSceneMatchesGolden) {
  RenderOptions options;
  options.shader = GetParam();
  check_golden(std::string("demo_") + shader_kind_name(GetParam()), render_demo(options));
}

INSTANTIATE_TEST_SUITE_P(AllShaders, GoldenShader,
                         ::testing::Values(ShaderKind::kFlat, ShaderKind::kGouraud,
                                           ShaderKind::kTexture, ShaderKind::kPhong,
                                           ShaderKind::kNormals, ShaderKind::kDepth,
                                           ShaderKind::kWireframe),
                         [](const auto& info) {
                           return std::string(shader_kind_name(info.param));
                         });

TEST(Golden, WireframeOverlay) {
  RenderOptions options;
  options.wireframe_overlay = true;
  check_golden("demo_phong_wireframe_overlay", render_demo(options));
}

TEST(Golden, NearestFilteringAndAlphaBlending) {
  RenderOptions options;
  options.shader = ShaderKind::kTexture;
  options.sampler.filter = Filter::kNearest;
  options.state.blend = BlendMode::kAlpha;
  options.alpha = 0.6f;
  options.state.cull = CullMode::kNone;
  check_golden("demo_texture_nearest_alpha", render_demo(options));
}

// The scanline rasterizer must give the very same image as the default one, pixel for pixel.
TEST(Golden, ScanlineRasterizerGivesTheSameImage) {
  RenderOptions options;
  Image edge = render_demo(options);
  options.state.raster = RasterAlgorithm::kScanline;
  Image scan = render_demo(options);
  EXPECT_TRUE(edge.rgba == scan.rgba);
}

}  // namespace
}  // namespace softrast
