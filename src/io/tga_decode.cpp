// io/tga_decode.cpp: Truevision TGA files into RGBA8, a small strict decoder of our own.
// TGA has no signature, so its 18-byte header is validated field by field; every read is checked
// against the bytes present, and the pixel data must be there before the image is allocated.
//
// Supported: image types 1/9 (colour-mapped, 8-bit indices into a 15/16/24/32-bit map),
// 2/10 (true colour, 15/16/24/32 bits), 3/11 (grey 8 bits, or 16 bits grey + alpha), raw or RLE;
// both row orders and right-to-left rows. 15/16-bit pixels are 5-5-5 and opaque: the attribute
// bit is not used as alpha; the fourth byte of a 32-bit pixel is alpha whatever the descriptor's
// alpha-bit count says (both as in stb_image, which this replaces). Interleaved rows (descriptor
// bits 6-7, obsolete since TGA 2.0) are refused. The ID field, extension area and footer are
// skipped.

#include <cstdint>
#include <string>
#include <vector>

#include "io/image_decode.hpp"

namespace softrast::detail {
namespace {

constexpr size_t kHeaderBytes = 18;
constexpr int kMaxRlePacket = 128;  // a packet's count is 7 bits, plus one

enum Kind { kColourMapped = 1, kTrueColour = 2, kGrey = 3 };

struct Header {
  int id_bytes = 0;
  bool has_map = false;
  Kind kind = kTrueColour;
  bool rle = false;
  int map_first = 0;   // the pixel value of the first stored map entry
  int map_length = 0;  // entries stored
  int map_bits = 0;
  int width = 0;
  int height = 0;
  int bits = 0;  // per stored pixel
  bool top_down = false;
  bool right_to_left = false;

  int pixel_bytes() const { return (bits + 7) / 8; }
  int map_entry_bytes() const { return (map_bits + 7) / 8; }
  size_t map_bytes() const { return has_map ? size_t(map_length) * size_t(map_entry_bytes()) : 0; }
  int64_t pixels() const { return int64_t(width) * height; }
};

int le16(const uint8_t* p) {
  return p[0] | p[1] << 8;
}

bool valid_colour_bits(int bits) {
  return bits == 15 || bits == 16 || bits == 24 || bits == 32;
}

// The pixel depths each kind of image may have.
bool valid_pixel_bits(Kind kind, int bits) {
  switch (kind) {
    case kColourMapped:
      return bits == 8;
    case kTrueColour:
      return valid_colour_bits(bits);
    case kGrey:
      return bits == 8 || bits == 16;
  }
  return false;
}

// The colour map fields agree with the map type byte and the image type.
bool valid_map(const Header& h) {
  if (!h.has_map) return h.kind != kColourMapped && h.map_length == 0;
  return h.map_length > 0 && valid_colour_bits(h.map_bits);
}

// Reads and validates the fixed header; false if any field is impossible for a TGA.
bool parse_header(const uint8_t* data, size_t size, Header& h) {
  if (size < kHeaderBytes || data[1] > 1) return false;
  int type = data[2];
  if ((type & ~8) < kColourMapped || (type & ~8) > kGrey) return false;
  h.id_bytes = data[0];
  h.has_map = data[1] == 1;
  h.kind = Kind(type & ~8);
  h.rle = (type & 8) != 0;
  h.map_first = le16(data + 3);
  h.map_length = le16(data + 5);
  h.map_bits = data[7];
  h.width = le16(data + 12);
  h.height = le16(data + 14);
  h.bits = data[16];
  h.right_to_left = (data[17] & 0x10) != 0;
  h.top_down = (data[17] & 0x20) != 0;
  bool interleaved = (data[17] & 0xc0) != 0;
  return !interleaved && h.width > 0 && h.height > 0 && valid_pixel_bits(h.kind, h.bits) &&
         valid_map(h);
}

// The fewest bytes of pixel data that can describe the image: all of it stored raw, or for RLE
// one packet per 128 pixels, each a count byte and one pixel.
int64_t least_pixel_bytes(const Header& h) {
  if (!h.rle) return h.pixels() * h.pixel_bytes();
  return (h.pixels() + kMaxRlePacket - 1) / kMaxRlePacket * (1 + h.pixel_bytes());
}

uint8_t expand5(int v) {
  return uint8_t(v << 3 | v >> 2);
}

// A stored true-colour value (BGR(A) byte order, or 5-5-5 little-endian) as RGBA.
void colour_to_rgba(const uint8_t* in, int bits, uint8_t* out) {
  if (bits == 15 || bits == 16) {
    int v = le16(in);
    out[0] = expand5(v >> 10 & 31), out[1] = expand5(v >> 5 & 31), out[2] = expand5(v & 31);
    out[3] = 255;
    return;
  }
  out[0] = in[2], out[1] = in[1], out[2] = in[0];
  out[3] = bits == 32 ? in[3] : 255;
}

// How stored pixels become RGBA: the header's kind and depth, and the map as RGBA entries.
struct PixelFormat {
  const Header& header;
  std::vector<uint8_t> map;  // map_length RGBA entries

  // False only for a colour-map index outside the stored entries.
  bool to_rgba(const uint8_t* in, uint8_t* out) const {
    switch (header.kind) {
      case kTrueColour:
        colour_to_rgba(in, header.bits, out);
        return true;
      case kGrey:
        out[0] = out[1] = out[2] = in[0];
        out[3] = header.bits == 16 ? in[1] : 255;
        return true;
      case kColourMapped:
        return map_entry(in[0], out);
    }
    return false;
  }

  bool map_entry(int value, uint8_t* out) const {
    int entry = value - header.map_first;
    if (entry < 0 || entry >= header.map_length) return false;
    for (int c = 0; c < 4; ++c) out[c] = map[size_t(entry) * 4 + size_t(c)];
    return true;
  }
};

// The colour map converted to RGBA; the caller has checked that it is all present.
std::vector<uint8_t> read_map(const Header& h, const uint8_t* stored) {
  std::vector<uint8_t> map(size_t(h.map_length) * 4);
  for (int i = 0; i < h.map_length; ++i) {
    colour_to_rgba(stored + size_t(i) * size_t(h.map_entry_bytes()), h.map_bits,
                   &map[size_t(i) * 4]);
  }
  return map;
}

// Destinations of the stored pixels in file order: rows bottom-up unless top_down, each row left
// to right unless right_to_left; the image itself is top row first. The decoder asks for at most
// width * height destinations: it refuses packets that run past the image.
class Placer {
 public:
  Placer(Image& image, const Header& h) : image_(image), h_(h) {}
  // Row and column are counted, not divided out of a pixel index: a division per pixel was the
  // larger part of decoding a 1024x1024 texture.
  uint8_t* next() {
    int x = h_.right_to_left ? h_.width - 1 - column_ : column_;
    int y = h_.top_down ? row_ : h_.height - 1 - row_;
    if (++column_ == h_.width) {
      column_ = 0;
      ++row_;
    }
    return image_.pixel(x, y);
  }
  // For rows stored left to right: the next min(count, rest of the row) destinations, which are
  // consecutive in the image; `n` says how many.
  uint8_t* row_run(int64_t count, int& n) {
    n = int(std::min<int64_t>(count, h_.width - column_));
    uint8_t* first = image_.pixel(column_, h_.top_down ? row_ : h_.height - 1 - row_);
    column_ += n;
    if (column_ == h_.width) {
      column_ = 0;
      ++row_;
    }
    return first;
  }

 private:
  Image& image_;
  const Header& h_;
  int row_ = 0, column_ = 0;
};

// Reads pixel data from [at, end): every read checked against end.
class Decoder {
 public:
  Decoder(const PixelFormat& format, const uint8_t* at, const uint8_t* end, Image& image,
          const std::string& name)
      : format_(format), at_(at), end_(end), placer_(image, format.header), name_(name) {}

  Status raw() { return copy_pixels(format_.header.pixels()); }

  Status rle() {
    const int bytes = format_.header.pixel_bytes();
    for (int64_t left = format_.header.pixels(); left > 0;) {
      if (end_ - at_ < 1) return truncated();
      int packet = *at_++;
      int count = (packet & 0x7f) + 1;
      if (count > left) return image_error(name_, "corrupt TGA: an RLE packet runs past the image");
      left -= count;
      if (Status s = (packet & 0x80) ? repeat_pixel(bytes, count) : copy_pixels(count); !s.ok()) {
        return s;
      }
    }
    return {};
  }

 private:
  Status copy_pixels(int64_t count) {
    const int64_t bytes = format_.header.pixel_bytes();
    if (end_ - at_ < count * bytes) return truncated();
    const Header& h = format_.header;
    if (h.kind == kTrueColour && (h.bits == 24 || h.bits == 32) && !h.right_to_left) {
      // The usual texture: BGR(A) rows left to right, converted a row's run at a time.
      while (count > 0) {
        int n;
        uint8_t* out = placer_.row_run(count, n);
        if (h.bits == 24) {
          for (int i = 0; i < n; ++i, out += 4, at_ += 3) {
            out[0] = at_[2], out[1] = at_[1], out[2] = at_[0], out[3] = 255;
          }
        } else {
          for (int i = 0; i < n; ++i, out += 4, at_ += 4) {
            out[0] = at_[2], out[1] = at_[1], out[2] = at_[0], out[3] = at_[3];
          }
        }
        count -= n;
      }
      return {};
    }
    for (int64_t i = 0; i < count; ++i, at_ += bytes) {
      if (!format_.to_rgba(at_, placer_.next())) return bad_index();
    }
    return {};
  }

  Status repeat_pixel(int bytes, int count) {
    if (end_ - at_ < bytes) return truncated();
    uint8_t rgba[4];
    if (!format_.to_rgba(at_, rgba)) return bad_index();
    at_ += bytes;
    for (int i = 0; i < count; ++i) {
      uint8_t* out = placer_.next();
      for (int c = 0; c < 4; ++c) out[c] = rgba[c];
    }
    return {};
  }

  Status truncated() const {
    return image_error(name_, "truncated TGA: the pixel data ends early");
  }
  Status bad_index() const {
    return image_error(name_, "corrupt TGA: a pixel indexes past the colour map");
  }

  const PixelFormat& format_;
  const uint8_t* at_;
  const uint8_t* end_;
  Placer placer_;
  const std::string& name_;
};

std::string size_text(const Header& h) {
  return std::to_string(h.width) + "x" + std::to_string(h.height);
}

// Before allocating: the ID field and map are present, then at least the least pixel data the
// header implies (a forged or cut header names its missing bytes), then our size caps.
Status check_sizes(const Header& h, size_t size, const std::string& name) {
  size_t data_start = kHeaderBytes + size_t(h.id_bytes) + h.map_bytes();
  if (size < data_start) {
    return image_error(name, "truncated TGA: the header, ID and colour map need " +
                                 std::to_string(data_start) + " bytes, the file has " +
                                 std::to_string(size));
  }
  int64_t needed = least_pixel_bytes(h);
  int64_t present = int64_t(size - data_start);
  if (present < needed) {
    return image_error(name, "truncated TGA: " + size_text(h) + " pixels need " +
                                 (h.rle ? "at least " : "") + std::to_string(needed) +
                                 " bytes of pixel data, the file has " + std::to_string(present) +
                                 " (" + std::to_string(needed - present) + " missing)");
  }
  return check_image_size(name, h.width, h.height);
}

}  // namespace

bool is_tga(const uint8_t* data, size_t size) {
  Header ignored;
  return parse_header(data, size, ignored);
}

Result<Image> decode_tga(const uint8_t* data, size_t size, const std::string& name) {
  Header h;
  if (!parse_header(data, size, h)) return image_error(name, "not a valid TGA header");
  if (Status s = check_sizes(h, size, name); !s.ok()) return s;
  const uint8_t* map_start = data + kHeaderBytes + h.id_bytes;
  PixelFormat format{h, h.kind == kColourMapped ? read_map(h, map_start) : std::vector<uint8_t>()};
  Image image(h.width, h.height);
  Decoder decoder(format, map_start + h.map_bytes(), data + size, image, name);
  if (Status s = h.rle ? decoder.rle() : decoder.raw(); !s.ok()) return s;
  return image;
}

}  // namespace softrast::detail
