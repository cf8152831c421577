// io/image_encode.cpp: RGBA8 images into PNG (zlib) and JPEG (libjpeg-turbo) bytes.
//
// PNG is written for speed: a rendered 1920x1080 frame is 8 MB of pixels, and stb_image_write
// (zlib level 8 by its own deflate, all five filters tried on every row) took longer than the
// render. Here:
//  - every row uses the SUB filter: one subtraction per byte and no trial of the other filters;
//    on rendered images (flat backgrounds, smooth shading) it leaves long runs of small values;
//  - zlib compresses at level 1 with the Z_RLE strategy (matches only at distance one pixel
//    byte, i.e. runs): on SUB-filtered rendered rows that is both faster and smaller than level 1's
//    general matching (diablo3_pose at 1920x1080: 355 KB against 422 KB, about 1 ms less); level
//    1 had already given files about two thirds the size of stb's at a tenth of the time;
//  - the rows are compressed in strips of kStripRows rows on the library's worker threads, each a
//    raw deflate stream ended by a sync flush (byte-aligned, not final) except the last, so that
//    their concatenation is one valid zlib stream (the method of pigz); the Adler-32 checksums of
//    the strips are combined with adler32_combine. Strips depend only on the image height, so
//    the bytes are the same whatever the thread count;
//  - images whose alpha is 255 everywhere are written as RGB: a quarter less data, and reading
//    them back gives alpha 255, so the round trip is exact either way.
// libspng (our PNG decoder) can encode too, but only on one thread: 25-30 ms for this frame.
// The container is three chunks (IHDR, IDAT, IEND), each with its CRC-32 from zlib.

#include "io/image_encode.hpp"

#include <algorithm>
#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE and size_t declared first
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <zlib.h>

#include "softrast/detail/parallel.hpp"

namespace softrast::detail {
namespace {

// Rows per independently compressed strip: enough that the dictionary reset costs well under 1%
// of the size, few enough that a 1080-row frame gives 9 strips to share among threads.
constexpr int kStripRows = 128;

bool opaque(const Image& image) {
  const uint8_t* p = image.rgba.data();
  size_t n = image.rgba.size();
  uint8_t all = 0xff;
  for (size_t i = 3; i < n; i += 4) all &= p[i];
  return all == 0xff;
}

// Rows [y0, y1) as PNG scanlines: a filter byte (1, SUB) then each byte minus the byte one pixel
// to its left (0 for the first pixel), RGB or RGBA (a constant, so the loop is unrolled).
template <size_t kChannels>
void filter_rows(const Image& image, int y0, int y1, uint8_t* o) {
  for (int y = y0; y < y1; ++y) {
    const uint8_t* in = image.pixel(0, y);
    *o++ = 1;
    for (size_t c = 0; c < kChannels; ++c) *o++ = in[c];
    for (int x = 1; x < image.width; ++x, o += kChannels) {
      in += 4;
      for (size_t c = 0; c < kChannels; ++c) o[c] = uint8_t(in[c] - in[c - 4]);
    }
  }
}

struct Strip {
  std::vector<uint8_t> deflated;
  uLong adler = 0;
  uLong raw_size = 0;
  bool ok = false;
};

// Rows filtered and fed to zlib this many at a time, so the filtered bytes never exist whole.
constexpr int kFeedRows = 16;

// Compresses whole strips, one after the other, with one zlib stream and buffers reused (fresh
// memory costs page faults: a zlib state and a strip's worth of rows per strip would touch more
// memory than the output). deflateReset makes each strip exactly what a new stream would give.
class StripCompressor {
 public:
  StripCompressor(const Image& image, bool rgb) : image_(image), rgb_(rgb) {
    row_bytes_ = 1 + size_t(image.width) * (rgb ? 3 : 4);
    ok_ = deflateInit2(&z_, 1, Z_DEFLATED, -15, 8, Z_RLE) == Z_OK;
    if (ok_) out_.resize(deflateBound(&z_, uLong(row_bytes_ * kStripRows)) + 64);
    rows_.resize(row_bytes_ * kFeedRows);
  }
  ~StripCompressor() {
    if (ok_) deflateEnd(&z_);
  }
  StripCompressor(const StripCompressor&) = delete;
  StripCompressor& operator=(const StripCompressor&) = delete;

  // Rows [y0, y1) as one raw deflate stream, ended by a sync flush, or finished if `last`.
  void compress(int y0, int y1, bool last, Strip& strip) {
    if (!ok_ || deflateReset(&z_) != Z_OK) return;
    strip.adler = adler32(0L, Z_NULL, 0);
    z_.next_out = out_.data();
    z_.avail_out = uInt(out_.size());
    for (int y = y0; y < y1; y += kFeedRows) {
      int n = std::min(kFeedRows, y1 - y);
      if (rgb_) {
        filter_rows<3>(image_, y, y + n, rows_.data());
      } else {
        filter_rows<4>(image_, y, y + n, rows_.data());
      }
      auto size = uInt(row_bytes_ * size_t(n));
      strip.adler = adler32(strip.adler, rows_.data(), size);
      strip.raw_size += size;
      z_.next_in = rows_.data();
      z_.avail_in = size;
      bool end = y + n == y1;
      int code = deflate(&z_, !end ? Z_NO_FLUSH : last ? Z_FINISH : Z_SYNC_FLUSH);
      bool done = end && last ? code == Z_STREAM_END : code == Z_OK;
      if (!done || z_.avail_in != 0) return;
    }
    strip.deflated.assign(out_.data(), z_.next_out);
    strip.ok = true;
  }

 private:
  const Image& image_;
  bool rgb_;
  bool ok_ = false;
  size_t row_bytes_ = 0;
  z_stream z_{};
  std::vector<uint8_t> rows_, out_;
};

void put32(std::vector<uint8_t>& out, uint32_t v) {
  out.insert(out.end(), {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)});
}

// Appends a chunk: length, type, data, CRC-32 of type and data.
void put_chunk(std::vector<uint8_t>& out, const char* type, const uint8_t* data, size_t size) {
  put32(out, uint32_t(size));
  size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  if (size > 0) out.insert(out.end(), data, data + size);
  put32(out, uint32_t(crc32(0L, out.data() + type_at, uInt(size + 4))));
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
  bool rgb = opaque(image);
  int strips = (image.height + kStripRows - 1) / kStripRows;
  std::vector<Strip> parts(static_cast<size_t>(strips));
  // Each worker takes a run of consecutive strips; the bytes depend only on the strips.
  int workers = std::clamp(hardware_threads(), 1, strips);
  parallel_for(size_t(workers), workers, [&](size_t w) {
    StripCompressor compressor(image, rgb);
    size_t first = w * size_t(strips) / size_t(workers);
    size_t end = (w + 1) * size_t(strips) / size_t(workers);
    for (size_t i = first; i < end; ++i) {
      int y0 = int(i) * kStripRows;
      int y1 = std::min(image.height, y0 + kStripRows);
      compressor.compress(y0, y1, int(i) == strips - 1, parts[i]);
    }
  });
  // The zlib stream: header (deflate, 32 KiB window, "fastest" level), strips, Adler-32.
  std::vector<uint8_t> idat = {0x78, 0x01};
  uLong adler = adler32(0L, Z_NULL, 0);
  for (const Strip& p : parts) {
    if (!p.ok) return Status::error("cannot encode PNG: zlib failed (out of memory?)");
    idat.insert(idat.end(), p.deflated.begin(), p.deflated.end());
    adler = adler32_combine(adler, p.adler, z_off_t(p.raw_size));
  }
  parts = {};
  put32(idat, uint32_t(adler));
  uint8_t ihdr[13] = {};
  ihdr[0] = uint8_t(image.width >> 24);
  ihdr[1] = uint8_t(image.width >> 16);
  ihdr[2] = uint8_t(image.width >> 8);
  ihdr[3] = uint8_t(image.width);
  ihdr[4] = uint8_t(image.height >> 24);
  ihdr[5] = uint8_t(image.height >> 16);
  ihdr[6] = uint8_t(image.height >> 8);
  ihdr[7] = uint8_t(image.height);
  ihdr[8] = 8;            // bits per channel
  ihdr[9] = rgb ? 2 : 6;  // truecolour, with alpha or not
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  png.reserve(idat.size() + 64);
  put_chunk(png, "IHDR", ihdr, sizeof ihdr);
  put_chunk(png, "IDAT", idat.data(), idat.size());
  put_chunk(png, "IEND", nullptr, 0);
  return png;
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
