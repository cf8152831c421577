// tests/image_decode_test.cpp: the image decoders behind load_image/decode_image (PNG through
// libspng, JPEG through libjpeg-turbo, our own TGA). Only the three formats, chosen by content;
// size limits applied from the header before any pixel is allocated; truncated or corrupt files
// an error at every cut, never invented pixels. Test images are made here with libspng's and
// libjpeg's encoders or byte by byte; run under the debug preset's sanitizers as well.

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <spng.h>
#include <zlib.h>

#include "io/image_decode.hpp"
#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

using Rgba = std::array<uint8_t, 4>;

const std::string kUnsupported = "mem: unsupported image format (PNG, TGA and JPG are supported)";

Result<Image> decode(const std::string& bytes) {
  return decode_image(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "mem");
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string bytes_of(std::initializer_list<int> values) {
  std::string s;
  for (int v : values) s += char(v);
  return s;
}

Rgba pixel(const Image& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  return {p[0], p[1], p[2], p[3]};
}

// The process's peak resident memory in KiB. ctest runs every test in its own process, so the
// growth across a call shows what that call touched; in one long run an earlier, larger peak can
// hide it (the check then passes vacuously, never wrongly fails).
long peak_rss_kib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// Refused, with `part` in the message, without the process's memory growing by 64 MiB.
void expect_refused_small(const std::string& bytes, const std::string& part) {
  long before = peak_rss_kib();
  Result<Image> image = decode(bytes);
  long grown_kib = peak_rss_kib() - before;
  ASSERT_FALSE(image.ok());
  EXPECT_TRUE(contains(image.status().message(), part)) << image.status().message();
  EXPECT_LT(grown_kib, 64 * 1024) << "the refusal allocated memory";
}

// Every strict prefix of `bytes` (from empty to one byte short) fails with a message; none
// decodes to an image. The complete file must decode.
void expect_every_cut_fails(const std::string& bytes) {
  ASSERT_TRUE(decode(bytes).ok()) << decode(bytes).status().message();
  for (size_t keep = 0; keep < bytes.size(); ++keep) {
    Result<Image> image = decode(bytes.substr(0, keep));
    ASSERT_FALSE(image.ok()) << "cut to " << keep << " of " << bytes.size() << " bytes decoded";
    ASSERT_FALSE(image.status().message().empty());
  }
}

// ---- Which formats ---------------------------------------------------------------------------

TEST(ImageDecode, SixteenBitPgmIsUnsupported) {
  // 19 bytes declaring 1000x1000 16-bit grey with no data: stb_image 2.27 read past the heap
  // buffer converting it (SIGSEGV); a complete 2x2 one decoded to heap garbage.
  const std::string header_only = "P5\n1000 1000\n65535\n";
  ASSERT_EQ(header_only.size(), 19u);
  const std::string complete =
      "P5\n2 2\n65535\n" + bytes_of({0, 1, 0x80, 0, 0xff, 0xff, 0x12, 0x34});
  for (const std::string& pgm : {header_only, complete, header_only + "x"}) {
    Result<Image> image = decode(pgm);
    ASSERT_FALSE(image.ok());
    EXPECT_EQ(image.status().message(), kUnsupported);
  }
}

TEST(ImageDecode, OtherFormatsStbDecodedAreUnsupported) {
  // Each of these is a complete 1x1 image that stb_image decodes.
  const std::string gif =
      "GIF89a" + bytes_of({1, 0, 1, 0, 0x80, 0, 0, 255, 0, 0, 0,    0, 255, 0x2c, 0,
                           0, 0, 0, 1, 0,    1, 0, 0,   2, 2, 0x44, 1, 0,   0x3b});
  const std::string bmp =
      "BM" + bytes_of({58, 0, 0,    0,    0, 0, 0, 0,  54, 0, 0, 0, 40, 0, 0,   0, 1, 0,    0,
                       0,  1, 0,    0,    0, 1, 0, 24, 0,  0, 0, 0, 0,  4, 0,   0, 0, 0x13, 0x0b,
                       0,  0, 0x13, 0x0b, 0, 0, 0, 0,  0,  0, 0, 0, 0,  0, 255, 0, 0, 0});
  const std::string psd =
      "8BPS" + bytes_of({0, 1, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0, 0, 1, 0, 0, 0,  1,  0, 8,
                         0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 10, 20, 30});
  const std::string hdr =
      "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n" + bytes_of({128, 64, 32, 129});
  const std::string ppm = "P6\n1 1\n255\n" + bytes_of({1, 2, 3});
  const std::string pic = bytes_of({0x53, 0x80, 0xf6, 0x34}) + std::string(100, 'x');
  for (const std::string& file : {gif, bmp, psd, hdr, ppm, pic}) {
    SCOPED_TRACE(file.substr(0, 4));
    Result<Image> image = decode(file);
    ASSERT_FALSE(image.ok());
    EXPECT_EQ(image.status().message(), kUnsupported);
  }
}

TEST(ImageDecode, EmptyAndShortInputs) {
  EXPECT_EQ(decode_image(nullptr, 0, "mem").status().message(), "mem: empty file");
  EXPECT_EQ(decode("hello").status().message(), kUnsupported);
  EXPECT_EQ(decode(std::string(64, '\0')).status().message(), kUnsupported);
  EXPECT_FALSE(decode("\x89PN").ok());  // the start of a PNG signature: a cut PNG
  EXPECT_FALSE(decode("\xff\xd8").ok());
}

TEST(ImageDecode, SizeLimitBoundaries) {
  EXPECT_TRUE(detail::check_image_size("n", 16384, 4096).ok());  // exactly kMaxImagePixels
  EXPECT_TRUE(detail::check_image_size("n", 1, 16384).ok());
  EXPECT_EQ(detail::check_image_size("n", 16384, 4097).message(),
            "n: image size 16384x4097 has more than 67108864 pixels, the limit for images");
  EXPECT_EQ(detail::check_image_size("n", 16385, 1).message(),
            "n: image size 16385x1 is outside 1..16384");
  EXPECT_FALSE(detail::check_image_size("n", 0, 5).ok());
  EXPECT_FALSE(detail::check_image_size("n", 65535, 65535).ok());
}

// ---- PNG -------------------------------------------------------------------------------------

struct SpngDeleter {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};

// A PNG written by libspng's encoder from rows in the PNG's own layout (SPNG_FMT_PNG: 16-bit
// samples host-endian).
std::string encode_png(uint32_t width, uint32_t height, uint8_t color_type, uint8_t bit_depth,
                       const void* pixels, size_t size, spng_plte* plte = nullptr,
                       spng_trns* trns = nullptr) {
  std::unique_ptr<spng_ctx, SpngDeleter> ctx(spng_ctx_new(SPNG_CTX_ENCODER));
  spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1);
  spng_ihdr ihdr{width, height, bit_depth, color_type, 0, 0, 0};
  EXPECT_EQ(spng_set_ihdr(ctx.get(), &ihdr), 0);
  if (plte) {
    EXPECT_EQ(spng_set_plte(ctx.get(), plte), 0);
  }
  if (trns) {
    EXPECT_EQ(spng_set_trns(ctx.get(), trns), 0);
  }
  int code = spng_encode_image(ctx.get(), pixels, size, SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  EXPECT_EQ(code, 0) << spng_strerror(code);
  size_t length = 0;
  int error = 0;
  void* buffer = spng_get_png_buffer(ctx.get(), &length, &error);
  std::string png(static_cast<const char*>(buffer), length);
  std::free(buffer);
  return png;
}

std::string be32(uint32_t v) {
  return bytes_of({int(v >> 24), int(v >> 16 & 255), int(v >> 8 & 255), int(v & 255)});
}

// One chunk with a correct CRC, so only the fields inside can be what is refused.
std::string png_chunk(const std::string& type, const std::string& data) {
  std::string body = type + data;
  uLong crc = crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()));
  return be32(uint32_t(data.size())) + body + be32(uint32_t(crc));
}

std::string zlib_compress(const std::string& raw) {
  uLongf size = compressBound(uLong(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                      reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), Z_BEST_SPEED),
            Z_OK);
  out.resize(size);
  return out;
}

// A well-formed PNG of the given size and colour type (8 bits) whose pixels are all zero:
// filter byte 0 and zero samples for every row, compressed for real.
std::string zero_png(uint32_t width, uint32_t height, int color_type, int channels) {
  std::string ihdr = be32(width) + be32(height) + bytes_of({8, color_type, 0, 0, 0});
  std::string raw(size_t(height) * (1 + size_t(width) * size_t(channels)), '\0');
  return "\x89PNG\r\n\x1a\n" + png_chunk("IHDR", ihdr) + png_chunk("IDAT", zlib_compress(raw)) +
         png_chunk("IEND", "");
}

TEST(ImageDecode, PngRgbaDecodesExactly) {
  std::vector<uint8_t> rgba(5 * 3 * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = uint8_t(i * 37 + 11);
  Result<Image> image =
      decode(encode_png(5, 3, SPNG_COLOR_TYPE_TRUECOLOR_ALPHA, 8, rgba.data(), rgba.size()));
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->width, 5);
  EXPECT_EQ(image->height, 3);
  EXPECT_EQ(image->rgba, rgba);
}

TEST(ImageDecode, PngPaletteWithTransparency) {
  spng_plte plte{};
  plte.n_entries = 3;
  plte.entries[0] = {255, 0, 0, 0};
  plte.entries[1] = {0, 255, 0, 0};
  plte.entries[2] = {10, 20, 30, 0};
  spng_trns trns{};
  trns.n_type3_entries = 2;  // entry 2 has no alpha entry: opaque
  trns.type3_alpha[0] = 0;
  trns.type3_alpha[1] = 128;
  const uint8_t indices[4] = {0, 1, 2, 1};  // 2 x 2
  Result<Image> image =
      decode(encode_png(2, 2, SPNG_COLOR_TYPE_INDEXED, 8, indices, 4, &plte, &trns));
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(pixel(*image, 0, 0), (Rgba{255, 0, 0, 0}));
  EXPECT_EQ(pixel(*image, 1, 0), (Rgba{0, 255, 0, 128}));
  EXPECT_EQ(pixel(*image, 0, 1), (Rgba{10, 20, 30, 255}));
  EXPECT_EQ(pixel(*image, 1, 1), (Rgba{0, 255, 0, 128}));
}

TEST(ImageDecode, PngGreyWithKeyColourAndGreyAlpha) {
  spng_trns key{};
  key.gray = 7;  // grey 7 is transparent
  const uint8_t grey[3] = {7, 100, 255};
  Result<Image> keyed =
      decode(encode_png(3, 1, SPNG_COLOR_TYPE_GRAYSCALE, 8, grey, 3, nullptr, &key));
  ASSERT_TRUE(keyed.ok()) << keyed.status().message();
  EXPECT_EQ(pixel(*keyed, 0, 0), (Rgba{7, 7, 7, 0}));
  EXPECT_EQ(pixel(*keyed, 1, 0), (Rgba{100, 100, 100, 255}));
  EXPECT_EQ(pixel(*keyed, 2, 0), (Rgba{255, 255, 255, 255}));

  const uint8_t grey_alpha[4] = {50, 200, 250, 3};
  Result<Image> ga = decode(encode_png(2, 1, SPNG_COLOR_TYPE_GRAYSCALE_ALPHA, 8, grey_alpha, 4));
  ASSERT_TRUE(ga.ok()) << ga.status().message();
  EXPECT_EQ(pixel(*ga, 0, 0), (Rgba{50, 50, 50, 200}));
  EXPECT_EQ(pixel(*ga, 1, 0), (Rgba{250, 250, 250, 3}));
}

TEST(ImageDecode, Png16BitRgbBecomes8Bit) {
  const uint16_t rgb[6] = {0xffff, 0x0000, 0x8080, 0x1234, 0xabcd, 0x0101};  // 2 x 1
  Result<Image> image = decode(encode_png(2, 1, SPNG_COLOR_TYPE_TRUECOLOR, 16, rgb, sizeof rgb));
  ASSERT_TRUE(image.ok()) << image.status().message();
  for (int x = 0; x < 2; ++x) {
    for (int c = 0; c < 3; ++c) {
      double exact = rgb[x * 3 + c] / 257.0;  // 16-bit to 8-bit, within rounding
      EXPECT_NEAR(image->pixel(x, 0)[c], exact, 1.0) << "x " << x << " channel " << c;
    }
    EXPECT_EQ(image->pixel(x, 0)[3], 255);
  }
}

TEST(ImageDecode, PngEveryTruncationIsAnError) {
  std::vector<uint8_t> rgba(6 * 4 * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = uint8_t(i * 13);
  expect_every_cut_fails(
      encode_png(6, 4, SPNG_COLOR_TYPE_TRUECOLOR_ALPHA, 8, rgba.data(), rgba.size()));
  expect_every_cut_fails(zero_png(9, 5, SPNG_COLOR_TYPE_GRAYSCALE, 1));
}

TEST(ImageDecode, PngCorruptChecksumIsAnError) {
  std::string png = zero_png(4, 4, SPNG_COLOR_TYPE_TRUECOLOR, 3);
  png[png.size() - 12 - 1] ^= 1;  // the IDAT CRC's last byte (IEND is the last 12 bytes)
  Result<Image> image = decode(png);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(), "mem: corrupt PNG: invalid chunk checksum");
}

TEST(ImageDecode, PngOverEitherSizeLimitIsRefusedBeforeAllocating) {
  // 65535 x 65535: 16 GiB as RGBA, refused by the per-side limit from the IHDR alone.
  std::string ihdr = be32(65535) + be32(65535) + bytes_of({8, 6, 0, 0, 0});
  std::string huge = "\x89PNG\r\n\x1a\n" + png_chunk("IHDR", ihdr) +
                     png_chunk("IDAT", zlib_compress(std::string(64, '\0'))) +
                     png_chunk("IEND", "");
  expect_refused_small(huge, "mem: image size 65535x65535 is outside 1..16384");
  // Within 16384 each way but over the pixel cap: a real, complete grey PNG (about 65 KB of
  // deflate data) that would inflate to 268 MB of RGBA.
  expect_refused_small(zero_png(16384, 4097, SPNG_COLOR_TYPE_GRAYSCALE, 1),
                       "mem: image size 16384x4097 has more than 67108864 pixels");
}

// ---- JPEG ------------------------------------------------------------------------------------

// A JPEG written by libjpeg (quality 95, standard Huffman tables) from `components`-byte pixels
// in `space`; progressive if asked.
std::string encode_jpeg(int width, int height, J_COLOR_SPACE space, int components,
                        const std::vector<uint8_t>& pixels, bool progressive = false) {
  jpeg_compress_struct cinfo{};
  jpeg_error_mgr errors{};
  cinfo.err = jpeg_std_error(&errors);
  jpeg_create_compress(&cinfo);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&cinfo, &out, &size);
  cinfo.image_width = JDIMENSION(width);
  cinfo.image_height = JDIMENSION(height);
  cinfo.input_components = components;
  cinfo.in_color_space = space;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 95, TRUE);
  if (progressive) jpeg_simple_progression(&cinfo);
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<uint8_t*>(&pixels[size_t(cinfo.next_scanline) * width * components]);
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  std::string jpeg(reinterpret_cast<const char*>(out), size);
  jpeg_destroy_compress(&cinfo);
  std::free(out);
  return jpeg;
}

std::string solid_jpeg(int size, Rgba colour, bool progressive = false) {
  std::vector<uint8_t> rgb;
  for (int i = 0; i < size * size; ++i) rgb.insert(rgb.end(), colour.begin(), colour.begin() + 3);
  return encode_jpeg(size, size, JCS_RGB, 3, rgb, progressive);
}

// A photo-like 24 x 16 gradient, so that the entropy data is more than a few bytes.
std::string gradient_jpeg(bool progressive) {
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 24; ++x) rgb.insert(rgb.end(), {uint8_t(x * 10), uint8_t(y * 15), 90});
  }
  return encode_jpeg(24, 16, JCS_RGB, 3, rgb, progressive);
}

// The offset of the first marker segment `marker` (FF marker) before the scan data, walking the
// segments by their lengths; the test fails if there is none.
size_t find_segment(const std::string& jpeg, int marker) {
  size_t at = 2;  // after SOI
  while (at + 4 <= jpeg.size() && uint8_t(jpeg[at]) == 0xff) {
    int m = uint8_t(jpeg[at + 1]);
    if (m == marker) return at;
    if (m == 0xda) break;  // scan data follows; no more segments to walk
    at += 2 + (uint8_t(jpeg[at + 2]) << 8 | uint8_t(jpeg[at + 3]));
  }
  ADD_FAILURE() << "no marker 0x" << std::hex << marker;
  return 0;
}

TEST(ImageDecode, JpegSolidColourDecodesWithinTolerance) {
  const Rgba colour = {200, 100, 50, 255};
  for (bool progressive : {false, true}) {
    SCOPED_TRACE(progressive ? "progressive" : "baseline");
    Result<Image> image = decode(solid_jpeg(16, colour, progressive));
    ASSERT_TRUE(image.ok()) << image.status().message();
    ASSERT_EQ(image->width, 16);
    ASSERT_EQ(image->height, 16);
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) {
        Rgba p = pixel(*image, x, y);
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(p[c], colour[c], 3) << x << "," << y;
        ASSERT_EQ(p[3], 255);
      }
    }
  }
}

TEST(ImageDecode, JpegGreyBecomesGreyRgba) {
  std::vector<uint8_t> grey(8 * 8, 77);
  Result<Image> image = decode(encode_jpeg(8, 8, JCS_GRAYSCALE, 1, grey));
  ASSERT_TRUE(image.ok()) << image.status().message();
  Rgba p = pixel(*image, 3, 5);
  EXPECT_NEAR(p[0], 77, 1);
  EXPECT_EQ(p[0], p[1]);
  EXPECT_EQ(p[1], p[2]);
  EXPECT_EQ(p[3], 255);
}

TEST(ImageDecode, JpegCmykIsRefusedClearly) {
  std::vector<uint8_t> cmyk(8 * 8 * 4, 40);
  Result<Image> image = decode(encode_jpeg(8, 8, JCS_CMYK, 4, cmyk));
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(), "mem: CMYK JPEG is not supported (save it as RGB)");
}

TEST(ImageDecode, JpegHuffmanTableWithTooManyCodesIsAnError) {
  std::string jpeg = solid_jpeg(16, {10, 20, 30, 255});
  size_t dht = find_segment(jpeg, 0xc4);
  // The 16 code counts follow the marker, the length and the class/id byte; 255 + 255 codes is
  // more than the 256 a table may hold (stb_image 2.27 wrote past its table for this).
  jpeg[dht + 5 + 14] = char(255);
  jpeg[dht + 5 + 15] = char(255);
  Result<Image> image = decode(jpeg);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(), "mem: cannot decode JPEG: Bogus Huffman table definition");
}

TEST(ImageDecode, JpegScanNamingAnUndefinedHuffmanTableIsAnError) {
  const std::string jpeg = solid_jpeg(16, {10, 20, 30, 255});
  size_t sos = find_segment(jpeg, 0xda);
  // The first component's table selectors (DC high nibble, AC low) follow the marker, the length,
  // the component count and the component id. Tables 0 and 1 are defined (or, if absent, the
  // standard ones are used, as Motion-JPEG expects); 2 and 3 are valid numbers never defined
  // here, 15 is out of range.
  for (int selectors : {0x22, 0x02, 0x30, 0xff}) {
    SCOPED_TRACE(selectors);
    std::string bad = jpeg;
    bad[sos + 6] = char(selectors);
    Result<Image> image = decode(bad);
    ASSERT_FALSE(image.ok());
    EXPECT_TRUE(contains(image.status().message(), "mem: cannot decode JPEG: Huffman table 0x"))
        << image.status().message();
  }
}

TEST(ImageDecode, JpegEveryTruncationIsAnError) {
  // libjpeg fills a cut file with grey after a warning; the decoder makes that warning an error.
  std::string jpeg = gradient_jpeg(false);
  Result<Image> cut = decode(jpeg.substr(0, jpeg.size() - 40));
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().message(), "mem: cannot decode JPEG: Premature end of JPEG file");
  expect_every_cut_fails(jpeg);
  expect_every_cut_fails(gradient_jpeg(true));
}

TEST(ImageDecode, JpegOverTheSizeLimitsIsRefusedBeforeDecoding) {
  std::string jpeg = solid_jpeg(16, {1, 2, 3, 255});
  size_t sof = find_segment(jpeg, 0xc0);  // height, then width, after the precision byte
  auto set_size = [&](int width, int height) {
    std::string s = jpeg;
    s[sof + 5] = char(height >> 8), s[sof + 6] = char(height & 255);
    s[sof + 7] = char(width >> 8), s[sof + 8] = char(width & 255);
    return s;
  };
  expect_refused_small(set_size(20000, 16), "mem: image size 20000x16 is outside 1..16384");
  expect_refused_small(set_size(16384, 4097), "has more than 67108864 pixels");
}

// ---- TGA -------------------------------------------------------------------------------------

// The 18-byte header, field by field.
struct TgaHeader {
  int id_length = 0;
  int map_type = 0;
  int image_type = 2;
  int map_first = 0;
  int map_length = 0;
  int map_bits = 0;
  int width = 1;
  int height = 1;
  int bits = 24;
  int descriptor = 0;

  std::string bytes() const {
    return bytes_of({id_length, map_type, image_type, map_first & 255, map_first >> 8,
                     map_length & 255, map_length >> 8, map_bits, 0, 0, 0, 0, width & 255,
                     width >> 8, height & 255, height >> 8, bits, descriptor});
  }
};

// The pixel formats a TGA can store; each stores some RGBA values exactly.
enum class TgaFormat { kBgr24, kBgra32, kRgb555, kGrey8, kGreyAlpha16, kMapped24, kMapped32 };

const TgaFormat kTgaFormats[] = {TgaFormat::kBgr24,   TgaFormat::kBgra32,      TgaFormat::kRgb555,
                                 TgaFormat::kGrey8,   TgaFormat::kGreyAlpha16, TgaFormat::kMapped24,
                                 TgaFormat::kMapped32};

uint8_t expand5(int v) {
  return uint8_t(v << 3 | v >> 2);
}

// Colour k (0..5) of a six-colour palette the format can store exactly.
Rgba tga_colour(TgaFormat format, int k) {
  const uint8_t a = uint8_t(40 * k + 15);
  switch (format) {
    case TgaFormat::kBgr24:
    case TgaFormat::kMapped24:
      return {uint8_t(250 - 40 * k), uint8_t(30 * k), uint8_t(17 * k + 3), 255};
    case TgaFormat::kBgra32:
    case TgaFormat::kMapped32:
      return {uint8_t(250 - 40 * k), uint8_t(30 * k), uint8_t(17 * k + 3), a};
    case TgaFormat::kRgb555:
      return {expand5(31 - 5 * k), expand5(3 * k), expand5(k + 9), 255};
    case TgaFormat::kGrey8:
      return {uint8_t(45 * k), uint8_t(45 * k), uint8_t(45 * k), 255};
    case TgaFormat::kGreyAlpha16:
      return {uint8_t(45 * k), uint8_t(45 * k), uint8_t(45 * k), a};
  }
  return {};
}

// Stored bytes of a true-colour or grey value (BGR(A), 5-5-5 little-endian, grey(+alpha)).
std::string store_colour(TgaFormat format, Rgba c) {
  switch (format) {
    case TgaFormat::kBgr24:
    case TgaFormat::kMapped24:
      return bytes_of({c[2], c[1], c[0]});
    case TgaFormat::kBgra32:
    case TgaFormat::kMapped32:
      return bytes_of({c[2], c[1], c[0], c[3]});
    case TgaFormat::kRgb555: {
      int v = (c[0] >> 3) << 10 | (c[1] >> 3) << 5 | c[2] >> 3;
      return bytes_of({v & 255, v >> 8});
    }
    case TgaFormat::kGrey8:
      return bytes_of({c[0]});
    case TgaFormat::kGreyAlpha16:
      return bytes_of({c[0], c[3]});
  }
  return {};
}

bool is_mapped(TgaFormat f) {
  return f == TgaFormat::kMapped24 || f == TgaFormat::kMapped32;
}

// A test picture: colour index per pixel, in top-row-first order. The first six pixels differ
// (a raw packet), then runs of four that cross row ends (width 5).
int colour_index(int i) {
  return i < 6 ? i : (i / 4) % 6;
}

struct TgaPicture {
  std::string file;
  Image expected;
};

// Packs stored pixel values into RLE packets: runs of two or more equal values become run
// packets, everything else raw packets, at most 128 pixels each.
std::string rle_encode(const std::vector<std::string>& values) {
  std::string out;
  size_t i = 0;
  while (i < values.size()) {
    size_t run = 1;
    while (i + run < values.size() && run < 128 && values[i + run] == values[i]) ++run;
    if (run >= 2) {
      out += char(0x80 | (run - 1));
      out += values[i];
      i += run;
      continue;
    }
    size_t raw = 1;
    while (i + raw < values.size() && raw < 128 &&
           (i + raw + 1 >= values.size() || values[i + raw] != values[i + raw + 1])) {
      ++raw;
    }
    out += char(raw - 1);
    for (size_t k = 0; k < raw; ++k) out += values[i + k];
    i += raw;
  }
  return out;
}

// A 5 x 3 TGA of `format`, raw or RLE, stored in the row order and direction given, with an ID
// field; colour-mapped ones have their map start at entry `map_first`.
TgaPicture make_tga(TgaFormat format, bool rle, bool top_down, bool right_to_left,
                    int map_first = 0) {
  const int width = 5, height = 3;
  TgaPicture picture{{}, Image(width, height)};
  std::vector<std::string> stored;  // per pixel in file order
  for (int row = 0; row < height; ++row) {
    for (int column = 0; column < width; ++column) {
      int x = right_to_left ? width - 1 - column : column;
      int y = top_down ? row : height - 1 - row;
      int k = colour_index(y * width + x);
      Rgba c = tga_colour(format, k);
      std::copy(c.begin(), c.end(), picture.expected.pixel(x, y));
      stored.push_back(is_mapped(format) ? bytes_of({k + map_first}) : store_colour(format, c));
    }
  }
  TgaHeader h;
  h.id_length = 3;
  h.width = width;
  h.height = height;
  h.descriptor = (top_down ? 0x20 : 0) | (right_to_left ? 0x10 : 0);
  std::string map;
  switch (format) {
    case TgaFormat::kBgr24:
      h.bits = 24;
      break;
    case TgaFormat::kBgra32:
      h.bits = 32, h.descriptor |= 8;
      break;
    case TgaFormat::kRgb555:
      h.bits = 16;
      break;
    case TgaFormat::kGrey8:
      h.bits = 8;
      break;
    case TgaFormat::kGreyAlpha16:
      h.bits = 16, h.descriptor |= 8;
      break;
    case TgaFormat::kMapped24:
    case TgaFormat::kMapped32:
      h.bits = 8, h.map_type = 1, h.map_first = map_first, h.map_length = 6;
      h.map_bits = format == TgaFormat::kMapped24 ? 24 : 32;
      for (int k = 0; k < 6; ++k) map += store_colour(format, tga_colour(format, k));
      break;
  }
  const bool grey = format == TgaFormat::kGrey8 || format == TgaFormat::kGreyAlpha16;
  h.image_type = (is_mapped(format) ? 1 : grey ? 3 : 2) + (rle ? 8 : 0);
  std::string data;
  if (rle) {
    data = rle_encode(stored);
  } else {
    for (const std::string& s : stored) data += s;
  }
  picture.file = h.bytes() + "id!" + map + data;
  return picture;
}

std::string format_name(TgaFormat format) {
  const char* names[] = {"bgr24",        "bgra32",   "rgb555",  "grey8",
                         "grey_alpha16", "mapped24", "mapped32"};
  return names[int(format)];
}

TEST(ImageDecode, TgaEveryFormatOrderAndCompression) {
  for (TgaFormat format : kTgaFormats) {
    for (bool rle : {false, true}) {
      for (int origin = 0; origin < 4; ++origin) {
        bool top_down = origin & 1, right_to_left = origin & 2;
        SCOPED_TRACE(format_name(format) + (rle ? " rle" : " raw") +
                     (top_down ? " top-down" : " bottom-up") + (right_to_left ? " rtl" : ""));
        TgaPicture picture = make_tga(format, rle, top_down, right_to_left);
        Result<Image> image = decode(picture.file);
        ASSERT_TRUE(image.ok()) << image.status().message();
        ASSERT_EQ(image->width, 5);
        ASSERT_EQ(image->height, 3);
        EXPECT_EQ(image->rgba, picture.expected.rgba);
      }
    }
  }
}

TEST(ImageDecode, TgaColourMapStartingPastEntryZero) {
  TgaPicture picture = make_tga(TgaFormat::kMapped24, true, false, false, 40);
  Result<Image> image = decode(picture.file);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->rgba, picture.expected.rgba);
}

TEST(ImageDecode, TgaColourMapIndexOutsideTheMapIsAnError) {
  for (int value : {0, 39, 46, 255}) {  // the map holds entries 40..45
    TgaHeader h;
    h.map_type = 1, h.image_type = 1, h.map_first = 40, h.map_length = 6, h.map_bits = 24;
    h.bits = 8;
    Result<Image> image = decode(h.bytes() + std::string(18, '\x7f') + bytes_of({value}));
    ASSERT_FALSE(image.ok()) << value;
    EXPECT_EQ(image.status().message(), "mem: corrupt TGA: a pixel indexes past the colour map");
  }
}

TEST(ImageDecode, TgaEveryTruncationIsAnError) {
  for (bool rle : {false, true}) {
    for (TgaFormat format : {TgaFormat::kBgra32, TgaFormat::kMapped24, TgaFormat::kGrey8}) {
      SCOPED_TRACE(format_name(format) + (rle ? " rle" : " raw"));
      expect_every_cut_fails(make_tga(format, rle, false, false).file);
    }
  }
}

TEST(ImageDecode, TgaWrittenByTheLibraryEveryTruncationIsAnError) {
  // save_image writes RLE TGAs through stb_image_write; they load back exactly (io_test) and
  // every cut of one is an error.
  Image image(7, 4);
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = uint8_t(i / 8 * 40);
  fs::path path =
      fs::temp_directory_path() / ("softrast_decode_" + std::to_string(getpid()) + ".tga");
  ASSERT_TRUE(save_image(path.string(), image).ok());
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(path);
  ASSERT_EQ(bytes[2], 10) << "expected an RLE true-colour file";
  ASSERT_EQ(decode(bytes)->rgba, image.rgba);
  expect_every_cut_fails(bytes);
}

TEST(ImageDecode, TgaRlePacketRunningPastTheImageIsAnError) {
  TgaHeader h;
  h.image_type = 10, h.width = 2, h.height = 2;
  // A run packet of 5 pixels for a 4-pixel image, then a raw packet of 2 after 3 pixels.
  for (const std::string& data :
       {bytes_of({0x84, 1, 2, 3}), bytes_of({0x82, 1, 2, 3, 0x01, 1, 2, 3, 4, 5, 6})}) {
    Result<Image> image = decode(h.bytes() + data);
    ASSERT_FALSE(image.ok());
    EXPECT_EQ(image.status().message(), "mem: corrupt TGA: an RLE packet runs past the image");
  }
}

TEST(ImageDecode, TgaRleDataEndingEarlyIsAnError) {
  TgaHeader h;
  h.image_type = 10, h.width = 200, h.height = 1;  // two packets needed, at least 8 bytes
  // Enough bytes for the up-front check, but the raw packet claims more pixels than follow.
  Result<Image> image = decode(h.bytes() + bytes_of({0x7f}) + std::string(20, '\1'));
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(), "mem: truncated TGA: the pixel data ends early");
}

TEST(ImageDecode, TgaHugeHeaderWithoutDataIsRefusedBeforeAllocating) {
  TgaHeader h;
  h.width = h.height = 16384;  // 1 GiB as RGBA; the old decoder allocated it and returned zeros
  h.bits = 32;
  expect_refused_small(h.bytes(),
                       "mem: truncated TGA: 16384x16384 pixels need 1073741824 bytes of pixel "
                       "data, the file has 0 (1073741824 missing)");
  h.image_type = 10;  // RLE: at least one 5-byte packet per 128 pixels
  expect_refused_small(h.bytes() + "abc",
                       "need at least 10485760 bytes of pixel data, the file "
                       "has 3 (10485757 missing)");
}

TEST(ImageDecode, TgaOverThePixelCapIsRefusedBeforeAllocating) {
  // Complete RLE data (a run of 128 per packet, 1 MB) for 16384 x 4097 grey pixels.
  TgaHeader h;
  h.image_type = 11, h.bits = 8, h.width = 16384, h.height = 4097;
  std::string data;
  for (int64_t packets = 16384 * 4097 / 128; packets > 0; --packets) data += "\xff\x40";
  expect_refused_small(h.bytes() + data,
                       "mem: image size 16384x4097 has more than 67108864 pixels");
}

TEST(ImageDecode, TgaInvalidHeadersAreUnsupported) {
  auto with = [](const std::function<void(TgaHeader&)>& change) {
    TgaHeader h;
    h.width = h.height = 2;
    change(h);
    return h.bytes() + std::string(64, '\x11');
  };
  ASSERT_TRUE(decode(with([](TgaHeader&) {})).ok());  // the unchanged header is fine
  const std::vector<std::function<void(TgaHeader&)>> changes = {
      [](TgaHeader& h) { h.image_type = 0; },   // no image data
      [](TgaHeader& h) { h.image_type = 4; },   // no such type
      [](TgaHeader& h) { h.image_type = 32; },  // Huffman/delta compressed, obsolete
      [](TgaHeader& h) { h.map_type = 2; },
      [](TgaHeader& h) { h.bits = 17; },
      [](TgaHeader& h) { h.bits = 8; },        // 8 bits is grey or mapped, not true colour
      [](TgaHeader& h) { h.image_type = 3; },  // grey 24-bit
      [](TgaHeader& h) { h.image_type = 1; },  // colour-mapped without a map
      [](TgaHeader& h) { h.map_length = 4; },  // map entries but no map
      [](TgaHeader& h) { h.map_type = 1, h.map_length = 4, h.map_bits = 12; },
      [](TgaHeader& h) { h.map_type = 1, h.map_length = 0, h.map_bits = 24; },
      [](TgaHeader& h) { h.width = 0; },
      [](TgaHeader& h) { h.height = 0; },
      [](TgaHeader& h) { h.descriptor = 0x40; },  // interleaved rows
  };
  for (size_t i = 0; i < changes.size(); ++i) {
    Result<Image> image = decode(with(changes[i]));
    ASSERT_FALSE(image.ok()) << "change " << i;
    EXPECT_EQ(image.status().message(), kUnsupported) << "change " << i;
  }
}

TEST(ImageDecode, TgaWithColourMapOnATrueColourImageSkipsTheMap) {
  TgaHeader h;
  h.map_type = 1, h.map_length = 2, h.map_bits = 24;  // a map the true-colour pixels ignore
  Result<Image> image = decode(h.bytes() + bytes_of({9, 9, 9, 8, 8, 8}) + bytes_of({3, 2, 1}));
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(pixel(*image, 0, 0), (Rgba{1, 2, 3, 255}));
}

// ---- Mutations -------------------------------------------------------------------------------

// Flipped bytes, cuts and spliced runs of one byte, as in robustness_test.cpp, for the formats
// that file does not make (JPEG; colour-mapped, grey and 5-5-5 TGA).
std::string mutate(const std::string& input, std::mt19937& rng) {
  std::string s = input;
  for (int edits = 1 + int(rng() % 4); edits > 0 && !s.empty(); --edits) {
    size_t at = rng() % s.size();
    switch (rng() % 3) {
      case 0:
        s[at] = char(rng());
        break;
      case 1:
        s.resize(at);
        break;
      default:
        s.insert(at, std::string(1 + rng() % 8, char(rng())));
        break;
    }
  }
  return s;
}

TEST(ImageDecode, MutatedFilesDecodeOrFailCleanly) {
  const std::vector<std::string> seeds = {gradient_jpeg(false), gradient_jpeg(true),
                                          make_tga(TgaFormat::kMapped32, true, true, false).file,
                                          make_tga(TgaFormat::kGreyAlpha16, true, false, true).file,
                                          make_tga(TgaFormat::kRgb555, false, false, false).file};
  std::mt19937 rng(11);
  for (const std::string& seed : seeds) {
    for (int n = 0; n < 600; ++n) {
      Result<Image> image = decode(mutate(seed, rng));
      if (!image.ok()) {
        ASSERT_FALSE(image.status().message().empty());
        continue;
      }
      ASSERT_GT(image->width, 0);
      ASSERT_GT(image->height, 0);
      ASSERT_EQ(image->rgba.size(), size_t(image->width) * size_t(image->height) * 4);
    }
  }
}

// ---- Files -----------------------------------------------------------------------------------

TEST(ImageDecode, DevZeroAsAnImageFailsAtOnce) {
  long before = peak_rss_kib();
  Result<Image> image = load_image("/dev/zero");
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(),
            "/dev/zero: unsupported image format (PNG, TGA and JPG are supported)");
  EXPECT_LT(peak_rss_kib() - before, 16 * 1024) << "read far more than the first bytes";
}

TEST(ImageDecode, FileLargerThanTheLimitIsRefusedUnread) {
  // A sparse 600 MiB file that starts like a PNG: refused from its size, nothing read.
  fs::path path = fs::temp_directory_path() / ("softrast_big_" + std::to_string(getpid()) + ".png");
  { std::ofstream(path, std::ios::binary) << "\x89PNG\r\n\x1a\n"; }
  fs::resize_file(path, uintmax_t(600) << 20);
  long before = peak_rss_kib();
  Result<Image> image = load_image(path.string());
  long grown_kib = peak_rss_kib() - before;
  fs::remove(path);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.status().message(),
            path.string() + ": file is larger than 512 MiB, the limit for images");
  EXPECT_LT(grown_kib, 16 * 1024);
}

}  // namespace
}  // namespace softrast
