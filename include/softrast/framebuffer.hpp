// softrast/framebuffer.hpp: the render target: RGBA8 colour and float32 depth.
// Row 0 is the top row (window y grows downwards), the same as Image.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "softrast/image.hpp"
#include "softrast/status.hpp"

namespace softrast {

class Framebuffer {
 public:
  // Precondition: 1 <= width, height <= kMaxImageSize (see create() for checked construction).
  Framebuffer(int width, int height);
  // Checked construction: an error for sizes outside [1, kMaxImageSize].
  static Result<Framebuffer> create(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }

  // Clears colour (floats clamped to [0, 1]) and depth; the defaults are CONVENTIONS.md's.
  void clear_color(glm::vec4 color = {0.1f, 0.1f, 0.1f, 1.0f});
  void clear_depth(float depth = 1.0f);
  void clear() {
    clear_color();
    clear_depth();
  }
  // Both at once, in bands of rows spread over `threads` threads (0: every core), each band's
  // colour and depth together: the frame clear of a renderer that draws on several threads.
  void clear(glm::vec4 color, float depth, int threads);

  // Packed RGBA8 pixel: byte 0 is red (little-endian uint32 = 0xAABBGGRR).
  uint32_t* color_row(int y) { return &color_[size_t(y) * size_t(width_)]; }
  const uint32_t* color_row(int y) const { return &color_[size_t(y) * size_t(width_)]; }
  float* depth_row(int y) { return &depth_[size_t(y) * size_t(width_)]; }
  const float* depth_row(int y) const { return &depth_[size_t(y) * size_t(width_)]; }
  uint32_t color_at(int x, int y) const { return color_row(y)[x]; }
  float depth_at(int x, int y) const { return depth_row(y)[x]; }

  Image to_image() const;

  // Colour and depth per sample for multisampled draws (RenderState::samples > 1), `count`
  // samples per pixel, pixel (x, y)'s at [(y * width + x) * count, ... + count). Kept between
  // multisampled draws with the same count, so that triangles of different draws sharing an edge
  // blend per sample; every draw leaves the pixels resolved (colour the rounded average of the
  // samples, depth their minimum). `valid` is false until a multisampled draw fills the samples
  // from the pixels; clear_color, clear_depth and single-sampled draws reset it, and
  // clear(colour, depth, threads) clears the samples with the pixels. Code that writes pixels
  // directly after a multisampled draw sets it to false too.
  struct Multisample {
    int count = 0;
    bool valid = false;
    std::vector<uint32_t> color;
    std::vector<float> depth;
  };
  Multisample& multisample() { return multisample_; }
  const Multisample& multisample() const { return multisample_; }

 private:
  int width_;
  int height_;
  std::vector<uint32_t> color_;
  std::vector<float> depth_;
  Multisample multisample_;
};

// Float colour to RGBA8 by the conventions: clamp to [0, 1], then x * 255 + 0.5 truncated.
inline uint8_t to_unorm8(float x) {
  // max(0, NaN) is 0 (the comparison is false), so NaN maps to 0; no branches.
  float clamped = std::min(1.0f, std::max(0.0f, x));
  return static_cast<uint8_t>(clamped * 255.0f + 0.5f);
}
inline uint32_t pack_rgba8(glm::vec4 c) {
#if defined(__SSE2__)  // every x86-64 has SSE2: the four channels at once, same results
  __m128 v = _mm_setr_ps(c.r, c.g, c.b, c.a);
  v = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(1.0f));  // max(NaN, 0) is 0
  __m128i i = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(v, _mm_set1_ps(255.0f)), _mm_set1_ps(0.5f)));
  i = _mm_packs_epi32(i, i);
  return uint32_t(_mm_cvtsi128_si32(_mm_packus_epi16(i, i)));
#else
  return uint32_t(to_unorm8(c.r)) | uint32_t(to_unorm8(c.g)) << 8 | uint32_t(to_unorm8(c.b)) << 16 |
         uint32_t(to_unorm8(c.a)) << 24;
#endif
}
inline glm::vec4 unpack_rgba8(uint32_t p) {
  constexpr float k = 1.0f / 255.0f;
  return {float(p & 0xff) * k, float((p >> 8) & 0xff) * k, float((p >> 16) & 0xff) * k,
          float(p >> 24) * k};
}

}  // namespace softrast
