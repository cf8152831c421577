// io/png_decode.cpp: PNG files into RGBA8 through libspng, every limit set before decoding.
// spng is fuzzed upstream, checks CRCs and never writes past the buffer it is given; what it
// cannot know is how large an image we are willing to hold, so that is checked here first.

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>

#include <spng.h>

#include "io/image_decode.hpp"

namespace softrast::detail {
namespace {

// Ancillary chunks (text, ICC profiles, EXIF, unknown chunks) are kept by spng in memory; these
// bound one chunk and all of them together. IDAT is streamed, never cached, so neither limit
// touches image data. 16 MiB is far above any real profile or comment.
constexpr size_t kPngChunkLimit = size_t(16) << 20;
constexpr size_t kPngCacheLimit = size_t(64) << 20;

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

struct ContextDeleter {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};
using Context = std::unique_ptr<spng_ctx, ContextDeleter>;

// spng reports running out of input as "end of stream" (SPNG_IO_EOF) or "end of file".
Status png_error(const std::string& name, int code) {
  if (code == SPNG_IO_EOF || code == SPNG_EOF) {
    return image_error(name, "truncated PNG: the file ends before its IEND chunk");
  }
  return image_error(name, std::string("corrupt PNG: ") + spng_strerror(code));
}

uint32_t big_endian32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// spng refuses sizes above its user limits with a generic code; this says which size it was,
// read from the IHDR fields (bytes 16..23, which spng has just parsed to refuse them).
Status size_refusal(const uint8_t* data, size_t size, const std::string& name, int code) {
  if (size < 24) return png_error(name, code);
  Status s = check_image_size(name, big_endian32(data + 16), big_endian32(data + 20));
  return s.ok() ? png_error(name, code) : s;
}

// True if the chunk sequence reaches a complete IEND chunk (length, type and CRC) inside the
// file. spng stops at IEND's type and never reads its CRC, so without this a file cut in its last
// four bytes would pass; after a successful decode every earlier chunk is known to be whole.
bool has_complete_iend(const uint8_t* data, size_t size) {
  size_t at = sizeof kPngSignature;
  while (size - at >= 12) {
    size_t length = big_endian32(data + at);
    if (std::memcmp(data + at + 4, "IEND", 4) == 0) return true;
    if (length > size - at - 12) return false;
    at += 12 + length;
  }
  return false;
}

// A context reading `data` with our limits. Limits are set before the buffer so that even the
// header is parsed under them.
Context open_png(const uint8_t* data, size_t size) {
  Context ctx(spng_ctx_new(0));
  if (!ctx) return ctx;
  if (spng_set_image_limits(ctx.get(), kMaxImageSize, kMaxImageSize) != 0 ||
      spng_set_chunk_limits(ctx.get(), kPngChunkLimit, kPngCacheLimit) != 0 ||
      spng_set_png_buffer(ctx.get(), data, size) != 0) {
    ctx.reset();
  }
  return ctx;
}

// Header checks: the size against our caps, and spng's RGBA8 buffer size agreeing with it.
Status check_header(spng_ctx* ctx, const uint8_t* data, size_t size, const std::string& name) {
  spng_ihdr ihdr{};
  if (int code = spng_get_ihdr(ctx, &ihdr); code != 0) {
    if (code == SPNG_EUSER_WIDTH || code == SPNG_EUSER_HEIGHT) {
      return size_refusal(data, size, name, code);
    }
    return png_error(name, code);
  }
  if (Status s = check_image_size(name, ihdr.width, ihdr.height); !s.ok()) return s;
  size_t bytes = 0;
  if (int code = spng_decoded_image_size(ctx, SPNG_FMT_RGBA8, &bytes); code != 0) {
    return png_error(name, code);
  }
  if (bytes != size_t(ihdr.width) * ihdr.height * 4) {
    return image_error(name, "PNG decoded size disagrees with its header");
  }
  return {};
}

}  // namespace

bool is_png(const uint8_t* data, size_t size) {
  return size > 0 && std::memcmp(data, kPngSignature, std::min(size, sizeof kPngSignature)) == 0;
}

Result<Image> decode_png(const uint8_t* data, size_t size, const std::string& name) {
  Context ctx = open_png(data, size);
  if (!ctx) return image_error(name, "cannot start the PNG decoder (out of memory)");
  if (Status s = check_header(ctx.get(), data, size, name); !s.ok()) return s;
  spng_ihdr ihdr{};
  spng_get_ihdr(ctx.get(), &ihdr);  // cannot fail after check_header
  Image image(int(ihdr.width), int(ihdr.height));
  // TRNS turns a palette's or a grey/RGB key colour's transparency into alpha; 16-bit channels
  // are scaled to 8 bits; no gamma correction (textures are used as stored).
  if (int code = spng_decode_image(ctx.get(), image.rgba.data(), image.rgba.size(), SPNG_FMT_RGBA8,
                                   SPNG_DECODE_TRNS);
      code != 0) {
    return png_error(name, code);
  }
  // Read on to IEND: a file cut after its image data is still a cut file.
  if (int code = spng_decode_chunks(ctx.get()); code != 0) return png_error(name, code);
  if (!has_complete_iend(data, size)) return png_error(name, SPNG_EOF);
  return image;
}

}  // namespace softrast::detail
