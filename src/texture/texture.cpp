// texture/texture.cpp: building textures from images (the samplers live in texture.hpp).
// The only work here is the flip from file order (top row first) to texel order (bottom first).

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "softrast/texture.hpp"

namespace softrast {

Texture Texture::from_image(const Image& image) {
  size_t row_bytes = size_t(image.width) * 4;
  if (image.width < 0 || image.height < 0 ||
      image.rgba.size() != row_bytes * size_t(image.height)) {
    // A contract violation, not a recoverable error: every Image built by the library is valid.
    std::fprintf(stderr, "Texture::from_image: image %dx%d holds %zu bytes, expected %zu\n",
                 image.width, image.height, image.rgba.size(), row_bytes * size_t(image.height));
    std::abort();
  }
  if (image.rgba.empty()) return Texture();  // a 0 x n image: samples as opaque white
  Texture texture;
  texture.width_ = image.width;
  texture.height_ = image.height;
  texture.texels_.resize(image.rgba.size());
  for (int j = 0; j < image.height; ++j) {
    const uint8_t* source = image.pixel(0, image.height - 1 - j);
    std::copy(source, source + row_bytes, texture.texels_.begin() + row_bytes * size_t(j));
  }
  return texture;
}

}  // namespace softrast
