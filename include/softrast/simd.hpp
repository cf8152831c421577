// softrast/simd.hpp: the wide types fragment shaders are written with. A value of Float<N> holds
// one float per pixel of a 4x4 block (16 lanes, lane 4 * row + column), stored as 16 / N native
// vectors of N lanes: N = 4 for SSE, 8 for AVX2, 16 for AVX-512. Shaders are templates on N and
// read like scalar code; the fragment stage compiles them once per instruction set (each inside
// a function with that set's target attribute, everything inlined) and picks one at run time.
//
// Why this shape: GCC's vector extensions at a native width lower to good code for any target
// the enclosing function is compiled for, so one source serves every level, including shaders in
// the user's own translation unit; the few operations the extensions lack (sqrt, gathers, mask
// extraction) go through small helpers with a target attribute that take their vectors by
// reference, so no wide vector crosses a call boundary between code built for different targets.
#pragma once

// Wide vectors are passed by value between inlined helpers; GCC notes that the ABI of such
// parameters changed in GCC 4.6, which cannot matter here (nothing crosses a library boundary).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace softrast::simd {

#define SOFTRAST_SIMD_INLINE [[gnu::always_inline]] inline

// Pixels of a 4x4 block: the unit the fragment stage shades.
inline constexpr int kLanes = 16;

// (Spelled out per width: GCC drops vector_size on an alias whose size depends on N.)
template <int N>
struct Native;
template <>
struct Native<4> {
  typedef float F __attribute__((vector_size(16)));
  typedef int32_t I __attribute__((vector_size(16)));
  typedef uint32_t U __attribute__((vector_size(16)));
  typedef double D __attribute__((vector_size(32)));  // N doubles (depth)
  // For loads and stores at any 4-byte aligned address, through any type.
  typedef float FU __attribute__((vector_size(16), aligned(4), may_alias));
  typedef int32_t IU __attribute__((vector_size(16), aligned(4), may_alias));
};
template <>
struct Native<8> {
  typedef float F __attribute__((vector_size(32)));
  typedef int32_t I __attribute__((vector_size(32)));
  typedef uint32_t U __attribute__((vector_size(32)));
  typedef double D __attribute__((vector_size(64)));  // N doubles (depth)
  // For loads and stores at any 4-byte aligned address, through any type.
  typedef float FU __attribute__((vector_size(32), aligned(4), may_alias));
  typedef int32_t IU __attribute__((vector_size(32), aligned(4), may_alias));
};
template <>
struct Native<16> {
  typedef float F __attribute__((vector_size(64)));
  typedef int32_t I __attribute__((vector_size(64)));
  typedef uint32_t U __attribute__((vector_size(64)));
  typedef double D __attribute__((vector_size(128)));  // N doubles (depth)
  // For loads and stores at any 4-byte aligned address, through any type.
  typedef float FU __attribute__((vector_size(64), aligned(4), may_alias));
  typedef int32_t IU __attribute__((vector_size(64), aligned(4), may_alias));
};

template <int N>
struct Int;

// AVX-512 comparisons and selects go through intrinsics: GCC 12 splits (or fails to compile)
// some 512-bit vector conditions written with the extensions, since AVX-512 keeps them in mask
// registers. Each helper has the AVX-512 target and takes its vectors by reference; the
// fragment stage's entry point inlines them (flatten).
namespace isa {
using F16 = float __attribute__((vector_size(64)));
using I16 = int32_t __attribute__((vector_size(64)));
#define SOFTRAST_AVX512 [[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] inline
SOFTRAST_AVX512 void cmp(int predicate, const F16& a, const F16& b, I16& r);
SOFTRAST_AVX512 void cmp(int predicate, const I16& a, const I16& b, I16& r);
SOFTRAST_AVX512 void blend(const I16& mask, const F16& a, const F16& b, F16& r);
SOFTRAST_AVX512 void blend(const I16& mask, const I16& a, const I16& b, I16& r);
SOFTRAST_AVX512 void broadcast(float s, F16& r);
SOFTRAST_AVX512 void broadcast(int32_t s, I16& r);
SOFTRAST_AVX512 void store_lanes(uint32_t bits, const F16& v, float* to);
SOFTRAST_AVX512 void store_lanes(uint32_t bits, const I16& v, int32_t* to);
SOFTRAST_AVX512 void lanes_of(uint32_t bits, I16& r);
// r[i] = bit i of `bits` ? b : a, for 16 doubles.
using D16 = double __attribute__((vector_size(128)));
SOFTRAST_AVX512 void pick(uint32_t bits, const double& a, const double& b, D16& r);
// 16 doubles as two registers of 8 (lanes 0 to 7, 8 to 15): a loop that carries D16 values is
// split into scalars by GCC 12.
using D8 = double __attribute__((vector_size(64)));
// half[i] = b where bit i of `bits` is set, for lanes 0 to 7 of a D16 (`high`: 8 to 15); else
// unchanged.
SOFTRAST_AVX512 void merge(uint32_t bits, const double& b, D8& low, D8& high);
SOFTRAST_AVX512 void join(const D8& low, const D8& high, D16& r);
// AVX2's broadcasts, one VBROADCASTSS or VPBROADCASTD (the shuffle of lane 0 below is a move into
// a zeroed register, a move to clear the upper lanes again and then the broadcast).
using F8 = float __attribute__((vector_size(32)));
using I8 = int32_t __attribute__((vector_size(32)));
[[gnu::target("avx")]] inline void broadcast(float s, F8& r) {
  r = F8(_mm256_set1_ps(s));
}
[[gnu::target("avx2")]] inline void broadcast(int32_t s, I8& r) {
  r = I8(_mm256_set1_epi32(s));
}
}  // namespace isa

template <int N>
struct Float {
  static constexpr int kParts = kLanes / N;
  using V = typename Native<N>::F;
  using IV = typename Native<N>::I;
  V p[kParts];

  Float() = default;
  // Broadcast; implicit so that 2.0f * x reads naturally. (Written as a shuffle of lane 0:
  // GCC 12 builds `V{} + s` lane by lane once it has been inlined into a wider target; at 16
  // lanes the shuffle became two broadcasts and at 8 three instructions, so there it is the
  // intrinsic.)
  SOFTRAST_SIMD_INLINE Float(float s) {
#if defined(__clang__)  // no __builtin_shuffle; clang broadcasts a scalar added to a vector
    for (int k = 0; k < kParts; ++k) p[k] = V{} + s;
#else
    if constexpr (N == 16 || N == 8) {
      isa::broadcast(s, p[0]);  // one VBROADCASTSS
      for (int k = 1; k < kParts; ++k) p[k] = p[0];
    } else {
      V t = {};
      t[0] = s;
      for (int k = 0; k < kParts; ++k) p[k] = __builtin_shuffle(t, typename Native<N>::I{});
    }
#endif
  }
  // (Typed unaligned vector accesses: GCC 12 splits a memcpy of the parts into 16-byte moves.)
  SOFTRAST_SIMD_INLINE static Float load(const float* lanes) {
    Float r;
    for (int k = 0; k < kParts; ++k)
      r.p[k] = *reinterpret_cast<const typename Native<N>::FU*>(lanes + k * N);
    return r;
  }
  SOFTRAST_SIMD_INLINE void store(float* lanes) const {
    for (int k = 0; k < kParts; ++k)
      *reinterpret_cast<typename Native<N>::FU*>(lanes + k * N) = p[k];
  }
  SOFTRAST_SIMD_INLINE float lane(int i) const {
    return p[i / N][i % N];
  }
  SOFTRAST_SIMD_INLINE void set_lane(int i, float v) {
    p[i / N][i % N] = v;
  }

#define SOFTRAST_SIMD_FLOAT_OP(op)                                                \
  SOFTRAST_SIMD_INLINE friend Float operator op(const Float& a, const Float& b) { \
    Float r;                                                                      \
    for (int k = 0; k < kParts; ++k) r.p[k] = a.p[k] op b.p[k];                   \
    return r;                                                                     \
  }                                                                               \
  SOFTRAST_SIMD_INLINE Float& operator op##=(const Float& b) {                    \
    return *this = *this op b;                                                    \
  }
  SOFTRAST_SIMD_FLOAT_OP(+)
  SOFTRAST_SIMD_FLOAT_OP(-)
  SOFTRAST_SIMD_FLOAT_OP(*)
  SOFTRAST_SIMD_FLOAT_OP(/)
#undef SOFTRAST_SIMD_FLOAT_OP
  SOFTRAST_SIMD_INLINE friend Float operator-(const Float& a) {
    Float r;
    for (int k = 0; k < kParts; ++k) r.p[k] = -a.p[k];
    return r;
  }
#define SOFTRAST_SIMD_FLOAT_CMP(op, predicate)                                     \
  SOFTRAST_SIMD_INLINE friend Int<N> operator op(const Float& a, const Float& b) { \
    Int<N> r;                                                                      \
    for (int k = 0; k < kParts; ++k) {                                             \
      if constexpr (N == 16) {                                                     \
        isa::cmp(predicate, a.p[k], b.p[k], r.p[k]);                               \
      } else {                                                                     \
        r.p[k] = a.p[k] op b.p[k] ? ~IV{} : IV{};                                  \
      }                                                                            \
    }                                                                              \
    return r;                                                                      \
  }
  SOFTRAST_SIMD_FLOAT_CMP(<, _CMP_LT_OQ)
  SOFTRAST_SIMD_FLOAT_CMP(<=, _CMP_LE_OQ)
  SOFTRAST_SIMD_FLOAT_CMP(>, _CMP_GT_OQ)
  SOFTRAST_SIMD_FLOAT_CMP(>=, _CMP_GE_OQ)
  SOFTRAST_SIMD_FLOAT_CMP(==, _CMP_EQ_OQ)
  SOFTRAST_SIMD_FLOAT_CMP(!=, _CMP_NEQ_UQ)
#undef SOFTRAST_SIMD_FLOAT_CMP
};

// 32-bit integers, and lane masks: a comparison gives -1 (all bits) where true, 0 where false;
// consumers of masks (select, bits, any) read only the sign bit.
template <int N>
struct Int {
  static constexpr int kParts = kLanes / N;
  using V = typename Native<N>::I;
  V p[kParts];

  Int() = default;
  SOFTRAST_SIMD_INLINE Int(int32_t s) {  // broadcast, as Float's
#if defined(__clang__)
    for (int k = 0; k < kParts; ++k) p[k] = V{} + s;
#else
    if constexpr (N == 16 || N == 8) {
      isa::broadcast(s, p[0]);
      for (int k = 1; k < kParts; ++k) p[k] = p[0];
    } else {
      V t = {};
      t[0] = s;
      for (int k = 0; k < kParts; ++k) p[k] = __builtin_shuffle(t, V{});
    }
#endif
  }
  SOFTRAST_SIMD_INLINE static Int load(const int32_t* lanes) {
    Int r;
    for (int k = 0; k < kParts; ++k)
      r.p[k] = *reinterpret_cast<const typename Native<N>::IU*>(lanes + k * N);
    return r;
  }
  SOFTRAST_SIMD_INLINE void store(int32_t* lanes) const {
    for (int k = 0; k < kParts; ++k)
      *reinterpret_cast<typename Native<N>::IU*>(lanes + k * N) = p[k];
  }
  SOFTRAST_SIMD_INLINE int32_t lane(int i) const {
    return p[i / N][i % N];
  }

#define SOFTRAST_SIMD_INT_OP(op)                                            \
  SOFTRAST_SIMD_INLINE friend Int operator op(const Int& a, const Int& b) { \
    Int r;                                                                  \
    for (int k = 0; k < kParts; ++k) r.p[k] = a.p[k] op b.p[k];             \
    return r;                                                               \
  }
  SOFTRAST_SIMD_INT_OP(+)
  SOFTRAST_SIMD_INT_OP(-)
  SOFTRAST_SIMD_INT_OP(*)
  SOFTRAST_SIMD_INT_OP(&)
  SOFTRAST_SIMD_INT_OP(|)
  SOFTRAST_SIMD_INT_OP(^)
#undef SOFTRAST_SIMD_INT_OP
  // Comparisons written as selects: GCC 12 keeps a vector condition whole, where it may split
  // a bare integer comparison into lanes.
#define SOFTRAST_SIMD_INT_CMP(op, predicate)                                \
  SOFTRAST_SIMD_INLINE friend Int operator op(const Int& a, const Int& b) { \
    Int r;                                                                  \
    for (int k = 0; k < kParts; ++k) {                                      \
      if constexpr (N == 16) {                                              \
        isa::cmp(predicate, a.p[k], b.p[k], r.p[k]);                        \
      } else {                                                              \
        r.p[k] = a.p[k] op b.p[k] ? ~V{} : V{};                             \
      }                                                                     \
    }                                                                       \
    return r;                                                               \
  }
  SOFTRAST_SIMD_INT_CMP(<, _MM_CMPINT_LT)
  SOFTRAST_SIMD_INT_CMP(>, _MM_CMPINT_NLE)
  SOFTRAST_SIMD_INT_CMP(==, _MM_CMPINT_EQ)
  SOFTRAST_SIMD_INT_CMP(!=, _MM_CMPINT_NE)
#undef SOFTRAST_SIMD_INT_CMP
  SOFTRAST_SIMD_INLINE friend Int operator~(const Int& a) {
    Int r;
    for (int k = 0; k < kParts; ++k) r.p[k] = ~a.p[k];
    return r;
  }
  SOFTRAST_SIMD_INLINE friend Int operator<<(const Int& a, int s) {
    Int r;
    for (int k = 0; k < kParts; ++k) r.p[k] = a.p[k] << s;
    return r;
  }
  // Logical shift (zeros in from the left), as packed colours need.
  SOFTRAST_SIMD_INLINE friend Int operator>>(const Int& a, int s) {
    using U = typename Native<N>::U;
    Int r;
    for (int k = 0; k < kParts; ++k) r.p[k] = V(U(a.p[k]) >> s);
    return r;
  }
};

// mask ? a : b, lane by lane (mask lanes are -1 or 0).
template <int N>
SOFTRAST_SIMD_INLINE Float<N> select(const Int<N>& mask, const Float<N>& a, const Float<N>& b) {
  Float<N> r;
  // `< 0` (the sign bit) rather than `!= 0`: GCC 12 splits the latter into lanes for AVX-512.
  for (int k = 0; k < Float<N>::kParts; ++k) {
    if constexpr (N == 16) {
      isa::blend(mask.p[k], a.p[k], b.p[k], r.p[k]);
    } else {
      r.p[k] = mask.p[k] < 0 ? a.p[k] : b.p[k];
    }
  }
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Int<N> select(const Int<N>& mask, const Int<N>& a, const Int<N>& b) {
  Int<N> r;
  for (int k = 0; k < Int<N>::kParts; ++k) {
    if constexpr (N == 16) {
      isa::blend(mask.p[k], a.p[k], b.p[k], r.p[k]);
    } else {
      r.p[k] = mask.p[k] < 0 ? a.p[k] : b.p[k];
    }
  }
  return r;
}

// Lane i of `v` to to[i] where lane i of `mask` is set (`bits`: its lanes as bits, simd::bits),
// the other elements of `to` untouched. At AVX-512 one masked store; elsewhere a whole store for
// all 16 lanes, else a blend into the values loaded and a whole store (AVX2's masked stores are
// slow on AMD's Zen 3: core/store_mode.hpp).
// (V: Float<N> with T = float, or Int<N> with T = int32_t.)
template <int N, class V, class T>
SOFTRAST_SIMD_INLINE void store_lanes(const Int<N>& mask, uint32_t bits, const V& v, T* to) {
  if constexpr (N == 16) {
    isa::store_lanes(bits, v.p[0], to);
  } else if (bits == 0xffffu) {
    v.store(to);
  } else {
    select(mask, v, V::load(to)).store(to);
  }
}

// min/max with the SSE semantics (and std::min/std::max's): the second operand when either is
// NaN, so max(NaN, 0) is 0.
// (One instruction each, defined with the helpers below.)
template <int N>
SOFTRAST_SIMD_INLINE Float<N> min(const Float<N>& a, const Float<N>& b);
template <int N>
SOFTRAST_SIMD_INLINE Float<N> max(const Float<N>& a, const Float<N>& b);
// std::clamp's definition: v < lo ? lo : (hi < v ? hi : v) (NaN stays NaN), which is
// max(lo, min(hi, v)) with MINPS/MAXPS's operand order.
template <int N>
SOFTRAST_SIMD_INLINE Float<N> clamp(const Float<N>& v, const Float<N>& lo, const Float<N>& hi);

template <int N>
SOFTRAST_SIMD_INLINE Float<N> to_float(const Int<N>& a) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) {
    r.p[k] = __builtin_convertvector(a.p[k], typename Native<N>::F);
  }
  return r;
}
// Truncates towards zero. Precondition: |a| < 2^31 (NaN and larger values are unspecified).
template <int N>
SOFTRAST_SIMD_INLINE Int<N> to_int(const Float<N>& a) {
  Int<N> r;
  for (int k = 0; k < Int<N>::kParts; ++k) {
    r.p[k] = __builtin_convertvector(a.p[k], typename Native<N>::I);
  }
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Int<N> bit_cast_int(const Float<N>& a) {
  Int<N> r;
  for (int k = 0; k < Int<N>::kParts; ++k) r.p[k] = typename Native<N>::I(a.p[k]);
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Float<N> bit_cast_float(const Int<N>& a) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) r.p[k] = typename Native<N>::F(a.p[k]);
  return r;
}
// The smaller of two 32-bit integers, lane by lane.
template <int N>
SOFTRAST_SIMD_INLINE Int<N> min(const Int<N>& a, const Int<N>& b) {
  Int<N> r;
  for (int k = 0; k < Int<N>::kParts; ++k) r.p[k] = a.p[k] < b.p[k] ? a.p[k] : b.p[k];
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Float<N> abs(const Float<N>& a) {
  return bit_cast_float(bit_cast_int(a) & Int<N>(0x7fffffff));
}

// ---- Operations the vector extensions lack: one helper per instruction set. ----

// Whether the gathers of N lanes (8: AVX2, 16: AVX-512) are one load per lane instead of the
// gather instruction: the same values either way, and the faster on this CPU (gather_mode() in
// softrast/simd_level.hpp, settled before the first draw). Index 0 for 8 lanes, 1 for 16.
extern bool g_loads_for_gathers[2];
template <int N>
SOFTRAST_SIMD_INLINE bool loads_for_gathers() {
  static_assert(N == 8 || N == 16);
  return g_loads_for_gathers[N == 16];
}

// How a gather by loads (loads_for_gathers) takes the lanes' indices out of the vector register:
// stored and read back by scalar loads (kMemory), which cost the load ports only, or two at a time
// by 64-bit extracts (kRegisters), which cost the shuffle port but do not wait for a store to
// forward. Which is faster depends on the code around the gather, so each site says; measured
// on an AMD Zen 3 (AVX2), medians of alternating runs at one thread: the sampler's texel loads
// by registers (quad_grid texture 4 to 6 % faster, diablo3 4 %); the triangle kernel's vertex
// loads by memory (by registers, spheres gouraud was 11 to 13 % slower in three sets of runs:
// its transposes keep the shuffle port busy). Only the 8-lane (AVX2) forms have both routes;
// the others ignore it.
enum class IndexRoute { kMemory, kRegisters };

namespace isa {

// The comparison predicate must be a constant after inlining (it always is: an operator's).
SOFTRAST_AVX512 void cmp(int predicate, const F16& a, const F16& b, I16& r) {
  __mmask16 m = 0;
  switch (predicate) {
    case _CMP_LT_OQ:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_LT_OQ);
      break;
    case _CMP_LE_OQ:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_LE_OQ);
      break;
    case _CMP_GT_OQ:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_GT_OQ);
      break;
    case _CMP_GE_OQ:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_GE_OQ);
      break;
    case _CMP_EQ_OQ:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_EQ_OQ);
      break;
    default:
      m = _mm512_cmp_ps_mask(__m512(a), __m512(b), _CMP_NEQ_UQ);
      break;
  }
  r = I16(_mm512_movm_epi32(m));
}
SOFTRAST_AVX512 void cmp(int predicate, const I16& a, const I16& b, I16& r) {
  __mmask16 m = 0;
  switch (predicate) {
    case _MM_CMPINT_LT:
      m = _mm512_cmplt_epi32_mask(__m512i(a), __m512i(b));
      break;
    case _MM_CMPINT_NLE:
      m = _mm512_cmpgt_epi32_mask(__m512i(a), __m512i(b));
      break;
    case _MM_CMPINT_EQ:
      m = _mm512_cmpeq_epi32_mask(__m512i(a), __m512i(b));
      break;
    default:
      m = _mm512_cmpneq_epi32_mask(__m512i(a), __m512i(b));
      break;
  }
  r = I16(_mm512_movm_epi32(m));
}
SOFTRAST_AVX512 void blend(const I16& mask, const F16& a, const F16& b, F16& r) {
  r = F16(_mm512_mask_blend_ps(_mm512_movepi32_mask(__m512i(mask)), __m512(b), __m512(a)));
}
SOFTRAST_AVX512 void broadcast(float s, F16& r) {
  r = F16(_mm512_set1_ps(s));
}
SOFTRAST_AVX512 void broadcast(int32_t s, I16& r) {
  r = I16(_mm512_set1_epi32(s));
}
SOFTRAST_AVX512 void blend(const I16& mask, const I16& a, const I16& b, I16& r) {
  r = I16(_mm512_mask_blend_epi32(_mm512_movepi32_mask(__m512i(mask)), __m512i(b), __m512i(a)));
}
// Lane k all ones where bit k of `bits` is set, else zero: a mask register made a vector.
SOFTRAST_AVX512 void lanes_of(uint32_t bits, I16& r) {
  r = I16(_mm512_movm_epi32(__mmask16(bits)));
}
SOFTRAST_AVX512 void pick(uint32_t bits, const double& a, const double& b, D16& r) {
  using D8 = double __attribute__((vector_size(64)));
  const __m512d low = _mm512_set1_pd(a);
  const D8 first(_mm512_mask_blend_pd(__mmask8(bits), low, _mm512_set1_pd(b)));
  const D8 second(_mm512_mask_blend_pd(__mmask8(bits >> 8), low, _mm512_set1_pd(b)));
  r = __builtin_shufflevector(first, second, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
}
SOFTRAST_AVX512 void merge(uint32_t bits, const double& b, D8& low, D8& high) {
  const __m512d value = _mm512_set1_pd(b);
  low = D8(_mm512_mask_blend_pd(__mmask8(bits), __m512d(low), value));
  high = D8(_mm512_mask_blend_pd(__mmask8(bits >> 8), __m512d(high), value));
}
SOFTRAST_AVX512 void join(const D8& low, const D8& high, D16& r) {
  r = __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
}
SOFTRAST_AVX512 void store_lanes(uint32_t bits, const F16& v, float* to) {
  _mm512_mask_storeu_ps(to, __mmask16(bits), __m512(v));
}
SOFTRAST_AVX512 void store_lanes(uint32_t bits, const I16& v, int32_t* to) {
  _mm512_mask_storeu_epi32(to, __mmask16(bits), __m512i(v));
}

inline void sqrt(const Native<4>::F& a, Native<4>::F& r) {
  r = Native<4>::F(_mm_sqrt_ps(__m128(a)));
}
[[gnu::target("avx")]] inline void sqrt(const Native<8>::F& a, Native<8>::F& r) {
  r = Native<8>::F(_mm256_sqrt_ps(__m256(a)));
}
[[gnu::target("avx512f")]] inline void sqrt(const Native<16>::F& a, Native<16>::F& r) {
  r = Native<16>::F(
      _mm512_maskz_sqrt_ps(__mmask16(0xffff), __m512(a)));  // maskz: no undefined source
}

// r = floor(a), lane by lane (VROUNDPS): AVX2's texel addresses (texture_simd.hpp's texel_floor);
// the baseline truncates and corrects instead (SSE2 has no rounding instruction).
[[gnu::target("avx")]] inline void floor(const Native<8>::F& a, Native<8>::F& r) {
  r = Native<8>::F(_mm256_round_ps(__m256(a), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
}

// r = a * b + c, fused (one rounding) where the level has FMA (AVX2 with FMA, AVX-512); two
// roundings at SSE2 and SSE4, so the levels may differ in the last bit.
inline void fmadd(const Native<4>::F& a, const Native<4>::F& b, const Native<4>::F& c,
                  Native<4>::F& r) {
  r = a * b + c;
}
[[gnu::target("avx2,fma")]] inline void fmadd(const Native<8>::F& a, const Native<8>::F& b,
                                              const Native<8>::F& c, Native<8>::F& r) {
  r = Native<8>::F(_mm256_fmadd_ps(__m256(a), __m256(b), __m256(c)));
}
[[gnu::target("avx512f")]] inline void fmadd(const Native<16>::F& a, const Native<16>::F& b,
                                             const Native<16>::F& c, Native<16>::F& r) {
  r = Native<16>::F(_mm512_maskz_fmadd_ps(__mmask16(0xffff), __m512(a), __m512(b), __m512(c)));
}

// r ~ 1 / sqrt(a): the instruction's estimate (relative error below 1.5 * 2^-12, AVX-512's below
// 2^-14). The Newton step that makes it a float is in simd::rsqrt.
inline void rsqrt_estimate(const Native<4>::F& a, Native<4>::F& r) {
  r = Native<4>::F(_mm_rsqrt_ps(__m128(a)));
}
[[gnu::target("avx")]] inline void rsqrt_estimate(const Native<8>::F& a, Native<8>::F& r) {
  r = Native<8>::F(_mm256_rsqrt_ps(__m256(a)));
}
[[gnu::target("avx512f")]] inline void rsqrt_estimate(const Native<16>::F& a, Native<16>::F& r) {
  r = Native<16>::F(_mm512_maskz_rsqrt14_ps(__mmask16(0xffff), __m512(a)));
}

// r = a < b ? a : b and a > b ? a : b (MINPS / MAXPS: the second operand when either is NaN).
inline void min(const Native<4>::F& a, const Native<4>::F& b, Native<4>::F& r) {
  r = Native<4>::F(_mm_min_ps(__m128(a), __m128(b)));
}
inline void max(const Native<4>::F& a, const Native<4>::F& b, Native<4>::F& r) {
  r = Native<4>::F(_mm_max_ps(__m128(a), __m128(b)));
}
[[gnu::target("avx")]] inline void min(const Native<8>::F& a, const Native<8>::F& b,
                                       Native<8>::F& r) {
  r = Native<8>::F(_mm256_min_ps(__m256(a), __m256(b)));
}
[[gnu::target("avx")]] inline void max(const Native<8>::F& a, const Native<8>::F& b,
                                       Native<8>::F& r) {
  r = Native<8>::F(_mm256_max_ps(__m256(a), __m256(b)));
}
[[gnu::target("avx512f")]] inline void min(const Native<16>::F& a, const Native<16>::F& b,
                                           Native<16>::F& r) {
  r = Native<16>::F(_mm512_maskz_min_ps(__mmask16(0xffff), __m512(a), __m512(b)));
}
[[gnu::target("avx512f")]] inline void max(const Native<16>::F& a, const Native<16>::F& b,
                                           Native<16>::F& r) {
  r = Native<16>::F(_mm512_maskz_max_ps(__mmask16(0xffff), __m512(a), __m512(b)));
}

inline int sign_bits(const Native<4>::I& a) {
  return _mm_movemask_ps(__m128(a));
}
[[gnu::target("avx")]] inline int sign_bits(const Native<8>::I& a) {
  return _mm256_movemask_ps(__m256(a));
}
[[gnu::target("avx512f,avx512dq")]] inline int sign_bits(const Native<16>::I& a) {
  return int(_mm512_movepi32_mask(__m512i(a)));
}

// r[i] = base[index[i]] for 32-bit elements.
inline void gather(const int32_t* base, const Native<4>::I& index, Native<4>::I& r,
                   IndexRoute = IndexRoute::kMemory) {
  for (int i = 0; i < 4; ++i) {
    int32_t v;
    std::memcpy(&v, base + index[i], sizeof v);  // the base may be a byte array
    r[i] = v;
  }
}
// The gathers of AVX2 and AVX-512 come in two forms that give the same values: the instruction
// (`*_instruction`) and one scalar load per lane (`*_loads`), which the CPU runs faster where its
// microcode slows the instruction down (gather_mode()). `at` holds the lanes' indices.

// Keeps the indices in memory: read back by scalar loads, they cost the load ports, where GCC
// would otherwise take each out of the vector by an extract on the shuffle port, which the
// shaders' own shuffles need.
template <size_t Lanes>
SOFTRAST_SIMD_INLINE void through_memory(int32_t (&at)[Lanes]) {
  asm("" : "+m"(at));
}
// The 16 indices stored as two 256-bit halves: a 512-bit store does not forward to the scalar
// loads that read its upper half, which then wait for the store to reach the cache (measured:
// twice the time of the loads themselves).
[[gnu::target("avx512f")]] inline void store_halves(int32_t (&at)[16], const Native<16>::I& index) {
  using V = Native<8>::IU;
  *reinterpret_cast<V*>(at) = __builtin_shufflevector(index, index, 0, 1, 2, 3, 4, 5, 6, 7);
  *reinterpret_cast<V*>(at + 8) =
      __builtin_shufflevector(index, index, 8, 9, 10, 11, 12, 13, 14, 15);
  through_memory(at);
}
// The 8 indices of an AVX2 register as scalars for the loads, by `route`: stored and read back
// (through_memory), or taken out of the register 64 bits (two indices) at a time.
[[gnu::target("avx2")]] inline void index_lanes(const Native<8>::I& index, IndexRoute route,
                                                int32_t (&at)[8]) {
  if (route == IndexRoute::kMemory) {
    _mm256_store_si256(reinterpret_cast<__m256i*>(at), __m256i(index));
    through_memory(at);
    return;
  }
  const __m128i low = _mm256_castsi256_si128(__m256i(index));
  const __m128i high = _mm256_extracti128_si256(__m256i(index), 1);
  const uint64_t q[4] = {uint64_t(_mm_cvtsi128_si64(low)), uint64_t(_mm_extract_epi64(low, 1)),
                         uint64_t(_mm_cvtsi128_si64(high)), uint64_t(_mm_extract_epi64(high, 1))};
  for (int i = 0; i < 4; ++i) {
    at[2 * i] = int32_t(uint32_t(q[i]));
    at[2 * i + 1] = int32_t(uint32_t(q[i] >> 32));
  }
}
[[gnu::target("avx2")]] inline __m128i load_lanes4(const int32_t* base, const int32_t* at) {
  auto lane = [base](int32_t i) {
    int32_t v;
    std::memcpy(&v, base + i, sizeof v);  // the base may be a byte array
    return _mm_cvtsi32_si128(v);
  };
  return _mm_unpacklo_epi64(_mm_unpacklo_epi32(lane(at[0]), lane(at[1])),
                            _mm_unpacklo_epi32(lane(at[2]), lane(at[3])));
}
// Two lanes' pairs: base[at[0]], base[at[0] + 1], base[at[1]], base[at[1] + 1].
[[gnu::target("avx2")]] inline __m128i load_pairs2(const int32_t* base, const int32_t* at) {
  return _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + at[0])),
                            _mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + at[1])));
}
[[gnu::target("avx2")]] inline __m256i join(__m128i low, __m128i high) {
  return _mm256_inserti128_si256(_mm256_castsi128_si256(low), high, 1);
}
[[gnu::target("avx512f")]] inline __m512i join(__m256i low, __m256i high) {
  // (A vector shuffle, not the cast intrinsic, whose undefined upper half GCC 12 reports.)
  using V = Native<8>::I;
  return __m512i(__builtin_shufflevector(V(low), V(high), 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12,
                                         13, 14, 15));
}

[[gnu::target("avx2")]] inline void gather_instruction(const int32_t* base,
                                                       const Native<8>::I& index, Native<8>::I& r) {
  r = Native<8>::I(_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), base, __m256i(index),
                                               _mm256_set1_epi32(-1), 4));
}
[[gnu::target("avx2")]] inline void gather_loads(const int32_t* base, const Native<8>::I& index,
                                                 Native<8>::I& r,
                                                 IndexRoute route = IndexRoute::kMemory) {
  alignas(32) int32_t at[8];
  index_lanes(index, route, at);
  r = Native<8>::I(join(load_lanes4(base, at), load_lanes4(base, at + 4)));
}
[[gnu::target("avx512f")]] inline void gather_instruction(const int32_t* base,
                                                          const Native<16>::I& index,
                                                          Native<16>::I& r) {
  r = Native<16>::I(_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), __mmask16(0xffff),
                                                __m512i(index), base, 4));
}
[[gnu::target("avx512f")]] inline void gather_loads(const int32_t* base, const Native<16>::I& index,
                                                    Native<16>::I& r,
                                                    IndexRoute = IndexRoute::kMemory) {
  alignas(64) int32_t at[16];
  store_halves(at, index);
  r = Native<16>::I(join(join(load_lanes4(base, at), load_lanes4(base, at + 4)),
                         join(load_lanes4(base, at + 8), load_lanes4(base, at + 12))));
}
[[gnu::target("avx2")]] inline void gather(const int32_t* base, const Native<8>::I& index,
                                           Native<8>::I& r,
                                           IndexRoute route = IndexRoute::kMemory) {
  if (loads_for_gathers<8>()) {
    gather_loads(base, index, r, route);
  } else {
    gather_instruction(base, index, r);
  }
}
[[gnu::target("avx512f")]] inline void gather(const int32_t* base, const Native<16>::I& index,
                                              Native<16>::I& r, IndexRoute = IndexRoute::kMemory) {
  if (loads_for_gathers<16>()) {
    gather_loads(base, index, r);
  } else {
    gather_instruction(base, index, r);
  }
}

// Asks the cache for base[at[lane] + ahead] for every fourth of `lanes` lanes (addresses formed
// as integers: they may lie past the table, which a prefetch never faults on). T: the table's
// element (the texels, or the row pairs of texture_simd.hpp).
template <class T>
inline void prefetch_every_fourth(const T* base, const int32_t* at, int ahead, int lanes = 16) {
  const uintptr_t start = reinterpret_cast<uintptr_t>(base);
  for (int lane = 0; lane < lanes; lane += 4) {
    const uintptr_t element = uintptr_t(int64_t(at[lane]) + ahead);
    _mm_prefetch(reinterpret_cast<const char*>(start + element * sizeof(T)), _MM_HINT_T0);
  }
}
// The 64-bit pairs base[index[i]], base[index[i] + 1] of every lane, in lane order: at 8 lanes
// a holds lanes 0 to 3, c the rest (gather_pair below sorts them into lo and hi).
[[gnu::target("avx2")]] inline void pairs_instruction(const int32_t* base,
                                                      const Native<8>::I& index, __m256i& a,
                                                      __m256i& c) {
  const auto* pairs = reinterpret_cast<const long long*>(base);
  __m256i i = __m256i(index);
  a = _mm256_i32gather_epi64(pairs, _mm256_castsi256_si128(i), 4);
  c = _mm256_i32gather_epi64(pairs, _mm256_extracti128_si256(i, 1), 4);
}
[[gnu::target("avx2")]] inline void pairs_loads(const int32_t* base, const Native<8>::I& index,
                                                __m256i& a, __m256i& c,
                                                IndexRoute route = IndexRoute::kMemory,
                                                int ahead = 0) {
  alignas(32) int32_t at[8];
  index_lanes(index, route, at);
  if (ahead != 0) prefetch_every_fourth(base, at, ahead, 8);
  a = join(load_pairs2(base, at), load_pairs2(base, at + 2));
  c = join(load_pairs2(base, at + 4), load_pairs2(base, at + 6));
}
// At 16 lanes both forms give the pairs already sorted: lo[i] = base[index[i]], hi[i] =
// base[index[i] + 1] (gather_pair takes them as they are, and the start-up timing times what
// gather_pair runs).
[[gnu::target("avx512f")]] inline void pairs_instruction(const int32_t* base,
                                                         const Native<16>::I& index, __m512i& lo,
                                                         __m512i& hi) {
  // The masked form with a zero source, and the index's halves by a vector shuffle: GCC 12's
  // header leaves the unmasked forms' sources uninitialised (a -Wmaybe-uninitialized warning
  // wherever this is inlined; GCC bug 105593).
  const __m512i zero = _mm512_setzero_si512();
  const Native<8>::I low = __builtin_shufflevector(index, index, 0, 1, 2, 3, 4, 5, 6, 7);
  const Native<8>::I high = __builtin_shufflevector(index, index, 8, 9, 10, 11, 12, 13, 14, 15);
  // a = lanes 0 to 7's pairs, c = lanes 8 to 15's (each pair two 32-bit elements, l then h)
  const __m512i a = _mm512_mask_i32gather_epi64(zero, 0xff, __m256i(low), base, 4);
  const __m512i c = _mm512_mask_i32gather_epi64(zero, 0xff, __m256i(high), base, 4);
  const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
  const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
  lo = _mm512_permutex2var_epi32(a, even, c);
  hi = _mm512_permutex2var_epi32(a, odd, c);
}
// The pairs sorted into lo and hi four lanes at a time, as they arrive (two unpacks), and then
// joined: a shorter way from the loads to lo and hi than joining the pairs whole and sorting them
// by two-source permutes (the sampler's texels wait on it; quad_grid phong + texture 1 % faster).
[[gnu::target("avx512f")]] inline void pairs_loads(const int32_t* base, const Native<16>::I& index,
                                                   __m512i& lo, __m512i& hi, int ahead = 0) {
  alignas(64) int32_t at[16];
  store_halves(at, index);
  if (ahead != 0) prefetch_every_fourth(base, at, ahead);
  auto pair = [&](int l) {
    return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + at[l]));
  };
  __m128i low4[4], high4[4];
  for (int g = 0; g < 4; ++g) {
    const __m128i p01 = _mm_unpacklo_epi32(pair(4 * g), pair(4 * g + 1));      // l0 l1 h0 h1
    const __m128i p23 = _mm_unpacklo_epi32(pair(4 * g + 2), pair(4 * g + 3));  // l2 l3 h2 h3
    low4[g] = _mm_unpacklo_epi64(p01, p23);
    high4[g] = _mm_unpackhi_epi64(p01, p23);
  }
  lo = join(join(low4[0], low4[1]), join(low4[2], low4[3]));
  hi = join(join(high4[0], high4[1]), join(high4[2], high4[3]));
}

// r[i] = table[index[i]] for a table of 16 floats, indices in [0, 16): a permute, no memory
// access per lane where the instruction set has one.
inline void lookup16(const float* table, const Native<4>::I& index, Native<4>::F& r) {
  for (int i = 0; i < 4; ++i) r[i] = table[index[i]];
}
[[gnu::target("avx2")]] inline void lookup16(const float* table, const Native<8>::I& index,
                                             Native<8>::F& r) {
  __m256i i = __m256i(index);
  __m256 lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(table), i);  // index & 7
  __m256 hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(table + 8), i);
  __m256 upper = _mm256_castsi256_ps(_mm256_slli_epi32(i, 28));  // index & 8 in the sign bit
  r = Native<8>::F(_mm256_blendv_ps(lo, hi, upper));
}
[[gnu::target("avx512f")]] inline void lookup16(const float* table, const Native<16>::I& index,
                                                Native<16>::F& r) {
  // The zero-masked form: GCC 12's unmasked one starts from _mm512_undefined_ps, which its
  // -Wmaybe-uninitialized reports (bug 105593).
  r = Native<16>::F(
      _mm512_maskz_permutexvar_ps(__mmask16(0xffff), __m512i(index), _mm512_loadu_ps(table)));
}

// Each lane as two int16 halves: (a * b + 2^14) >> 15 half by half, the product rounded to 15
// fraction bits (PMULHRSW, which SSE2 lacks: there the same integers from the product's halves).
// Neither product may be (-2^15)^2.
inline void mul_round15(const Native<4>::I& a, const Native<4>::I& b, Native<4>::I& r) {
  // With p = hi * 2^16 + lo (lo unsigned), (p + 2^14) >> 15 = 2 hi + ((lo >> 1) + 2^13) >> 14.
  __m128i x = __m128i(a), y = __m128i(b);
  __m128i hi = _mm_mulhi_epi16(x, y), lo = _mm_mullo_epi16(x, y);
  __m128i carry = _mm_srli_epi16(_mm_add_epi16(_mm_srli_epi16(lo, 1), _mm_set1_epi16(0x2000)), 14);
  r = Native<4>::I(_mm_add_epi16(_mm_add_epi16(hi, hi), carry));
}
[[gnu::target("avx2")]] inline void mul_round15(const Native<8>::I& a, const Native<8>::I& b,
                                                Native<8>::I& r) {
  r = Native<8>::I(_mm256_mulhrs_epi16(__m256i(a), __m256i(b)));
}
[[gnu::target("avx512bw")]] inline void mul_round15(const Native<16>::I& a, const Native<16>::I& b,
                                                    Native<16>::I& r) {
  r = Native<16>::I(_mm512_mulhrs_epi16(__m512i(a), __m512i(b)));
}

// lo[i] = base[index[i]] and hi[i] = base[index[i] + 1]: two neighbouring 32-bit elements per
// lane with one 64-bit load (half the loads of two gathers).
inline void gather_pair(const int32_t* base, const Native<4>::I& index, Native<4>::I& lo,
                        Native<4>::I& hi, IndexRoute = IndexRoute::kMemory) {
  for (int i = 0; i < 4; ++i) {
    int32_t v[2];
    std::memcpy(v, base + index[i], sizeof v);
    lo[i] = v[0];
    hi[i] = v[1];
  }
}
// `ahead` (not 0): with one load per lane, also prefetch_every_fourth (the texture sampler's
// rows read on to the right).
[[gnu::target("avx2")]] inline void gather_pair(const int32_t* base, const Native<8>::I& index,
                                                Native<8>::I& lo, Native<8>::I& hi,
                                                IndexRoute route = IndexRoute::kMemory,
                                                int ahead = 0) {
  // a = l0 h0 l1 h1 | l2 h2 l3 h3, c = l4 h4 l5 h5 | l6 h6 l7 h7 (32-bit elements)
  __m256i ai, ci;
  if (loads_for_gathers<8>()) {
    pairs_loads(base, index, ai, ci, route, ahead);
  } else {
    pairs_instruction(base, index, ai, ci);
  }
  __m256 a = _mm256_castsi256_ps(ai), c = _mm256_castsi256_ps(ci);
  // Even elements (l0 l1 l4 l5 | l2 l3 l6 l7), odd ones likewise, then the 64-bit pieces in order.
  __m256 l = _mm256_shuffle_ps(a, c, 0x88), h = _mm256_shuffle_ps(a, c, 0xdd);
  lo = Native<8>::I(_mm256_permute4x64_epi64(_mm256_castps_si256(l), 0xd8));
  hi = Native<8>::I(_mm256_permute4x64_epi64(_mm256_castps_si256(h), 0xd8));
}
// `ahead` (not 0): with one load per lane, also prefetch_every_fourth (the texture sampler's
// rows read on to the right; the gather instruction's form leaves it out).
[[gnu::target("avx512f")]] inline void gather_pair(const int32_t* base, const Native<16>::I& index,
                                                   Native<16>::I& lo, Native<16>::I& hi,
                                                   IndexRoute = IndexRoute::kMemory,
                                                   int ahead = 0) {
  __m512i l, h;
  if (loads_for_gathers<16>()) {
    pairs_loads(base, index, l, h, ahead);
  } else {
    pairs_instruction(base, index, l, h);
  }
  lo = Native<16>::I(l);
  hi = Native<16>::I(h);
}

}  // namespace isa

template <int N>
SOFTRAST_SIMD_INLINE Float<N> min(const Float<N>& a, const Float<N>& b) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::min(a.p[k], b.p[k], r.p[k]);
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Float<N> max(const Float<N>& a, const Float<N>& b) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::max(a.p[k], b.p[k], r.p[k]);
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE Float<N> clamp(const Float<N>& v, const Float<N>& lo, const Float<N>& hi) {
  return max(lo, min(hi, v));
}

// IEEE square root, exact in every lane (as std::sqrt).
template <int N>
SOFTRAST_SIMD_INLINE Float<N> sqrt(const Float<N>& a) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::sqrt(a.p[k], r.p[k]);
  return r;
}

// a * b + c, rounded once where the level has FMA (isa::fmadd): for lighting and the like, whose
// results may differ by a bit between levels, never for coverage, depth or texel addresses.
template <int N>
SOFTRAST_SIMD_INLINE Float<N> fma(const Float<N>& a, const Float<N>& b, const Float<N>& c) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::fmadd(a.p[k], b.p[k], c.p[k], r.p[k]);
  return r;
}

// 1 / sqrt(a) within a few units in the last place (the estimate and one Newton step), for
// positive finite a (0 gives NaN). Much faster than 1 / sqrt(a): the square
// root and the division share one divider that takes a 16-lane operation every 10 to 16 cycles,
// while these are multiplications. Not the same bits at every SIMD level.
template <int N>
SOFTRAST_SIMD_INLINE Float<N> rsqrt(const Float<N>& a) {
  Float<N> y;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::rsqrt_estimate(a.p[k], y.p[k]);
  const Float<N> half_a_y = Float<N>(0.5f) * a * y;
  return y * fma(-half_a_y, y, Float<N>(1.5f));
}

// Bit i set where lane i of the mask is set (its sign bit).
template <int N>
SOFTRAST_SIMD_INLINE uint32_t bits(const Int<N>& mask) {
  uint32_t r = 0;
  for (int k = 0; k < Int<N>::kParts; ++k) r |= uint32_t(isa::sign_bits(mask.p[k])) << (k * N);
  return r;
}
template <int N>
SOFTRAST_SIMD_INLINE bool any(const Int<N>& mask) {
  return bits(mask) != 0;
}

// Lane i = base[index[i]]; every index must be valid.
template <int N>
SOFTRAST_SIMD_INLINE Int<N> gather(const int32_t* base, const Int<N>& index,
                                   IndexRoute route = IndexRoute::kMemory) {
  Int<N> r;
  for (int k = 0; k < Int<N>::kParts; ++k) isa::gather(base, index.p[k], r.p[k], route);
  return r;
}

// Lane i: table[index[i]], for a table of 16 floats and every index in [0, 16).
template <int N>
SOFTRAST_SIMD_INLINE Float<N> lookup16(const float* table, const Int<N>& index) {
  Float<N> r;
  for (int k = 0; k < Float<N>::kParts; ++k) isa::lookup16(table, index.p[k], r.p[k]);
  return r;
}

// Lane i of lo = base[index[i]], of hi = base[index[i] + 1]; both must be valid. `ahead`, at 8
// lanes: isa::gather_pair's (the 16-lane kernels call theirs directly).
template <int N>
SOFTRAST_SIMD_INLINE void gather_pair(const int32_t* base, const Int<N>& index, Int<N>& lo,
                                      Int<N>& hi, IndexRoute route = IndexRoute::kMemory,
                                      int ahead = 0) {
  for (int k = 0; k < Int<N>::kParts; ++k) {
    if constexpr (N == 8) {
      isa::gather_pair(base, index.p[k], lo.p[k], hi.p[k], route, ahead);
    } else {
      isa::gather_pair(base, index.p[k], lo.p[k], hi.p[k], route);
    }
  }
}

// Lane constants, loaded as vectors (GCC builds a vector lane by lane otherwise).
alignas(64) inline constexpr uint32_t kLaneToSign[kLanes] = {
    1u << 31, 1u << 30, 1u << 29, 1u << 28, 1u << 27, 1u << 26, 1u << 25, 1u << 24,
    1u << 23, 1u << 22, 1u << 21, 1u << 20, 1u << 19, 1u << 18, 1u << 17, 1u << 16};
alignas(64) inline constexpr int32_t kLaneColumn[kLanes] = {0, 1, 2, 3, 0, 1, 2, 3,
                                                            0, 1, 2, 3, 0, 1, 2, 3};
alignas(64) inline constexpr int32_t kLaneRow[kLanes] = {0, 0, 0, 0, 1, 1, 1, 1,
                                                         2, 2, 2, 2, 3, 3, 3, 3};
// The lane of the top-left pixel of each lane's 2x2 quad (lane & ~(1 | 4)).
alignas(64) inline constexpr int32_t kLaneQuadTopLeft[kLanes] = {0, 0, 2,  2,  0, 0, 2,  2,
                                                                 8, 8, 10, 10, 8, 8, 10, 10};

// The lane mask of a 16-bit block mask. Masks are read by their sign bit everywhere (select,
// bits, and/or), so lane i only needs bit i of `mask` moved to bit 31: a multiplication by
// 2^(31 - i), with no comparison (GCC 12 splits some AVX-512 comparisons into lanes). At AVX-512
// the mask goes into a mask register and out as whole lanes (two instructions, where the
// multiplication's latency is ten cycles).
template <int N>
SOFTRAST_SIMD_INLINE Int<N> lanes_of(uint32_t mask) {
  Int<N> out;
  if constexpr (N == 16) {
    isa::lanes_of(mask, out.p[0]);
  } else {
    using U = typename Native<N>::U;
    Int<N> m = Int<N>(int32_t(mask));
    for (int k = 0; k < Int<N>::kParts; ++k) {
      U scale = U(*reinterpret_cast<const typename Native<N>::IU*>(kLaneToSign + k * N));
      out.p[k] = typename Native<N>::I(U(m.p[k]) * scale);
    }
  }
  return out;
}
// Column (0..3) and row (0..3) of each lane within the block.
template <int N>
SOFTRAST_SIMD_INLINE Int<N> lane_column() {
  return Int<N>::load(kLaneColumn);
}
template <int N>
SOFTRAST_SIMD_INLINE Int<N> lane_row() {
  return Int<N>::load(kLaneRow);
}

// ---- Small vectors of wide values, with glm's names. ----

template <int N>
struct Vec2 {
  Float<N> x, y;
};
template <int N>
struct Vec3 {
  Float<N> x, y, z;
  SOFTRAST_SIMD_INLINE friend Vec3 operator+(const Vec3& a, const Vec3& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
  }
  SOFTRAST_SIMD_INLINE friend Vec3 operator-(const Vec3& a, const Vec3& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
  }
  SOFTRAST_SIMD_INLINE friend Vec3 operator*(const Vec3& a, const Vec3& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
  }
  SOFTRAST_SIMD_INLINE friend Vec3 operator*(const Vec3& a, const Float<N>& s) {
    return {a.x * s, a.y * s, a.z * s};
  }
  SOFTRAST_SIMD_INLINE friend Vec3 operator*(const Float<N>& s, const Vec3& a) {
    return {s * a.x, s * a.y, s * a.z};
  }
  SOFTRAST_SIMD_INLINE friend Vec3 operator+(const Vec3& a, const Float<N>& s) {
    return {a.x + s, a.y + s, a.z + s};
  }
};
template <int N>
struct Vec4 {
  Float<N> x, y, z, w;
};

// A wide vector from a glm-like constant (anything with x, y, z).
template <int N, class V3>
SOFTRAST_SIMD_INLINE Vec3<N> splat3(const V3& v) {
  return {Float<N>(v.x), Float<N>(v.y), Float<N>(v.z)};
}

// a.x * b.x + a.y * b.y + a.z * b.z, the last two multiply-adds fused where the level has FMA
// (simd::fma): may differ from glm::dot in the last bit there.
template <int N>
SOFTRAST_SIMD_INLINE Float<N> dot(const Vec3<N>& a, const Vec3<N>& b) {
  return fma(a.z, b.z, fma(a.y, b.y, a.x * b.x));
}
// v / |v| exactly as glm::normalize computes it, at every level: v * (1 / sqrt(dot(v, v))), the
// dot product's sums rounded one by one.
template <int N>
SOFTRAST_SIMD_INLINE Vec3<N> normalize(const Vec3<N>& v) {
  Float<N> inv = Float<N>(1.0f) / sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return v * inv;
}
// v / |v| through rsqrt: within a few units in the last place of normalize, without the divider
// (what the built-in lighting uses; GPUs normalize this way too). A zero vector gives NaN, as
// normalize does.
template <int N>
SOFTRAST_SIMD_INLINE Vec3<N> normalize_fast(const Vec3<N>& v) {
  return v * rsqrt(dot(v, v));
}

}  // namespace softrast::simd

#pragma GCC diagnostic pop
