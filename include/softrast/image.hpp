// softrast/image.hpp: RGBA8 images in memory and their files (PNG, TGA, JPG in and out).
// Row 0 is the top row of the picture, as in the files; nothing here flips.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "softrast/status.hpp"

namespace softrast {

// Largest width or height accepted anywhere (images, textures, framebuffers). 16384 keeps every
// window coordinate inside the fixed-point range with a wide guard band (see raster/fixed_point).
inline constexpr int kMaxImageSize = 16384;

// Largest pixel count a decoded file may have: 64 Mi pixels, 256 MiB as RGBA8. It admits 8192x8192
// and 16384x4096 while keeping one texture load (the Image, then the Texture's copy of it) near
// 512 MiB. kMaxImageSize alone would allow 16384x16384, 1 GiB per copy, which a few hundred bytes
// of compressed data can declare; images the library makes itself (framebuffers) are not capped.
inline constexpr int64_t kMaxImagePixels = int64_t(1) << 26;

// Largest file load_image reads (and buffer decode_image takes): 512 MiB, twice the largest RGBA8
// image within kMaxImagePixels stored raw, so any sensible encoding of an accepted image fits.
inline constexpr int64_t kMaxImageFileBytes = int64_t(512) << 20;

// An 8-bit RGBA image, rows top to bottom, 4 bytes per pixel, no padding.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(size_t(w) * size_t(h) * 4, 0) {}
  uint8_t* pixel(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
  const uint8_t* pixel(int x, int y) const {
    return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
  }
};

// Reads a PNG, TGA (bottom-up or top-down rows) or JPG file into RGBA8, top row first. The format
// is told by the file's contents, not its name; any other format is an error. Errors name the
// file: missing, unreadable, larger than kMaxImageFileBytes, not one of the three formats,
// truncated or corrupt (never a partly invented image), or wider or taller than kMaxImageSize or
// with more than kMaxImagePixels pixels (refused from the header, before any pixel is allocated).
Result<Image> load_image(const std::string& path);

// Decodes an image held in memory (same formats and limits as load_image); `name` is used in
// messages.
Result<Image> decode_image(const uint8_t* data, size_t size, const std::string& name);

// The file formats save_image and encode_image write.
enum class ImageFormat { kPng, kTga, kJpeg };

// JPEG quality when none is given (libjpeg's 1..100 scale): no visible blocks on renders.
inline constexpr int kDefaultJpegQuality = 90;

// The format named by the extension of `path`: .png, .tga, .jpg or .jpeg, in any case; nullopt for
// anything else.
std::optional<ImageFormat> image_format_of(const std::string& path);

// The whole file for `image` in `format`. PNG is lossless (zlib level 1, the SUB filter; RGB when
// every alpha is 255) and reads back through load_image bit for bit; TGA is lossless; JPEG drops
// alpha and is lossy at `jpeg_quality` (1..100). Errors: an image whose size is outside
// 1..kMaxImageSize or whose buffer does not match it, a quality outside 1..100, an encoder failure.
Result<std::vector<uint8_t>> encode_image(const Image& image, ImageFormat format,
                                          int jpeg_quality = kDefaultJpegQuality);

// Writes `image` as PNG, TGA or JPEG, chosen by the extension of `path` (image_format_of).
// The file appears complete or not at all: the data goes to a temporary file in the same folder
// that is renamed over `path` only after a successful write.
Status save_image(const std::string& path, const Image& image,
                  int jpeg_quality = kDefaultJpegQuality);

// Removes the temporary file of a save_image in progress, if there is one. Async-signal-safe (it
// reads a fixed buffer and calls unlink), for the SIGINT/SIGTERM handler of a program that then
// exits: interrupted while writing, it leaves neither its output nor a `*.tmp.*` file behind.
// Covers one save_image at a time (with several threads saving at once, the first).
void remove_pending_temporary_file() noexcept;

}  // namespace softrast
