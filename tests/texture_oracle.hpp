// tests/texture_oracle.hpp: texture lookups as the OpenGL 4.6 specification defines them (8.14,
// the wrap modes of table 8.20, GL_NEAREST and GL_LINEAR), in double, as the oracle the texture
// tests hold softrast's sampler to. The texel source is a function texel(i, j) -> glm::dvec4 with
// j counted from the bottom row, so that an Image and a Texture serve alike.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "softrast/texture.hpp"

namespace softrast::test {

// The wrap mode for an integer texel coordinate i of a side of `size` texels.
inline int spec_wrap(Wrap mode, int64_t i, int64_t size) {
  auto mod = [](int64_t a, int64_t b) { return ((a % b) + b) % b; };
  auto mirror = [](int64_t a) { return a >= 0 ? a : -(1 + a); };
  switch (mode) {
    case Wrap::kRepeat:
      return int(mod(i, size));
    case Wrap::kClampToEdge:
      return int(std::clamp<int64_t>(i, 0, size - 1));
    case Wrap::kMirroredRepeat:
      return int((size - 1) - mirror(mod(i, 2 * size) - size));
  }
  return 0;
}

// GL_NEAREST: the texel floor(u * w), floor(v * h).
template <class Texel>
glm::dvec4 spec_nearest(Texel texel, int w, int h, const Sampler& s, double u, double v) {
  int i = spec_wrap(s.wrap_u, int64_t(std::floor(u * w)), w);
  int j = spec_wrap(s.wrap_v, int64_t(std::floor(v * h)), h);
  return texel(i, j);
}

// GL_LINEAR: the four texels around (u * w - 0.5, v * h - 0.5) weighted by the fractions.
template <class Texel>
glm::dvec4 spec_linear(Texel texel, int w, int h, const Sampler& s, double u, double v) {
  double x = u * w - 0.5, y = v * h - 0.5;
  double x0 = std::floor(x), y0 = std::floor(y);
  double a = x - x0, b = y - y0;
  int i0 = spec_wrap(s.wrap_u, int64_t(x0), w), i1 = spec_wrap(s.wrap_u, int64_t(x0) + 1, w);
  int j0 = spec_wrap(s.wrap_v, int64_t(y0), h), j1 = spec_wrap(s.wrap_v, int64_t(y0) + 1, h);
  return (1 - a) * (1 - b) * texel(i0, j0) + a * (1 - b) * texel(i1, j0) +
         (1 - a) * b * texel(i0, j1) + a * b * texel(i1, j1);
}

}  // namespace softrast::test
