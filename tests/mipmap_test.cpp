// Mip chains and trilinear filtering: the chain's sizes for any texture size, its box filter,
// the level of detail from derivatives (OpenGL's definition), constant textures at every level,
// and a receding plane that aliases with bilinear filtering and does not with trilinear.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "softrast/renderer.hpp"

namespace softrast {
namespace {

Texture texture_of(int width, int height, auto&& rgba_at) {
  Image image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::array<uint8_t, 4> c = rgba_at(x, y);
      std::copy(c.begin(), c.end(), image.pixel(x, y));
    }
  }
  return Texture::from_image(image);
}

// One-texel black and white squares.
Texture fine_checker(int size) {
  return texture_of(size, size, [](int x, int y) {
    uint8_t v = ((x + y) & 1) ? 255 : 0;
    return std::array<uint8_t, 4>{v, v, v, 255};
  });
}

TEST(Mipmap, ChainHalvesEachSideDownToOneTexel) {
  Texture t = texture_of(37, 19, [](int, int) { return std::array<uint8_t, 4>{1, 2, 3, 4}; });
  std::vector<std::pair<int, int>> want = {{37, 19}, {18, 9}, {9, 4}, {4, 2}, {2, 1}, {1, 1}};
  ASSERT_EQ(t.levels(), int(want.size()));
  size_t offset = 0;
  for (int k = 0; k < t.levels(); ++k) {
    EXPECT_EQ(t.level(k).width, want[size_t(k)].first) << "level " << k;
    EXPECT_EQ(t.level(k).height, want[size_t(k)].second) << "level " << k;
    EXPECT_EQ(t.level(k).offset, offset) << "level " << k;
    offset += size_t(t.level(k).width) * size_t(t.level(k).height);
  }
  Texture square = fine_checker(256);
  EXPECT_EQ(square.levels(), 9);  // 256, 128, ..., 1
}

TEST(Mipmap, BoxFilterAveragesTwoByTwoRounded) {
  // 2x2 texels with red 0, 10, 20, 31: level 1 is their mean 15.25, rounded to 15.
  const uint8_t red[2][2] = {{0, 10}, {20, 31}};
  Texture t = texture_of(2, 2, [&](int x, int y) {
    return std::array<uint8_t, 4>{red[y][x], 0, 0, 255};
  });
  ASSERT_EQ(t.levels(), 2);
  const uint8_t* top = t.texels() + t.level(1).offset * 4;
  EXPECT_EQ(top[0], 15);
  EXPECT_EQ(top[3], 255);
}

TEST(Mipmap, LevelOfDetailIsLog2OfTheLongerDerivativeInTexels) {
  Texture t = fine_checker(256);
  for (int k = -3; k <= 10; ++k) {
    float step = std::ldexp(1.0f, k) / 256.0f;  // 2^k texels per pixel
    EXPECT_NEAR(t.level_of_detail({step, 0.0f}, {0.0f, step * 0.5f}), float(k), 1e-4f);
    EXPECT_NEAR(t.level_of_detail({0.0f, 0.0f}, {step * 0.6f, step * 0.8f}), float(k), 1e-4f);
  }
  EXPECT_LT(t.level_of_detail({0.0f, 0.0f}, {0.0f, 0.0f}), -60.0f);  // no change: magnified
}

TEST(Mipmap, ConstantTextureIsTheConstantAtEveryLevelOfDetail) {
  Texture t = texture_of(48, 20, [](int, int) { return std::array<uint8_t, 4>{200, 100, 50, 25}; });
  Sampler s{Filter::kTrilinear, Wrap::kRepeat, Wrap::kRepeat};
  for (float lod = -2.0f; lod < 12.0f; lod += 0.37f) {
    float step = std::exp2(lod) / 48.0f;
    for (glm::vec2 uv : {glm::vec2(0.1f, 0.2f), glm::vec2(-2.3f, 7.9f), glm::vec2(0.5f, 0.5f)}) {
      glm::vec4 c = t.sample(s, uv, {step, 0.0f}, {0.0f, step});
      EXPECT_FLOAT_EQ(c.r, 200.0f / 255.0f) << "lod " << lod;
      EXPECT_FLOAT_EQ(c.g, 100.0f / 255.0f) << "lod " << lod;
      EXPECT_FLOAT_EQ(c.b, 50.0f / 255.0f) << "lod " << lod;
      EXPECT_FLOAT_EQ(c.a, 25.0f / 255.0f) << "lod " << lod;
    }
  }
}

TEST(Mipmap, TrilinearBlendsTheTwoLevelsAroundTheLevelOfDetail) {
  // Level 0 of the fine checker is black and white, every other level grey (128).
  Texture t = fine_checker(64);
  Sampler s{Filter::kTrilinear, Wrap::kRepeat, Wrap::kRepeat};
  // Texel (0, 0) is the bottom-left of the image, pixel (0, 63): white.
  glm::vec2 white_centre(0.5f / 64.0f, 0.5f / 64.0f);
  auto red = [&](float lod) {
    float step = std::exp2(lod) / 64.0f;
    return t.sample(s, white_centre, {step, 0.0f}, {0.0f, step}).r * 255.0f;
  };
  EXPECT_NEAR(red(-1.0f), 255.0f, 1e-3f);  // magnified: the base level, bilinear
  EXPECT_NEAR(red(0.0f), 255.0f, 1e-3f);
  EXPECT_NEAR(red(0.5f), 0.5f * 255.0f + 0.5f * 128.0f, 0.05f);
  EXPECT_NEAR(red(0.25f), 0.75f * 255.0f + 0.25f * 128.0f, 0.05f);
  EXPECT_NEAR(red(3.0f), 128.0f, 1e-3f);
  EXPECT_NEAR(red(40.0f), 128.0f, 1e-3f);  // past the last level: the 1x1 level
  // Without derivatives, or with another filter, the base level is sampled.
  EXPECT_NEAR(t.sample(s, white_centre).r * 255.0f, 255.0f, 1e-3f);
}

// A ground plane receding to the horizon, textured with one-texel squares: bilinear filtering
// aliases far away (black and white pixels side by side), trilinear filtering averages them to
// grey, and near the camera both show the squares.
TEST(Mipmap, RecedingPlaneIsGreyInTheDistanceWithTrilinearOnly) {
  Mesh plane;
  plane.positions = {{-50, 0, 5}, {50, 0, 5}, {50, 0, -200}, {-50, 0, -200}};
  plane.normals.assign(4, glm::vec3(0, 1, 0));
  plane.uvs = {{0, 0}, {100, 0}, {100, 205}, {0, 205}};  // 1 uv per world unit, 64 texels
  plane.indices = {0, 1, 2, 0, 2, 3};
  Camera camera;
  camera.eye = {0, 1.5f, 5};
  camera.target = {0, 0.5f, -10};
  camera.near_plane = 0.1f;
  camera.far_plane = 500.0f;
  auto far_rows_spread = [&](Filter filter) {
    RenderOptions options;
    options.shader = ShaderKind::kTexture;
    options.texture = std::make_shared<Texture>(fine_checker(64));
    options.sampler.filter = filter;
    Framebuffer fb(320, 240);
    render_mesh(fb, plane, camera, options);
    // Rows just below the horizon: the spread of red around grey.
    int worst = 0, covered = 0;
    for (int y = 0; y < 240; ++y) {
      for (int x = 40; x < 280; ++x) {
        if (fb.depth_at(x, y) >= 1.0f || fb.depth_at(x, y) < 0.995f) continue;  // far only
        ++covered;
        worst = std::max(worst, std::abs(int(fb.color_at(x, y) & 0xff) - 128));
      }
    }
    EXPECT_GT(covered, 500);
    return worst;
  };
  EXPECT_LE(far_rows_spread(Filter::kTrilinear), 16);
  EXPECT_GE(far_rows_spread(Filter::kBilinear), 100);
}

}  // namespace
}  // namespace softrast
