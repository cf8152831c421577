// softrast/texture.hpp: textures and samplers used by fragment shaders.
// Texel rows are stored bottom-up, as after an OpenGL upload: v = 0 is the last row of the file.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "softrast/image.hpp"

namespace softrast {

enum class Filter { kNearest, kBilinear };
enum class Wrap { kRepeat, kClampToEdge, kMirroredRepeat };

struct Sampler {
  Filter filter = Filter::kBilinear;
  Wrap wrap_u = Wrap::kRepeat;
  Wrap wrap_v = Wrap::kRepeat;
};

// An RGBA8 texture. Texel (i, j) has its centre at ((i + 0.5) / width, (j + 0.5) / height) in
// (u, v); j = 0 is the bottom row of the picture. Channels are read as linear values in [0, 1].
class Texture {
 public:
  Texture() = default;
  // Takes an image as stored in a file (top row first) and flips it so that v = 0 is its bottom.
  static Texture from_image(const Image& image);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return texels_.empty(); }
  // The texels, rows bottom-up, RGBA8 (width * height * 4 bytes).
  const uint8_t* texels() const { return texels_.data(); }
  // Texel (i, j), j counted from the bottom row; precondition: in range.
  glm::vec4 texel(int i, int j) const {
    const uint8_t* t = &texels_[(size_t(j) * size_t(width_) + size_t(i)) * 4];
    constexpr float k = 1.0f / 255.0f;
    return {t[0] * k, t[1] * k, t[2] * k, t[3] * k};
  }

  // Samples at (u, v) with the sampler's filter and wrap modes. An empty texture samples as
  // opaque white, so a shader never has to test for a missing map.
  glm::vec4 sample(const Sampler& s, glm::vec2 uv) const {
    if (texels_.empty()) return glm::vec4(1.0f);
    if (s.filter == Filter::kNearest) return sample_nearest(s, uv);
    return sample_bilinear(s, uv);
  }

  // Wraps texel index i into [0, size) by the OpenGL rules for each mode.
  static int wrap(Wrap mode, int i, int size);

 private:
  glm::vec4 sample_nearest(const Sampler& s, glm::vec2 uv) const;
  glm::vec4 sample_bilinear(const Sampler& s, glm::vec2 uv) const;

  int width_ = 0;
  int height_ = 0;
  std::vector<uint8_t> texels_;  // rows bottom-up, RGBA8
};

// Wraps texel index i into [0, size) by the OpenGL rules for each mode.
inline int Texture::wrap(Wrap mode, int i, int size) {
  switch (mode) {
    case Wrap::kRepeat: {
      if ((size & (size - 1)) == 0) return i & (size - 1);  // power of two: no division
      int m = i % size;
      return m < 0 ? m + size : m;
    }
    case Wrap::kClampToEdge:
      return i < 0 ? 0 : (i >= size ? size - 1 : i);
    case Wrap::kMirroredRepeat: {
      int period = 2 * size;
      int m = i % period;
      if (m < 0) m += period;
      return m < size ? m : period - 1 - m;
    }
  }
  return 0;
}

// Splits a texture coordinate scaled to texels into floor(x) and the fraction x - floor(x),
// without a library call, and without undefined behaviour for NaN or huge values (they land on
// texel 0 with fraction 0, then wrap like any other index).
inline int texel_floor(float x, float& fraction) {
  if (!(x > -1.0e9f && x < 1.0e9f)) {
    fraction = 0.0f;
    return 0;
  }
  int i = static_cast<int>(x);  // truncates towards zero
  if (float(i) > x) --i;
  fraction = x - float(i);
  return i;
}

inline glm::vec4 Texture::sample_nearest(const Sampler& s, glm::vec2 uv) const {
  float unused;
  int i = wrap(s.wrap_u, texel_floor(uv.x * float(width_), unused), width_);
  int j = wrap(s.wrap_v, texel_floor(uv.y * float(height_), unused), height_);
  return texel(i, j);
}

inline glm::vec4 Texture::sample_bilinear(const Sampler& s, glm::vec2 uv) const {
  // Texel centres sit at half-integers, so shift by half a texel before splitting into the
  // integer texel and the fractional weight (GL_LINEAR).
  float fx, fy;
  int x0 = texel_floor(uv.x * float(width_) - 0.5f, fx);
  int y0 = texel_floor(uv.y * float(height_) - 0.5f, fy);
  int i0 = wrap(s.wrap_u, x0, width_), i1 = wrap(s.wrap_u, x0 + 1, width_);
  int j0 = wrap(s.wrap_v, y0, height_), j1 = wrap(s.wrap_v, y0 + 1, height_);
  glm::vec4 bottom = texel(i0, j0) * (1.0f - fx) + texel(i1, j0) * fx;
  glm::vec4 top = texel(i0, j1) * (1.0f - fx) + texel(i1, j1) * fx;
  return bottom * (1.0f - fy) + top * fy;
}

}  // namespace softrast
