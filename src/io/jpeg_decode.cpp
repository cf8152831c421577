// io/jpeg_decode.cpp: JPEG files into RGBA8 through libjpeg-turbo.
// libjpeg reports errors by calling a function that must not return; ours longjmps back to the
// call that started the work and the message becomes a Status. Warnings that mean pixels were
// lost or made up (a truncated file is filled with grey) are errors too.

#include <algorithm>
#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE and size_t declared first
#include <cstring>
#include <string>
#include <vector>

#include <jpeglib.h>

#include <jerror.h>  // after jpeglib.h: its arithmetic-coding messages depend on jconfig.h

#include "io/image_decode.hpp"

namespace softrast::detail {
namespace {

// libjpeg's working memory (progressive files keep every coefficient of the image: about 6 bytes
// per pixel without chroma subsampling, so 384 MiB at kMaxImagePixels). With no backing store,
// going over is an error rather than a larger allocation.
constexpr long kJpegMemoryLimit = 512L << 20;

// The start-of-image marker and the 0xff that begins the next marker.
constexpr uint8_t kJpegSignature[3] = {0xff, 0xd8, 0xff};

// The error manager libjpeg calls; `mgr` comes first so that cinfo->err points at the whole.
struct JpegErrors {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
};

[[noreturn]] void jump_out(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  cinfo->err->format_message(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

// Warnings after which the decoder substitutes data: the end of the file (grey fill), entropy
// data that does not decode, markers in the middle of a scan, an impossible scan sequence.
// Warnings about metadata or stray bytes between segments leave the pixels intact.
bool loses_pixels(int code) {
  switch (code) {
    case JWRN_JPEG_EOF:
    case JWRN_HIT_MARKER:
    case JWRN_HUFF_BAD_CODE:
    case JWRN_ARITH_BAD_CODE:
    case JWRN_MUST_RESYNC:
    case JWRN_NOT_SEQUENTIAL:
    case JWRN_BOGUS_PROGRESSION:
      return true;
    default:
      return false;
  }
}

// libjpeg's emit_message: level -1 is a warning, higher levels are traces. Nothing is printed.
void on_message(j_common_ptr cinfo, int level) {
  if (level >= 0) return;
  ++cinfo->err->num_warnings;
  if (loses_pixels(cinfo->err->msg_code)) jump_out(cinfo);
}

// A decompressor that reports through JpegErrors and is destroyed with its owner.
struct Decompressor {
  jpeg_decompress_struct cinfo{};
  JpegErrors errors{};

  Decompressor() {
    cinfo.err = jpeg_std_error(&errors.mgr);
    errors.mgr.error_exit = jump_out;
    errors.mgr.emit_message = on_message;
  }
  ~Decompressor() { jpeg_destroy_decompress(&cinfo); }  // safe even if creation failed
  Decompressor(const Decompressor&) = delete;
  Decompressor& operator=(const Decompressor&) = delete;
};

// Runs `step`, which calls into libjpeg, with the jump buffer armed: false, with the library's
// message in d.errors, if libjpeg gave up. longjmp skips destructors, so `step` must own no
// object that has one; everything it touches lives in the caller.
template <class Step>
bool guarded(Decompressor& d, Step&& step) {
  if (setjmp(d.errors.jump) != 0) return false;
  step();
  return true;
}

Status jpeg_error(const std::string& name, const Decompressor& d) {
  return image_error(name, std::string("cannot decode JPEG: ") + d.errors.message);
}

// Everything decided from the header: size limits, a colour space we can turn into RGBA.
Status check_header(const jpeg_decompress_struct& cinfo, const std::string& name) {
  if (Status s = check_image_size(name, cinfo.image_width, cinfo.image_height); !s.ok()) return s;
  if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
    return image_error(name, "CMYK JPEG is not supported (save it as RGB)");
  }
  return {};
}

// Rows of `image` as libjpeg's output pointers.
std::vector<JSAMPROW> row_pointers(Image& image) {
  std::vector<JSAMPROW> rows(size_t(image.height));
  for (int y = 0; y < image.height; ++y) rows[size_t(y)] = image.pixel(0, y);
  return rows;
}

}  // namespace

bool is_jpeg(const uint8_t* data, size_t size) {
  return size > 0 && std::memcmp(data, kJpegSignature, std::min(size, sizeof kJpegSignature)) == 0;
}

Result<Image> decode_jpeg(const uint8_t* data, size_t size, const std::string& name) {
  Decompressor d;
  jpeg_decompress_struct* cinfo = &d.cinfo;
  bool read = guarded(d, [&] {
    jpeg_create_decompress(cinfo);
    jpeg_mem_src(cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(cinfo, TRUE);  // TRUE: a tables-only file is an error
  });
  if (!read) return jpeg_error(name, d);
  if (Status s = check_header(*cinfo, name); !s.ok()) return s;
  cinfo->out_color_space = JCS_EXT_RGBA;  // grey, YCbCr and RGB expand to RGBA, alpha 255
  cinfo->mem->max_memory_to_use = kJpegMemoryLimit;
  if (!guarded(d, [&] { jpeg_start_decompress(cinfo); })) return jpeg_error(name, d);
  if (cinfo->output_width != cinfo->image_width || cinfo->output_height != cinfo->image_height ||
      cinfo->output_components != 4) {
    return image_error(name, "JPEG decoder produced an unexpected layout");
  }
  Image image(int(cinfo->image_width), int(cinfo->image_height));
  std::vector<JSAMPROW> rows = row_pointers(image);
  JSAMPROW* row_array = rows.data();
  bool decoded = guarded(d, [&] {
    while (cinfo->output_scanline < cinfo->output_height) {
      jpeg_read_scanlines(cinfo, row_array + cinfo->output_scanline,
                          cinfo->output_height - cinfo->output_scanline);
    }
    jpeg_finish_decompress(cinfo);  // reads on to the end-of-image marker
  });
  if (!decoded) return jpeg_error(name, d);
  return image;
}

}  // namespace softrast::detail
