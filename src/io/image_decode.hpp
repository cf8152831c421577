// io/image_decode.hpp: the three decoders behind decode_image (PNG, JPEG, TGA) and what they share.
// Each takes the whole file in memory, refuses oversized images from the header alone and
// reports truncated or corrupt data as an error instead of filling in pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "softrast/image.hpp"

namespace softrast::detail {

// "name: reason", the one-line form of every image error.
Status image_error(const std::string& name, const std::string& reason);

// Ok if width x height is within kMaxImageSize each way and kMaxImagePixels in all; otherwise an
// error naming the size. Decoders call it before allocating the image.
Status check_image_size(const std::string& name, int64_t width, int64_t height);

// True if the bytes start like a PNG or JPEG (their signatures, or a prefix of one if the file is
// shorter) or hold a strictly valid TGA header; the TGA test is the only evidence for that format.
bool is_png(const uint8_t* data, size_t size);
bool is_jpeg(const uint8_t* data, size_t size);
bool is_tga(const uint8_t* data, size_t size);

// Decoders; `name` goes into messages. Each expects its format's test above to have passed.
Result<Image> decode_png(const uint8_t* data, size_t size, const std::string& name);
Result<Image> decode_jpeg(const uint8_t* data, size_t size, const std::string& name);
Result<Image> decode_tga(const uint8_t* data, size_t size, const std::string& name);

}  // namespace softrast::detail
