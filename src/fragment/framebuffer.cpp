// fragment/framebuffer.cpp
#include "softrast/framebuffer.hpp"

#include <algorithm>
#include <cstring>

#include "softrast/detail/parallel.hpp"

namespace softrast {

Framebuffer::Framebuffer(int width, int height)
    : width_(width),
      height_(height),
      color_(size_t(width) * size_t(height)),
      depth_(size_t(width) * size_t(height)) {
  clear();
}

Result<Framebuffer> Framebuffer::create(int width, int height) {
  if (width < 1 || height < 1 || width > kMaxImageSize || height > kMaxImageSize) {
    return Status::error("image size " + std::to_string(width) + "x" + std::to_string(height) +
                         " is outside 1x1 .. " + std::to_string(kMaxImageSize) + "x" +
                         std::to_string(kMaxImageSize));
  }
  return Framebuffer(width, height);
}

void Framebuffer::clear_color(glm::vec4 color) {
  multisample_.valid = false;
  std::fill(color_.begin(), color_.end(), pack_rgba8(color));
}

void Framebuffer::clear_depth(float depth) {
  multisample_.valid = false;
  std::fill(depth_.begin(), depth_.end(), depth);
}

void Framebuffer::clear(glm::vec4 color, float depth, int threads) {
  const uint32_t packed = pack_rgba8(color);
  // Bands of about 256 KiB of both buffers: enough work per index, and a band's colour and
  // depth are written by the same thread. Samples kept for multisampled draws are cleared with
  // their pixels (and stay valid), so that a multisampled frame does not copy them in again.
  const size_t pixels = color_.size();
  const size_t band = std::max<size_t>(size_t(32) << 10, size_t(width_));
  const size_t bands = (pixels + band - 1) / band;
  const size_t per = size_t(std::max(1, multisample_.count));
  const bool samples = multisample_.count > 1 && multisample_.color.size() == pixels * per &&
                       multisample_.depth.size() == pixels * per;
  multisample_.valid = samples;
  int n = threads > 0 ? threads : detail::hardware_threads();
  detail::parallel_for(bands, n, [&](size_t b) {
    size_t begin = b * band, end = std::min(pixels, begin + band);
    std::fill(color_.begin() + ptrdiff_t(begin), color_.begin() + ptrdiff_t(end), packed);
    std::fill(depth_.begin() + ptrdiff_t(begin), depth_.begin() + ptrdiff_t(end), depth);
    if (!samples) return;
    auto& ms = multisample_;
    std::fill(ms.color.begin() + ptrdiff_t(begin * per), ms.color.begin() + ptrdiff_t(end * per),
              packed);
    std::fill(ms.depth.begin() + ptrdiff_t(begin * per), ms.depth.begin() + ptrdiff_t(end * per),
              depth);
  });
}

Image Framebuffer::to_image() const {
  Image image(width_, height_);
  for (size_t i = 0; i < color_.size(); ++i) {
    uint32_t p = color_[i];
    uint8_t* out = &image.rgba[i * 4];
    out[0] = uint8_t(p), out[1] = uint8_t(p >> 8), out[2] = uint8_t(p >> 16),
    out[3] = uint8_t(p >> 24);
  }
  return image;
}

}  // namespace softrast
