// io/image_encode.cpp: RGBA8 images into PNG (libspng), JPEG (libjpeg-turbo) and TGA bytes.
//
// PNG is written for speed: a rendered 1920x1080 frame is 8 MB of pixels, and zlib's default
// level with a per-row choice among all five filters took longer than rendering it. Here zlib
// runs at level 1 (Z_RLE would be faster still but loses 2-3x in size on textured renders) and
// every row uses the SUB filter: one subtraction per byte, no trial of the other filters, and on
// rendered images (flat backgrounds, smooth shading) it leaves long runs of zeros that level 1
// compresses well. Images whose alpha is 255 everywhere are written as RGB, a quarter less data to
// filter and compress; reading them back gives alpha 255, so the round trip is exact either way.

#include "io/image_encode.hpp"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE and size_t declared first
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <spng.h>
#include <zlib.h>

namespace softrast::detail {
namespace {

struct SpngDeleter {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};

bool opaque(const Image& image) {
  const uint8_t* p = image.rgba.data();
  size_t n = image.rgba.size();
  uint8_t all = 0xff;
  for (size_t i = 3; i < n; i += 4) all &= p[i];
  return all == 0xff;
}

std::vector<uint8_t> rgb_of(const Image& image) {
  size_t pixels = size_t(image.width) * size_t(image.height);
  std::vector<uint8_t> rgb(pixels * 3);
  const uint8_t* in = image.rgba.data();
  uint8_t* out = rgb.data();
  for (size_t i = 0; i < pixels; ++i, in += 4, out += 3) {
    out[0] = in[0];
    out[1] = in[1];
    out[2] = in[2];
  }
  return rgb;
}

Status png_failure(int code) {
  return Status::error(std::string("cannot encode PNG: ") + spng_strerror(code));
}

// libjpeg's error exit must not return: it jumps back to encode_jpeg with the message.
struct JpegErrors {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
};

[[noreturn]] void jpeg_jump_out(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  cinfo->err->format_message(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

}  // namespace

Result<std::vector<uint8_t>> encode_png(const Image& image) {
  std::unique_ptr<spng_ctx, SpngDeleter> ctx(spng_ctx_new(SPNG_CTX_ENCODER));
  if (!ctx) return Status::error("cannot encode PNG: out of memory");
  bool rgb = opaque(image);
  spng_ihdr ihdr{};
  ihdr.width = uint32_t(image.width);
  ihdr.height = uint32_t(image.height);
  ihdr.bit_depth = 8;
  ihdr.color_type = rgb ? SPNG_COLOR_TYPE_TRUECOLOR : SPNG_COLOR_TYPE_TRUECOLOR_ALPHA;
  int code = spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1);
  if (code == 0) code = spng_set_ihdr(ctx.get(), &ihdr);
  if (code == 0) code = spng_set_option(ctx.get(), SPNG_IMG_COMPRESSION_LEVEL, 1);
  if (code == 0) code = spng_set_option(ctx.get(), SPNG_FILTER_CHOICE, SPNG_FILTER_CHOICE_SUB);
  if (code != 0) return png_failure(code);
  std::vector<uint8_t> rgb_pixels;
  const uint8_t* pixels = image.rgba.data();
  size_t size = image.rgba.size();
  if (rgb) {
    rgb_pixels = rgb_of(image);
    pixels = rgb_pixels.data();
    size = rgb_pixels.size();
  }
  code = spng_encode_image(ctx.get(), pixels, size, SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  if (code != 0) return png_failure(code);
  size_t length = 0;
  int error = 0;
  std::unique_ptr<void, decltype(&std::free)> buffer(spng_get_png_buffer(ctx.get(), &length, &error),
                                                     &std::free);
  if (!buffer) return png_failure(error);
  const auto* bytes = static_cast<const uint8_t*>(buffer.get());
  return std::vector<uint8_t>(bytes, bytes + length);
}

Result<std::vector<uint8_t>> encode_jpeg(const Image& image, int quality) {
  jpeg_compress_struct cinfo{};
  JpegErrors errors{};
  cinfo.err = jpeg_std_error(&errors.mgr);
  errors.mgr.error_exit = jpeg_jump_out;
  unsigned char* buffer = nullptr;
  unsigned long length = 0;
  // Everything the jump can skip is set up before setjmp; nothing with a destructor lives between.
  if (setjmp(errors.jump) != 0) {
    jpeg_destroy_compress(&cinfo);
    std::free(buffer);
    return Status::error(std::string("cannot encode JPEG: ") + errors.message);
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &buffer, &length);
  cinfo.image_width = JDIMENSION(image.width);
  cinfo.image_height = JDIMENSION(image.height);
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_EXT_RGBA;  // libjpeg-turbo drops the alpha byte
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, quality, TRUE);
  // At high quality, full-resolution colour (4:4:4): renders have sharp coloured edges that 2x2
  // chroma subsampling smears; below 90 the smaller 4:2:0 file is what was asked for.
  if (quality >= 90) {
    for (int c = 0; c < cinfo.num_components; ++c) {
      cinfo.comp_info[c].h_samp_factor = 1;
      cinfo.comp_info[c].v_samp_factor = 1;
    }
  }
  jpeg_start_compress(&cinfo, TRUE);
  size_t stride = size_t(image.width) * 4;
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(image.rgba.data() + cinfo.next_scanline * stride);
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  std::vector<uint8_t> bytes(buffer, buffer + length);
  jpeg_destroy_compress(&cinfo);
  std::free(buffer);
  return bytes;
}

}  // namespace softrast::detail
