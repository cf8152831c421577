// softrast/detail/vertex_simd.hpp: the vertex stage for shaders that also have a wide vertex
// shader: 16 vertices a call, their attributes read as vectors (one pass over consecutive
// vertices' arrays, gathers otherwise), the outputs written to the clip-space array vertex by
// vertex as the scalar stage writes them. Compiled once per SIMD level inside the caller's
// translation unit, chosen at the draw by simd_level(), as the fragment stage is.
// Internal: included through softrast/shader.hpp.
#pragma once

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <cstring>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/simd.hpp"
#include "softrast/simd_level.hpp"

namespace softrast {

// The 16 vertices a wide vertex shader runs on: lane l is vertex index[l] of the shader's own
// arrays (the same number vertex(index, ...) would get). The loads read each lane's element of
// an array of float structs (glm::vec2, vec3, vec4 and the like). Every member is always inlined,
// as Fragments' are.
template <int N>
struct Vertices {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  I index;
  // index[l] == first + l for every lane: the loads then read the 16 elements in one pass.
  bool consecutive = false;
  uint32_t first = 0;

  SOFTRAST_SIMD_INLINE simd::Vec2<N> vec2(const glm::vec2* array) const {
    F v[2];
    load<2>(reinterpret_cast<const float*>(array), v);
    return {v[0], v[1]};
  }
  SOFTRAST_SIMD_INLINE simd::Vec3<N> vec3(const glm::vec3* array) const {
    F v[3];
    load<3>(reinterpret_cast<const float*>(array), v);
    return {v[0], v[1], v[2]};
  }
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vec4(const glm::vec4* array) const {
    F v[4];
    load<4>(reinterpret_cast<const float*>(array), v);
    return {v[0], v[1], v[2], v[3]};
  }

  // Element c of each lane's struct of kFloats floats, for c < kFloats.
  template <int kFloats>
  SOFTRAST_SIMD_INLINE void load(const float* array, F (&out)[kFloats]) const {
    static_assert(sizeof(F) == 16 * sizeof(float));
    if (consecutive) {
      // The 16 structs are 16 kFloats consecutive floats: loaded as kFloats vectors of 16 and
      // sorted by shuffles (two per element for vec3; written for any width, so each level
      // compiles them to its own permutes).
      typedef float V __attribute__((vector_size(64)));
      V a[kFloats];
      std::memcpy(a, array + size_t(first) * kFloats, sizeof a);
      V r[kFloats];
      deinterleave(a, r);
      for (int c = 0; c < kFloats; ++c) std::memcpy(&out[c], &r[c], sizeof(V));
      return;
    }
    const I scaled = index * I(kFloats);
    for (int c = 0; c < kFloats; ++c) {
      const I bits = simd::gather(reinterpret_cast<const int32_t*>(array), scaled + I(c));
      std::memcpy(&out[c], &bits, sizeof(F));
    }
  }

 private:
  template <class V>
  SOFTRAST_SIMD_INLINE static void deinterleave(const V (&a)[2], V (&r)[2]) {
    r[0] = __builtin_shufflevector(a[0], a[1], 0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26,
                                   28, 30);
    r[1] = __builtin_shufflevector(a[0], a[1], 1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27,
                                   29, 31);
  }
  // Element c of struct l is float 3 l + c of the 48: those below 32 come from the first two
  // vectors, the rest from the third.
  template <class V>
  SOFTRAST_SIMD_INLINE static void deinterleave(const V (&a)[3], V (&r)[3]) {
    const V x =
        __builtin_shufflevector(a[0], a[1], 0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0);
    const V y =
        __builtin_shufflevector(a[0], a[1], 1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0);
    const V z =
        __builtin_shufflevector(a[0], a[1], 2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0);
    r[0] = __builtin_shufflevector(x, a[2], 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29);
    r[1] = __builtin_shufflevector(y, a[2], 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30);
    r[2] = __builtin_shufflevector(z, a[2], 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31);
  }
  // Element c of struct l is float 4 l + c of the 64: every fourth of the first two vectors and
  // of the last two, joined.
  template <class V>
  SOFTRAST_SIMD_INLINE static void deinterleave(const V (&a)[4], V (&r)[4]) {
#define SOFTRAST_EVERY_FOURTH(v, w, c)                                                            \
  __builtin_shufflevector(v, w, c, c + 4, c + 8, c + 12, c + 16, c + 20, c + 24, c + 28, 0, 0, 0, \
                          0, 0, 0, 0, 0)
#define SOFTRAST_ELEMENT(c)                                                                     \
  __builtin_shufflevector(SOFTRAST_EVERY_FOURTH(a[0], a[1], c),                                 \
                          SOFTRAST_EVERY_FOURTH(a[2], a[3], c), 0, 1, 2, 3, 4, 5, 6, 7, 16, 17, \
                          18, 19, 20, 21, 22, 23)
    r[0] = SOFTRAST_ELEMENT(0);
    r[1] = SOFTRAST_ELEMENT(1);
    r[2] = SOFTRAST_ELEMENT(2);
    r[3] = SOFTRAST_ELEMENT(3);
#undef SOFTRAST_ELEMENT
#undef SOFTRAST_EVERY_FOURTH
  }
};

namespace detail {

// A shader with a wide vertex shader besides its scalar one (shader.hpp):
//   template <int N> SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& v,
//                                                               simd::Float<N>* varyings) const;
template <class S>
concept WideVertexShader = requires(const S& s, const Vertices<4>& v, simd::Float<4>* out) {
  { s.template vertices<4>(v, out) } -> std::same_as<simd::Vec4<4>>;
};

// Whether shader `s` takes its wide vertex shader in this draw: its wide_vertices(), if it has
// one (a shader whose wide form covers only some of its settings); otherwise it does.
template <class S>
bool uses_wide_vertices(const S& s) {
  if constexpr (requires {
                  { s.wide_vertices() } -> std::convertible_to<bool>;
                }) {
    return s.wide_vertices();
  } else {
    return true;
  }
}

// Shades vertices begin..end-1 (vertex k is the shader's vertex name[k], or k when name is null)
// into out, kStride floats each from out + k * kStride: the position, then the varyings.
using ShadeVerticesFn = void (*)(const void* shader, const uint32_t* name, uint32_t begin,
                                 uint32_t end, float* out);

// Writes the first `count` of 16 vertices, each `kStride` floats from out + l * kStride: float f
// of vertex l is lane l of rows[f]. The rows go through a block of 16-float rows, then out four
// floats of four vertices at a time (a 4x4 transpose, one store per vertex and four floats).
template <int N, int kStride>
SOFTRAST_SIMD_INLINE void store_vertices(float* out, int count, const simd::Float<N>* rows) {
  constexpr int kQuads = (kStride + 3) / 4;
  alignas(64) float block[4 * kQuads][16];
  for (int f = 0; f < kStride; ++f) rows[f].store(block[f]);
  for (int f = kStride; f < 4 * kQuads; ++f) std::memset(block[f], 0, sizeof block[f]);
  typedef float V4 __attribute__((vector_size(16)));
  for (int group = 0; group < 4; ++group) {
    if (4 * group >= count) break;
    for (int q = 0; q < kQuads; ++q) {
      V4 r[4];
      for (int k = 0; k < 4; ++k) std::memcpy(&r[k], block[4 * q + k] + 4 * group, sizeof(V4));
      const V4 t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 1, 5);
      const V4 t1 = __builtin_shufflevector(r[0], r[1], 2, 6, 3, 7);
      const V4 t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 1, 5);
      const V4 t3 = __builtin_shufflevector(r[2], r[3], 2, 6, 3, 7);
      const V4 v[4] = {
          __builtin_shufflevector(t0, t2, 0, 1, 4, 5), __builtin_shufflevector(t0, t2, 2, 3, 6, 7),
          __builtin_shufflevector(t1, t3, 0, 1, 4, 5), __builtin_shufflevector(t1, t3, 2, 3, 6, 7)};
      const int left = kStride - 4 * q;  // floats of this quad that belong to the vertex
      for (int j = 0; j < 4 && 4 * group + j < count; ++j) {
        float* to = out + size_t(4 * group + j) * kStride + 4 * q;
        // (Sizes known at compile time, so each copy is a store or two, not a call.)
        switch (left) {
          case 1:
            std::memcpy(to, &v[j], 4);
            break;
          case 2:
            std::memcpy(to, &v[j], 8);
            break;
          case 3:
            std::memcpy(to, &v[j], 12);
            break;
          default:
            std::memcpy(to, &v[j], 16);
            break;
        }
      }
    }
  }
}

template <class S, int N>
SOFTRAST_SIMD_INLINE void shade_vertices_wide(const S& shader, const uint32_t* name, uint32_t begin,
                                              uint32_t end, float* out) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  constexpr int kStride = 4 + S::kVaryings;
  alignas(64) static constexpr int32_t kLaneNumbers[16] = {0, 1, 2,  3,  4,  5,  6,  7,
                                                           8, 9, 10, 11, 12, 13, 14, 15};
  for (uint32_t i = begin; i < end; i += 16) {
    const int count = int(std::min<uint32_t>(16, end - i));
    Vertices<N> v;
    if (name == nullptr && count == 16) {
      v.consecutive = true;
      v.first = i;
      v.index = I(int32_t(i)) + I::load(kLaneNumbers);
    } else {
      // A short last group repeats its last vertex in the lanes past it (computed, not stored).
      alignas(64) int32_t index[16];
      for (int l = 0; l < 16; ++l) {
        const uint32_t k = i + uint32_t(std::min(l, count - 1));
        index[l] = int32_t(name != nullptr ? name[k] : k);
      }
      v.index = I::load(index);
    }
    F rows[kStride];
    const simd::Vec4<N> p = shader.template vertices<N>(v, rows + 4);
    rows[0] = p.x, rows[1] = p.y, rows[2] = p.z, rows[3] = p.w;
    store_vertices<N, kStride>(out + size_t(i) * kStride, count, rows);
  }
}

// One entry point per SIMD level, as shade_block_* (flatten: the shader and its loads compiled
// for the level).
template <class S>
[[gnu::flatten]] void shade_vertices_sse2(const void* shader, const uint32_t* name, uint32_t begin,
                                          uint32_t end, float* out) {
  shade_vertices_wide<S, 4>(*static_cast<const S*>(shader), name, begin, end, out);
}
template <class S>
[[gnu::target("sse4.2"), gnu::flatten]] void shade_vertices_sse4(const void* shader,
                                                                 const uint32_t* name,
                                                                 uint32_t begin, uint32_t end,
                                                                 float* out) {
  shade_vertices_wide<S, 4>(*static_cast<const S*>(shader), name, begin, end, out);
}
template <class S>
[[gnu::target("avx2,fma"), gnu::flatten]] void shade_vertices_avx2(const void* shader,
                                                                   const uint32_t* name,
                                                                   uint32_t begin, uint32_t end,
                                                                   float* out) {
  shade_vertices_wide<S, 8>(*static_cast<const S*>(shader), name, begin, end, out);
}
template <class S>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void shade_vertices_avx512(
    const void* shader, const uint32_t* name, uint32_t begin, uint32_t end, float* out) {
  shade_vertices_wide<S, 16>(*static_cast<const S*>(shader), name, begin, end, out);
}

template <class S>
ShadeVerticesFn wide_shade_vertices([[maybe_unused]] SimdLevel level) {
#if defined(SOFTRAST_SHADERS_BASELINE_ONLY)
  return &shade_vertices_sse2<S>;
#else
  switch (level) {
    case SimdLevel::kAvx512:
      return &shade_vertices_avx512<S>;
    case SimdLevel::kAvx2:
      return &shade_vertices_avx2<S>;
    case SimdLevel::kSse4:
      return &shade_vertices_sse4<S>;
    case SimdLevel::kSse2:
      break;
  }
  return &shade_vertices_sse2<S>;
#endif
}

}  // namespace detail
}  // namespace softrast

#pragma GCC diagnostic pop
