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
#include <utility>

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
    simd::Vec2<N> r;
    load<2>(reinterpret_cast<const float*>(array), {&r.x, &r.y});
    return r;
  }
  SOFTRAST_SIMD_INLINE simd::Vec3<N> vec3(const glm::vec3* array) const {
    simd::Vec3<N> r;
    load<3>(reinterpret_cast<const float*>(array), {&r.x, &r.y, &r.z});
    return r;
  }
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vec4(const glm::vec4* array) const {
    simd::Vec4<N> r;
    load<4>(reinterpret_cast<const float*>(array), {&r.x, &r.y, &r.z, &r.w});
    return r;
  }

  // Element c of each lane's struct of kFloats floats, for c < kFloats.
  // (Written through pointers to the caller's vectors, and the loads typed: arrays of vectors
  // copied by value, and memcpy, GCC 12 moves 16 bytes at a time through the stack at AVX2,
  // where each wider load of them then waits for the stores.)
  template <int kFloats>
  SOFTRAST_SIMD_INLINE void load(const float* array, F* const (&out)[kFloats]) const {
    static_assert(kFloats >= 2 && kFloats <= 4);
    if (consecutive) {
      // The structs of each native vector's lanes are kFloats consecutive vectors' worth of
      // floats: loaded as such and sorted by shuffles of native vectors (two-source shuffles of
      // the width the level has; at AVX2 and SSE, 16-lane shuffles were lowered lane by lane,
      // which made the wide form slower than the scalar one).
      using V = typename simd::Native<N>::F;
      for (int part = 0; part < F::kParts; ++part) {
        const float* from = array + (size_t(first) + size_t(part) * N) * kFloats;
        V a[kFloats];
        for (int k = 0; k < kFloats; ++k) {
          a[k] = *reinterpret_cast<const typename simd::Native<N>::FU*>(from + k * N);
        }
        element<kFloats, 0>(a, out[0]->p[part], std::make_integer_sequence<int, N>{});
        element<kFloats, 1>(a, out[1]->p[part], std::make_integer_sequence<int, N>{});
        if constexpr (kFloats > 2) {
          element<kFloats, 2>(a, out[2]->p[part], std::make_integer_sequence<int, N>{});
        }
        if constexpr (kFloats > 3) {
          element<kFloats, 3>(a, out[3]->p[part], std::make_integer_sequence<int, N>{});
        }
      }
      return;
    }
    const I scaled = index * I(kFloats);
    for (int c = 0; c < kFloats; ++c) {
      const I bits = simd::gather(reinterpret_cast<const int32_t*>(array), scaled + I(c));
      *out[c] = simd::bit_cast_float(bits);
    }
  }

 private:
  // Element c of lane l is float K l + c of the K vectors a[0..K-1] (a[j] holding floats j N to
  // j N + N - 1): those of a[0] and a[1] by one shuffle, then each later vector's by a shuffle
  // with the result so far.
  static constexpr int source(int k, int c, int l) { return k * l + c; }
  static constexpr int from_first_two(int k, int c, int l) {
    return source(k, c, l) < 2 * N ? source(k, c, l) : 0;
  }
  static constexpr int from_vector(int k, int c, int j, int l) {
    return source(k, c, l) / N == j ? N + source(k, c, l) - j * N : l;
  }
  template <int K, int c, class V, int... L>
  SOFTRAST_SIMD_INLINE static void element(const V (&a)[K], V& r,
                                           std::integer_sequence<int, L...>) {
    r = __builtin_shufflevector(a[0], a[1], from_first_two(K, c, L)...);
    if constexpr (K > 2) r = __builtin_shufflevector(r, a[2], from_vector(K, c, 2, L)...);
    if constexpr (K > 3) r = __builtin_shufflevector(r, a[3], from_vector(K, c, 3, L)...);
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
