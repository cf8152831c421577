// tests/counting_shader.hpp: a wide shader that counts the pixels it shades (the live lanes of
// its calls), from any number of threads, and writes opaque red.
#pragma once

#include <atomic>
#include <cstdint>

#include <glm/glm.hpp>

#include "softrast/shader.hpp"

namespace softrast::test {

struct CountingShader {
  static constexpr int kVaryings = 0;
  const glm::vec4* positions = nullptr;  // clip-space positions, by vertex index
  mutable std::atomic<int64_t> shaded{0};
  glm::vec4 vertex(uint32_t index, float*) const { return positions[index]; }
  template <int N>
  void shade(Fragments<N>& f) const {
    shaded += __builtin_popcount(simd::bits(f.live));
    f.color = {simd::Float<N>(1.0f), simd::Float<N>(0.0f), simd::Float<N>(0.0f),
               simd::Float<N>(1.0f)};
  }
};

}  // namespace softrast::test
