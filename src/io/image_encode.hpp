// io/image_encode.hpp: the PNG and JPEG encoders behind encode_image (softrast/image.hpp).
// Each takes a valid RGBA8 image (size checked by the caller) and returns the whole file.
#pragma once

#include <cstdint>
#include <vector>

#include "softrast/image.hpp"

namespace softrast::detail {

// PNG through libspng: zlib level 1, the SUB filter on every row, RGB when every alpha is 255.
Result<std::vector<uint8_t>> encode_png(const Image& image);

// Baseline JPEG through libjpeg-turbo at `quality` (1..100, checked by the caller); alpha dropped.
Result<std::vector<uint8_t>> encode_jpeg(const Image& image, int quality);

}  // namespace softrast::detail
