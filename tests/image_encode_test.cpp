// tests/image_encode_test.cpp: the PNG and JPEG writers. PNG must read back bit for bit and be
// written the fast way (zlib level 1, the SUB filter on every row); JPEG must decode back close to
// the image at the quality asked for.

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <zlib.h>

#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

// A deterministic image with smooth gradients, hard edges and noise, so every filter and every
// channel value matters; `opaque` sets every alpha to 255 (the RGB path of the PNG writer).
Image test_image(int width, int height, bool opaque) {
  Image image(width, height);
  uint32_t state = 12345;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      state = state * 1664525u + 1013904223u;
      uint8_t* p = image.pixel(x, y);
      p[0] = uint8_t(x * 255 / std::max(1, width - 1));
      p[1] = uint8_t((x / 8 + y / 8) % 2 ? 200 : 30);
      p[2] = uint8_t(state >> 24);
      p[3] = opaque ? 255 : uint8_t((x * 7 + y * 3) & 0xff);
    }
  }
  return image;
}

uint32_t big_endian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// The IHDR colour type and the concatenated IDAT payload of a PNG file.
struct PngParts {
  int color_type = -1;
  std::vector<uint8_t> idat;
};

PngParts png_parts(const std::vector<uint8_t>& png) {
  PngParts parts;
  for (size_t at = 8; at + 12 <= png.size();) {
    size_t length = big_endian32(&png[at]);
    std::string type(reinterpret_cast<const char*>(&png[at + 4]), 4);
    if (type == "IHDR") parts.color_type = png[at + 8 + 9];
    if (type == "IDAT") parts.idat.insert(parts.idat.end(), &png[at + 8], &png[at + 8 + length]);
    at += 12 + length;
  }
  return parts;
}

class ImageEncodeTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("softrast_encode_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(ImageEncodeTest, PngReadsBackBitForBitWithAndWithoutAlpha) {
  for (bool opaque : {false, true}) {
    for (auto [w, h] : {std::pair{1, 1}, std::pair{37, 23}, std::pair{640, 360}}) {
      Image image = test_image(w, h, opaque);
      ASSERT_TRUE(save_image(path("out.png"), image).ok());
      Result<Image> back = load_image(path("out.png"));
      ASSERT_TRUE(back.ok()) << back.status().message();
      EXPECT_EQ(back->width, w);
      EXPECT_EQ(back->height, h);
      EXPECT_TRUE(back->rgba == image.rgba) << w << "x" << h << " opaque " << opaque;
    }
  }
}

// The speed settings, read from the file itself: stb_image_write (the old writer) used zlib level
// 8 and tried all five filters per row; a change back would fail here.
TEST_F(ImageEncodeTest, PngUsesZlibLevelOneAndTheSubFilterOnEveryRow) {
  for (bool opaque : {false, true}) {
    Image image = test_image(300, 200, opaque);
    Result<std::vector<uint8_t>> png = encode_image(image, ImageFormat::kPng);
    ASSERT_TRUE(png.ok()) << png.status().message();
    PngParts parts = png_parts(*png);
    EXPECT_EQ(parts.color_type, opaque ? 2 : 6);  // RGB when every alpha is 255
    ASSERT_GE(parts.idat.size(), 2u);
    // The zlib header's FLEVEL (top two bits of the second byte): 0 is "fastest", levels 0-1.
    EXPECT_EQ(parts.idat[1] >> 6, 0) << "zlib level above 1";
    size_t row_bytes = 1 + size_t(image.width) * (opaque ? 3 : 4);
    std::vector<uint8_t> raw(row_bytes * size_t(image.height));
    uLongf raw_size = uLongf(raw.size());
    ASSERT_EQ(uncompress(raw.data(), &raw_size, parts.idat.data(), uLong(parts.idat.size())), Z_OK);
    ASSERT_EQ(raw_size, raw.size());
    for (int y = 0; y < image.height; ++y) EXPECT_EQ(raw[size_t(y) * row_bytes], 1) << "row " << y;
  }
}

TEST_F(ImageEncodeTest, JpegDecodesBackWithinItsTolerance) {
  // A smooth image (JPEG's case: no noise), alpha 128 everywhere to show it is dropped.
  Image image(96, 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 96; ++x) {
      uint8_t* p = image.pixel(x, y);
      p[0] = uint8_t(x * 255 / 95);
      p[1] = uint8_t(y * 255 / 63);
      p[2] = uint8_t((x + y) * 255 / 158);
      p[3] = 128;
    }
  }
  ASSERT_TRUE(save_image(path("out.jpg"), image).ok());  // default quality 90
  Result<Image> back = load_image(path("out.jpg"));
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->width, 96);
  ASSERT_EQ(back->height, 64);
  // Tolerance at quality 90 on smooth gradients: every channel within 8/255, mean within 1.5/255.
  int worst = 0;
  double sum = 0.0;
  for (size_t i = 0; i < image.rgba.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      int d = std::abs(int(back->rgba[i + c]) - int(image.rgba[i + c]));
      worst = std::max(worst, d);
      sum += d;
    }
    EXPECT_EQ(back->rgba[i + 3], 255);
  }
  EXPECT_LE(worst, 8);
  EXPECT_LE(sum / (96.0 * 64.0 * 3.0), 1.5);
  // Quality is passed on: lower quality, smaller file; upper-case .JPEG is JPEG too.
  Result<std::vector<uint8_t>> low = encode_image(test_image(96, 64, true), ImageFormat::kJpeg, 20);
  Result<std::vector<uint8_t>> high =
      encode_image(test_image(96, 64, true), ImageFormat::kJpeg, 98);
  ASSERT_TRUE(low.ok() && high.ok());
  EXPECT_LT(low->size() * 2, high->size());
  EXPECT_EQ(image_format_of("a/b.JPEG"), ImageFormat::kJpeg);
  EXPECT_EQ(image_format_of("a/b.bmp"), std::nullopt);
}

TEST_F(ImageEncodeTest, BadRequestsAreErrors) {
  Image image = test_image(8, 8, true);
  Result<std::vector<uint8_t>> bad = encode_image(image, ImageFormat::kJpeg, 0);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "JPEG quality 0 is outside 1..100");
  Status s = save_image(path("out.bmp"), image);
  EXPECT_EQ(s.message(), path("out.bmp") + ": unknown image extension (use .png, .jpg or .tga)");
  Image broken = image;
  broken.rgba.pop_back();
  s = save_image(path("out.png"), broken);
  EXPECT_EQ(s.message(), path("out.png") + ": invalid image 8x8 with 255 bytes");
  EXPECT_FALSE(fs::exists(path("out.png")));
}

}  // namespace
}  // namespace softrast
