// texture/texture.cpp: building textures from images (the samplers live in texture.hpp): the
// flip from file order (top row first) to texel order (bottom first), and the mip chain.

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
  texture.levels_ = mip_levels(image.width, image.height);
  const MipLevel& last = texture.levels_.back();
  texture.texels_.resize((last.offset + size_t(last.width) * size_t(last.height)) * 4);
  for (int j = 0; j < image.height; ++j) {
    const uint8_t* source = image.pixel(0, image.height - 1 - j);
    std::copy(source, source + row_bytes, texture.texels_.begin() + row_bytes * size_t(j));
  }
  for (size_t k = 1; k < texture.levels_.size(); ++k) {
    texture.downsample(texture.levels_[k - 1], texture.levels_[k]);
  }
  return texture;
}

std::vector<MipLevel> Texture::mip_levels(int width, int height) {
  std::vector<MipLevel> levels{{width, height, 0}};
  while (levels.back().width > 1 || levels.back().height > 1) {
    const MipLevel& l = levels.back();
    levels.push_back({std::max(l.width / 2, 1), std::max(l.height / 2, 1),
                      l.offset + size_t(l.width) * size_t(l.height)});
  }
  return levels;
}

// Level `to` from level `from` by a box filter: each texel averages the 2x2 texels it covers
// (rounded to nearest). For an odd size the last row or column of `from` is not reached, as
// with OpenGL's usual glGenerateMipmap; a side of 1 averages the texel with itself.
void Texture::downsample(const MipLevel& from, const MipLevel& to) {
  for (int j = 0; j < to.height; ++j) {
    int j0 = std::min(2 * j, from.height - 1), j1 = std::min(2 * j + 1, from.height - 1);
    for (int i = 0; i < to.width; ++i) {
      int i0 = std::min(2 * i, from.width - 1), i1 = std::min(2 * i + 1, from.width - 1);
      const uint8_t* a = &texels_[(from.offset + size_t(j0) * from.width + i0) * 4];
      const uint8_t* b = &texels_[(from.offset + size_t(j0) * from.width + i1) * 4];
      const uint8_t* c = &texels_[(from.offset + size_t(j1) * from.width + i0) * 4];
      const uint8_t* d = &texels_[(from.offset + size_t(j1) * from.width + i1) * 4];
      uint8_t* out = &texels_[(to.offset + size_t(j) * to.width + i) * 4];
      for (int ch = 0; ch < 4; ++ch) out[ch] = uint8_t((a[ch] + b[ch] + c[ch] + d[ch] + 2) / 4);
    }
  }
}

}  // namespace softrast
