// softrast/detail/texture_simd.hpp: texture sampling for wide shaders, 16 lanes at once, with
// the same arithmetic in the same order as Texture::sample (so both give the same bits).
// Internal: included through softrast/shader.hpp; shaders call softrast::sample().
#pragma once

// Wide vectors are passed by value between inlined helpers; GCC notes that the ABI of such
// parameters changed in GCC 4.6, which cannot matter here (nothing crosses a library boundary).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "softrast/simd.hpp"
#include "softrast/texture.hpp"

namespace softrast {
namespace detail {

// The sampler's gathers take their indices out of the vector by extracts (simd::IndexRoute).
inline constexpr simd::IndexRoute kTexelRoute = simd::IndexRoute::kRegisters;

// texel_floor for 16 lanes: floor(x) and x - floor(x); NaN and |x| >= 1e9 give texel 0, 0.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> texel_floor(const simd::Float<N>& x, simd::Float<N>& fraction) {
  using F = simd::Float<N>;
  simd::Int<N> ok = (x > F(-1.0e9f)) & (x < F(1.0e9f));
  F xs = simd::select(ok, x, F(0.0f));
  if constexpr (N == 8) {
    // The floor instruction: the same whole part (exact in float below 1e9), so the same texel
    // and fraction (of -0: +0 here, -0 below; both weigh 0).
    F whole;
    for (int k = 0; k < F::kParts; ++k) simd::isa::floor(xs.p[k], whole.p[k]);
    fraction = xs - whole;
    return simd::to_int(whole);
  }
  simd::Int<N> i = simd::to_int(xs);  // truncates towards zero
  i = i + (simd::to_float(i) > xs);   // the mask is -1 where truncation went up
  fraction = xs - simd::to_float(i);
  return i;
}

// floor(x) for |x| < 2^22 (truncation, one down where it went up).
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> floor_of(const simd::Float<N>& x) {
  simd::Float<N> t = simd::to_float(simd::to_int(x));
  return simd::select(t > x, t - simd::Float<N>(1.0f), t);
}

// Wraps texel indices into [0, size) per lane (sizes may differ by lane: mip levels).
// `pow2` says every lane's size is a power of two.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> wrap_texel(Wrap mode, const simd::Int<N>& i,
                                             const simd::Int<N>& size, bool pow2) {
  using I = simd::Int<N>;
  if (mode == Wrap::kClampToEdge) {
    I last = size - I(1);
    return simd::select(i < I(0), I(0), simd::select(i > last, last, i));
  }
  if (mode == Wrap::kRepeat && pow2) return i & (size - I(1));
  // Repeat of other sizes and mirrored repeat: i mod period in float where every |i| < 2^22 (the
  // quotient's floor is then off by at most one, which the two selects put right; periods are
  // below 2^16), else the scalar rule lane by lane, out of line (inlined into every sampling site
  // of every shader it made each shader's code several times larger).
  const I period = mode == Wrap::kMirroredRepeat ? size + size : size;
  if (!simd::any((i > I((1 << 22) - 1)) | (i < I(1 - (1 << 22))))) {
    using F = simd::Float<N>;
    F p = simd::to_float(period);
    I m = i - simd::to_int(floor_of<N>(simd::to_float(i) / p)) * period;
    m = simd::select(m < I(0), m + period, m);
    m = simd::select(m > period - I(1), m - period, m);
    if (mode == Wrap::kRepeat) return m;
    return simd::select(m < size, m, period - I(1) - m);
  }
  alignas(64) int32_t lanes[simd::kLanes], sizes[simd::kLanes];
  i.store(lanes);
  size.store(sizes);
  Texture::wrap_lanes(mode, lanes, sizes, simd::kLanes);
  return I::load(lanes);
}

// RGBA8 texels to channels in [0, 1]; `decode`: RGB through the sRGB decode table
// (Texture::decodes).
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> unpack_texel(const simd::Int<N>& texel, bool decode) {
  using F = simd::Float<N>;
  const F k(1.0f / 255.0f);
  simd::Int<N> byte(0xff);
  if (decode) {
    const int32_t* table = reinterpret_cast<const int32_t*>(srgb_decode_table());
    return {simd::bit_cast_float(simd::gather<N>(table, texel & byte, kTexelRoute)),
            simd::bit_cast_float(simd::gather<N>(table, (texel >> 8) & byte, kTexelRoute)),
            simd::bit_cast_float(simd::gather<N>(table, (texel >> 16) & byte, kTexelRoute)),
            simd::to_float(texel >> 24) * k};
  }
  return {simd::to_float(texel & byte) * k, simd::to_float((texel >> 8) & byte) * k,
          simd::to_float((texel >> 16) & byte) * k, simd::to_float(texel >> 24) * k};
}

// Texture::filter_weight, lane by lane (a named function: see pack_channel in shade_simd.hpp).
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> filter_weight(const simd::Float<N>& f) {
  simd::Int<N> w = simd::to_int(f * simd::Float<N>(32768.0f) + simd::Float<N>(0.5f));
  return simd::min(w, simd::Int<N>(32767));
}

// A texel's even bytes (half 0) or odd bytes (half 1) as levels in the 16-bit halves of its lane:
// (t >> 8 * half) & 0x00ff00ff, times 128 (the odd bytes in two operations: t >> 1, masked). A
// named always-inline function, not a lambda, which would be compiled for the baseline with its
// vectors in another ABI (see shade_simd.hpp's pack_channel).
// (The result by reference: a vector returned by value draws GCC's -Wpsabi note in the baseline
// translation units.)
template <class V>
SOFTRAST_SIMD_INLINE void texel_levels(const V& t, int half, V& out) {
  out = half == 0 ? (t & 0x00ff00ff) << 7 : (t >> 1) & 0x7f807f80;
}

// GL_LINEAR of four RGBA8 texels per lane (b0, b1: the lower row, t0, t1: the upper one),
// Texture::filter_rgba8's integers: the channels in the 16-bit halves of each lane (red and blue
// in `red_blue`, green and alpha in `green_alpha`), each a level with 7 fraction bits (0 to
// 255 * 128), blended by simd::isa::mul_round15 (PMULHRSW).
template <int N>
SOFTRAST_SIMD_INLINE void filter_levels(const simd::Int<N>& b0, const simd::Int<N>& b1,
                                        const simd::Int<N>& t0, const simd::Int<N>& t1,
                                        const simd::Float<N>& fx, const simd::Float<N>& fy,
                                        simd::Int<N>& red_blue, simd::Int<N>& green_alpha) {
  using I = simd::Int<N>;
  using V = typename simd::Native<N>::I;
  typedef int16_t H __attribute__((vector_size(sizeof(V))));
  const I wx = filter_weight<N>(fx), wy = filter_weight<N>(fy);
  for (int k = 0; k < I::kParts; ++k) {
    const V x = wx.p[k] | (wx.p[k] << 16), y = wy.p[k] | (wy.p[k] << 16);  // in both halves
    for (int half = 0; half < 2; ++half) {  // red and blue, then green and alpha
      // Levels with 7 fraction bits: at most 255 * 128 = 32640, so differences fit in int16.
      V levels[4];
      texel_levels(b0.p[k], half, levels[0]);
      texel_levels(b1.p[k], half, levels[1]);
      texel_levels(t0.p[k], half, levels[2]);
      texel_levels(t1.p[k], half, levels[3]);
      H lb = H(levels[0]), rb = H(levels[1]), lt = H(levels[2]), rt = H(levels[3]);
      V d;
      simd::isa::mul_round15(V(rb - lb), x, d);
      H bottom = lb + H(d);
      simd::isa::mul_round15(V(rt - lt), x, d);
      H top = lt + H(d);
      simd::isa::mul_round15(V(top - bottom), y, d);
      (half == 0 ? red_blue : green_alpha).p[k] = V(bottom + H(d));
    }
  }
}

// filter_levels as channels in [0, 1]: Texture::filter_rgba8's result.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> filter_rgba8(const simd::Int<N>& b0, const simd::Int<N>& b1,
                                                const simd::Int<N>& t0, const simd::Int<N>& t1,
                                                const simd::Float<N>& fx,
                                                const simd::Float<N>& fy) {
  using I = simd::Int<N>;
  using V = typename simd::Native<N>::I;
  using Fn = typename simd::Native<N>::F;
  I red_blue, green_alpha;
  filter_levels<N>(b0, b1, t0, t1, fx, fy, red_blue, green_alpha);
  simd::Vec4<N> out;
  for (int k = 0; k < I::kParts; ++k) {
    for (int half = 0; half < 2; ++half) {
      const V v = (half == 0 ? red_blue : green_alpha).p[k];
      // (v / 128) * (1 / 255) as Texture::texel computes it, in one multiplication: v / 128 is
      // exact, and so is (1 / 255) / 128 (both scale by a power of two), so v times the latter
      // rounds the same real number once, as the two multiplications do.
      const Fn to_unit = Fn{} + (1.0f / 255.0f) * (1.0f / 128.0f);
      Fn low = __builtin_convertvector(v & 0xffff, Fn) * to_unit;
      Fn high = __builtin_convertvector(v >> 16, Fn) * to_unit;
      (half == 0 ? out.x : out.y).p[k] = low;
      (half == 0 ? out.z : out.w).p[k] = high;
    }
  }
  return out;
}

// filter_levels packed as RGBA8, exactly what pack_rgba8 (shade_simd.hpp) makes of filter_rgba8's
// channels: for a level v, trunc(min(max((v / 128) / 255, 0), 1) * 255 + 0.5) in float is
// (v + 64) >> 7 (v / 128 rounded half up) for every v from 0 to 255 * 128, which the sampler
// tests confirm lane by lane. Both channels of a lane at once: no carry crosses the halves (v +
// 64 < 2^15), and the mask drops what the shift brings down from the upper half.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> filter_rgba8_packed(
    const simd::Int<N>& b0, const simd::Int<N>& b1, const simd::Int<N>& t0, const simd::Int<N>& t1,
    const simd::Float<N>& fx, const simd::Float<N>& fy) {
  using I = simd::Int<N>;
  I red_blue, green_alpha;
  filter_levels<N>(b0, b1, t0, t1, fx, fy, red_blue, green_alpha);
  // Green and alpha go to bytes 1 and 3: ((v >> 7) & 0x00ff00ff) << 8 is (v << 1) & 0xff00ff00
  // (the same bits 7 to 14 of each half, moved up by 1), one shift less on the way to the store.
  const I round(0x00400040), bytes(0x00ff00ff), odd_bytes(int32_t(0xff00ff00u));
  return (((red_blue + round) >> 7) & bytes) | (((green_alpha + round) << 1) & odd_bytes);
}

// How far along its texel row the sampler asks the cache for texels beyond each of a block's
// rows, where it reads each row's two texels with one 64-bit load (simd::gather_pair's `ahead`,
// on both rows of the filter, from every fourth lane). A triangle's blocks come left to right, so
// its next blocks read on along those rows, and where the texture outgrows the L2 cache
// (quad_grid's 1024x1024, read over several repeats) their lines would come from L3 while a block
// waits. 32 texels (two lines) measured faster than 16 and 64 at AVX-512 (the same as 16 and
// faster than 64 at AVX2, where it made quad_grid texture 12 % faster); aiming at the next
// block's own texels (from the block's change across its row) measured no faster than none.
inline constexpr int kTexelsAhead = 32;
// The same for the row pairs, in pairs (eight to a line): as many lines ahead.
inline constexpr int kPairsAhead = 16;

// Asks the cache for the pairs kPairsAhead on from every fourth of `lanes` lanes' pair `lane[l]`.
inline void prefetch_pairs_ahead(const int64_t* pairs, const int32_t* lane, int lanes) {
  simd::isa::prefetch_every_fourth(pairs, lane, kPairsAhead, lanes);
}

// The common bilinear sample at AVX-512, inlined into the 16-lane shaders: the base level of an
// RGBA8 texture without sRGB decode, each axis clamped to the edge or repeated over a power-of-two
// size. The arithmetic is sample_level's, the same operations in the same order (so the same
// bits); the way there is shorter: the floor instruction in place of texel_floor's truncate,
// compare and correct, a mask or a clamp in place of the generic wrap, comparisons straight into
// mask registers. Inlined, a sample saves the call's spills of the shader's live vectors and
// the lanes' round trip through memory (SampleLanes); the other cases stay out of line.
namespace avx512 {

#define SOFTRAST_AVX512_SAMPLER [[gnu::target("avx512f,avx512bw,avx512dq,avx512vl")]] inline

// texel_floor: floor(x) and x - floor(x); NaN and |x| >= 1e9 give texel 0, fraction 0. (The
// fraction of -0 comes out +0 here and -0 there; both give the weight 0.) The range test runs
// beside the rounding and masks its results, so the texel addresses, which the block's time
// follows, do not wait for it (quad_grid texture 2 % faster than masking x first). Here and
// below, the masked forms of the intrinsics and GCC's vector operators: the unmasked intrinsics
// of GCC 12's header leave a variable uninitialised, which -Wmaybe-uninitialized reports at every
// inlining site (GCC bug 105593, fixed in GCC 13).
SOFTRAST_AVX512_SAMPLER __m512i floor16(__m512 x, __m512& fraction) {
  __mmask16 ok = _mm512_cmp_ps_mask(x, _mm512_set1_ps(-1.0e9f), _CMP_GT_OQ) &
                 _mm512_cmp_ps_mask(x, _mm512_set1_ps(1.0e9f), _CMP_LT_OQ);
  __m512 whole =
      _mm512_maskz_roundscale_ps(__mmask16(0xffff), x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  fraction = _mm512_maskz_sub_ps(ok, x, whole);
  const __m512i i = _mm512_maskz_cvttps_epi32(__mmask16(0xffff), whole);
  return _mm512_maskz_mov_epi32(ok, i);
}

// wrap_texel for the two modes bilinear_texels16 takes (`last`: the size minus one, a power of
// two minus one when repeating).
SOFTRAST_AVX512_SAMPLER __m512i wrap_clamp_or_repeat16(bool repeat, __m512i i, int last) {
  using V = simd::Native<16>::I;
  V x = V(i);
  if (!repeat) {
    x = x < 0 ? V{} : x;
    return __m512i(x > last ? V{} + last : x);
  }
  return __m512i(x & last);
}

// The four texels of each lane from its rows' first texels and its two columns: one 64-bit load
// per lane and row where no lane wraps between its columns (sample_level), else four gathers.
// `ahead`: kTexelsAhead in the first case. (Also the out-of-line kernel's, sample_kernels.cpp,
// without it.)
SOFTRAST_AVX512_SAMPLER void gather_bilinear16(
    const int32_t* texels, const simd::Native<16>::I& row0, const simd::Native<16>::I& row1,
    const simd::Native<16>::I& i0, const simd::Native<16>::I& i1, simd::Native<16>::I& b0,
    simd::Native<16>::I& b1, simd::Native<16>::I& t0, simd::Native<16>::I& t1, bool ahead = false) {
  if (_mm512_cmpneq_epi32_mask(__m512i(i1), __m512i(i0 + 1)) == 0) {
    const int lead = ahead ? kTexelsAhead : 0;
    simd::isa::gather_pair(texels, row0 + i0, b0, b1, simd::IndexRoute::kMemory, lead);
    simd::isa::gather_pair(texels, row1 + i0, t0, t1, simd::IndexRoute::kMemory, lead);
    return;
  }
  simd::isa::gather(texels, row0 + i0, b0);
  simd::isa::gather(texels, row0 + i1, b1);
  simd::isa::gather(texels, row1 + i0, t0);
  simd::isa::gather(texels, row1 + i1, t1);
}

// The row pair (Texture::row_pairs) of each lane's lower row y0, for rows up to `last`: clamped,
// y0 within [-1, last] names both rows; repeated over a power of two, y0 & last does, except on
// the last row, whose upper row wraps to row 0 (those lanes set in `wraps`, to be gathered).
SOFTRAST_AVX512_SAMPLER simd::Native<16>::I pair_row16(bool repeat, simd::Native<16>::I y0,
                                                       simd::Native<16>::I last, __mmask16& wraps) {
  using V = simd::Native<16>::I;
  wraps = 0;
  if (repeat) {
    const V r = y0 & last;
    wraps = _mm512_cmpeq_epi32_mask(__m512i(r), __m512i(last));
    return r;
  }
  const V r = y0 < -1 ? V{} - 1 : y0;
  return r > last ? last : r;
}

// The four texels of every lane from the row pairs (Texture::row_pairs), where each lane's
// columns are neighbours: one 128-bit load per lane at its pair `at` holds b0, t0, b1 and t1, and
// a 4x4 transpose within each 128-bit part sorts them into the four vectors (as the triangle
// setup's load_quads: part c of vector m gathers lane 4c + m). Half the loads of two rows of
// 64-bit pairs, and no sorting of the pairs after them.
SOFTRAST_AVX512_SAMPLER void load_row_pairs16(const int64_t* pairs, const simd::Native<16>::I& at,
                                              simd::Native<16>::I& b0, simd::Native<16>::I& b1,
                                              simd::Native<16>::I& t0, simd::Native<16>::I& t1) {
  alignas(64) int32_t lane[16];
  _mm512_store_si512(lane, __m512i(at));
  prefetch_pairs_ahead(pairs, lane, 16);
  auto quad = [&](int l) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(pairs + lane[l]));
  };
  __m512i m[4];
  for (int k = 0; k < 4; ++k) {
    const __m256i low = _mm256_inserti128_si256(_mm256_castsi128_si256(quad(k)), quad(k + 4), 1);
    const __m256i high =
        _mm256_inserti128_si256(_mm256_castsi128_si256(quad(k + 8)), quad(k + 12), 1);
    m[k] = _mm512_maskz_inserti64x4(__mmask8(0xff), _mm512_castsi256_si512(low), high, 1);
  }
  const __mmask16 all = 0xffff;
  const __m512i a = _mm512_maskz_unpacklo_epi32(all, m[0], m[1]);
  const __m512i b = _mm512_maskz_unpackhi_epi32(all, m[0], m[1]);
  const __m512i c = _mm512_maskz_unpacklo_epi32(all, m[2], m[3]);
  const __m512i d = _mm512_maskz_unpackhi_epi32(all, m[2], m[3]);
  b0 = simd::Native<16>::I(_mm512_maskz_unpacklo_epi64(__mmask8(0xff), a, c));
  t0 = simd::Native<16>::I(_mm512_maskz_unpackhi_epi64(__mmask8(0xff), a, c));
  b1 = simd::Native<16>::I(_mm512_maskz_unpacklo_epi64(__mmask8(0xff), b, d));
  t1 = simd::Native<16>::I(_mm512_maskz_unpackhi_epi64(__mmask8(0xff), b, d));
}

// The four texels (bilinear_texels) and the weights' fractions of 16 lanes in the common case
// (BilinearPlan, texture.hpp). Everything by reference: a caller compiled for the baseline (a
// test, say) that does not inline this would pass 64-byte vectors in memory where it expects
// registers.
SOFTRAST_AVX512_SAMPLER void bilinear_texels16(const BilinearPlan& p, const simd::Vec2<16>& uv,
                                               simd::Int<16>& b0, simd::Int<16>& b1,
                                               simd::Int<16>& t0, simd::Int<16>& t1,
                                               simd::Float<16>& fxl, simd::Float<16>& fyl) {
  using V = simd::Native<16>::I;
  const __m512 u = __m512(uv.x.p[0]), v = __m512(uv.y.p[0]);
  __m512 fx, fy;
  __m512i x0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(u, _mm512_set1_ps(p.width)), _mm512_set1_ps(0.5f)), fx);
  __m512i y0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(v, _mm512_set1_ps(p.height)), _mm512_set1_ps(0.5f)), fy);
  const __m512i one = _mm512_set1_epi32(1);
  V i0 = V(wrap_clamp_or_repeat16(p.repeat_u, x0, p.last_u));
  V i1 = V(wrap_clamp_or_repeat16(p.repeat_u, _mm512_add_epi32(x0, one), p.last_u));
  fxl.p[0] = simd::Native<16>::F(fx);
  fyl.p[0] = simd::Native<16>::F(fy);
  if (p.pairs != nullptr) {
    // The row pairs (Texture::row_pairs), read where no lane's columns or rows wrap.
    __mmask16 wraps;
    const V r = pair_row16(p.repeat_v, V(y0), V{} + p.last_v, wraps);
    if ((_mm512_cmpneq_epi32_mask(__m512i(i1), __m512i(i0 + 1)) | wraps) == 0) {
      const V at = (p.row_shift >= 0 ? r << p.row_shift : r * p.row_width) + i0;
      load_row_pairs16(p.pairs, at, b0.p[0], b1.p[0], t0.p[0], t1.p[0]);
      return;
    }
  }
  V j0 = V(wrap_clamp_or_repeat16(p.repeat_v, y0, p.last_v));
  V j1 = V(wrap_clamp_or_repeat16(p.repeat_v, _mm512_add_epi32(y0, one), p.last_v));
  V row0, row1;
  if (p.row_shift >= 0) {
    row0 = j0 << p.row_shift;
    row1 = j1 << p.row_shift;
  } else {
    row0 = j0 * p.row_width;
    row1 = j1 * p.row_width;
  }
  gather_bilinear16(p.texels, row0, row1, i0, i1, b0.p[0], b1.p[0], t0.p[0], t1.p[0], true);
}

#undef SOFTRAST_AVX512_SAMPLER

}  // namespace avx512

// The row pairs (Texture::row_pairs) of 8 lanes at AVX2, as load_row_pairs16 reads 16: one
// 128-bit load per lane at its pair `at` holds b0, t0, b1 and t1, and a 4x4 transpose within each
// 128-bit part sorts them (part c of vector m gathers lane 4c + m); the pairs kPairsAhead on from
// every fourth lane are asked for.
[[gnu::target("avx2")]] inline void load_row_pairs8(const int64_t* pairs,
                                                    const simd::Native<8>::I& at,
                                                    simd::Native<8>::I& b0, simd::Native<8>::I& b1,
                                                    simd::Native<8>::I& t0,
                                                    simd::Native<8>::I& t1) {
  alignas(32) int32_t lane[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lane), __m256i(at));
  prefetch_pairs_ahead(pairs, lane, 8);
  auto quad = [&](int l) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(pairs + lane[l]));
  };
  __m256i m[4];
  for (int k = 0; k < 4; ++k) {
    m[k] = _mm256_inserti128_si256(_mm256_castsi128_si256(quad(k)), quad(k + 4), 1);
  }
  const __m256i a = _mm256_unpacklo_epi32(m[0], m[1]), b = _mm256_unpackhi_epi32(m[0], m[1]);
  const __m256i c = _mm256_unpacklo_epi32(m[2], m[3]), d = _mm256_unpackhi_epi32(m[2], m[3]);
  b0 = simd::Native<8>::I(_mm256_unpacklo_epi64(a, c));
  t0 = simd::Native<8>::I(_mm256_unpackhi_epi64(a, c));
  b1 = simd::Native<8>::I(_mm256_unpacklo_epi64(b, d));
  t1 = simd::Native<8>::I(_mm256_unpackhi_epi64(b, d));
}

// bilinear_texels for a BilinearPlan's case at AVX2 (8 lanes a register): the same texels and
// fractions, by the same operations; the rows by a shift where the width is a power of two, and
// from the row pairs (when the plan has them) where every lane's columns are neighbours and no
// repeated row wraps, as avx512::bilinear_texels16 reads them.
template <int N>
SOFTRAST_SIMD_INLINE void plan_texels(const BilinearPlan& p, const simd::Vec2<N>& uv,
                                      simd::Int<N>& b0, simd::Int<N>& b1, simd::Int<N>& t0,
                                      simd::Int<N>& t1, simd::Float<N>& fx, simd::Float<N>& fy) {
  static_assert(N == 8);
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  const I x0 = texel_floor<N>(uv.x * F(p.width) - F(0.5f), fx);
  const I y0 = texel_floor<N>(uv.y * F(p.height) - F(0.5f), fy);
  const I one(1);
  // The plan's modes are wrap_texel's clamp and power-of-two repeat.
  const Wrap wrap_u = p.repeat_u ? Wrap::kRepeat : Wrap::kClampToEdge;
  const Wrap wrap_v = p.repeat_v ? Wrap::kRepeat : Wrap::kClampToEdge;
  const I width(p.last_u + 1), height(p.last_v + 1);
  const I i0 = wrap_texel<N>(wrap_u, x0, width, true);
  const I i1 = wrap_texel<N>(wrap_u, x0 + one, width, true);
  const I neighbours = i1 == i0 + one;
  if (p.pairs != nullptr) {
    // The row pair of each lane's lower row (avx512::pair_row16).
    const I last(p.last_v);
    I r, wraps(0);
    if (p.repeat_v) {
      r = y0 & last;
      wraps = r == last;
    } else {
      r = simd::select(y0 < I(-1), I(-1), y0);
      r = simd::select(r > last, last, r);
    }
    if (simd::bits(neighbours & ~wraps) == 0xffffu) {
      const I at = (p.row_shift >= 0 ? r << p.row_shift : r * I(p.row_width)) + i0;
      for (int k = 0; k < I::kParts; ++k) {
        load_row_pairs8(p.pairs, at.p[k], b0.p[k], b1.p[k], t0.p[k], t1.p[k]);
      }
      return;
    }
  }
  const I j0 = wrap_texel<N>(wrap_v, y0, height, true);
  const I j1 = wrap_texel<N>(wrap_v, y0 + one, height, true);
  const I row0 = p.row_shift >= 0 ? j0 << p.row_shift : j0 * I(p.row_width);
  const I row1 = p.row_shift >= 0 ? j1 << p.row_shift : j1 * I(p.row_width);
  if (simd::bits(neighbours) == 0xffffu) {
    simd::gather_pair<N>(p.texels, row0 + i0, b0, b1, kTexelRoute, kTexelsAhead);
    simd::gather_pair<N>(p.texels, row1 + i0, t0, t1, kTexelRoute, kTexelsAhead);
    return;
  }
  b0 = simd::gather<N>(p.texels, row0 + i0, kTexelRoute);
  b1 = simd::gather<N>(p.texels, row0 + i1, kTexelRoute);
  t0 = simd::gather<N>(p.texels, row1 + i0, kTexelRoute);
  t1 = simd::gather<N>(p.texels, row1 + i1, kTexelRoute);
}

// Texel (i, j) of the level whose size and first texel are (w, h, offset), lane by lane.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> fetch(const Texture& t, const simd::Int<N>& i,
                                         const simd::Int<N>& j, const simd::Int<N>& w,
                                         const simd::Int<N>& offset, bool decode) {
  return unpack_texel<N>(simd::gather<N>(reinterpret_cast<const int32_t*>(t.texels()),
                                         offset + j * w + i, kTexelRoute),
                         decode);
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> lerp(const simd::Vec4<N>& a, const simd::Vec4<N>& b,
                                        const simd::Float<N>& t) {
  simd::Float<N> s = simd::Float<N>(1.0f) - t;
  return {a.x * s + b.x * t, a.y * s + b.y * t, a.z * s + b.z * t, a.w * s + b.w * t};
}

// GL_LINEAR's four texels of each lane in one level per lane (size w x h, first texel `offset`):
// b0, b1 on the lower row, t0, t1 on the upper one, and the weights' fractions fx, fy.
template <int N>
SOFTRAST_SIMD_INLINE void bilinear_texels(const Texture& t, const Sampler& s,
                                          const simd::Vec2<N>& uv, const simd::Int<N>& w,
                                          const simd::Int<N>& h, const simd::Int<N>& offset,
                                          bool pow2_u, bool pow2_v, simd::Int<N>& b0,
                                          simd::Int<N>& b1, simd::Int<N>& t0, simd::Int<N>& t1,
                                          simd::Float<N>& fx, simd::Float<N>& fy) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  // Texel centres sit at half-integers: shift by half a texel, then split (GL_LINEAR).
  I x0 = texel_floor<N>(uv.x * simd::to_float(w) - F(0.5f), fx);
  I y0 = texel_floor<N>(uv.y * simd::to_float(h) - F(0.5f), fy);
  I one(1);
  I i0 = wrap_texel<N>(s.wrap_u, x0, w, pow2_u);
  I i1 = wrap_texel<N>(s.wrap_u, x0 + one, w, pow2_u);
  I j0 = wrap_texel<N>(s.wrap_v, y0, h, pow2_v);
  I j1 = wrap_texel<N>(s.wrap_v, y0 + one, h, pow2_v);
  const auto* texels = reinterpret_cast<const int32_t*>(t.texels());
  if (simd::bits(i1 == i0 + one) == 0xffffu) {
    // No lane wraps between its two columns: texels (i0, j) and (i1, j) are neighbours in memory,
    // so one 64-bit load per lane and row fetches both (the same texels, half the loads), and
    // the rows' texels further right are asked for (at AVX2).
    simd::gather_pair<N>(texels, offset + j0 * w + i0, b0, b1, kTexelRoute, kTexelsAhead);
    simd::gather_pair<N>(texels, offset + j1 * w + i0, t0, t1, kTexelRoute, kTexelsAhead);
    return;
  }
  b0 = simd::gather<N>(texels, offset + j0 * w + i0, kTexelRoute);
  b1 = simd::gather<N>(texels, offset + j0 * w + i1, kTexelRoute);
  t0 = simd::gather<N>(texels, offset + j1 * w + i0, kTexelRoute);
  t1 = simd::gather<N>(texels, offset + j1 * w + i1, kTexelRoute);
}

// One level per lane (size w x h, first texel `offset`), nearest or bilinear: the arithmetic of
// Texture::sample_nearest / sample_bilinear in the same order.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_level(const Texture& t, const Sampler& s,
                                                const simd::Vec2<N>& uv, const simd::Int<N>& w,
                                                const simd::Int<N>& h, const simd::Int<N>& offset,
                                                bool pow2_u, bool pow2_v, bool nearest) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  F fx, fy;
  F wf = simd::to_float(w), hf = simd::to_float(h);
  const bool d = t.decodes(s);
  if (nearest) {
    I i = wrap_texel<N>(s.wrap_u, texel_floor<N>(uv.x * wf, fx), w, pow2_u);
    I j = wrap_texel<N>(s.wrap_v, texel_floor<N>(uv.y * hf, fy), h, pow2_v);
    return fetch<N>(t, i, j, w, offset, d);
  }
  I b0, b1, t0, t1;
  bilinear_texels<N>(t, s, uv, w, h, offset, pow2_u, pow2_v, b0, b1, t0, t1, fx, fy);
  if (!d) return filter_rgba8<N>(b0, b1, t0, t1, fx, fy);
  simd::Vec4<N> bottom = lerp<N>(unpack_texel<N>(b0, d), unpack_texel<N>(b1, d), fx);
  simd::Vec4<N> top = lerp<N>(unpack_texel<N>(t0, d), unpack_texel<N>(t1, d), fx);
  return lerp<N>(bottom, top, fy);
}

// fast_log2 (texture.hpp) for 16 lanes, the same operations.
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> fast_log2(const simd::Float<N>& x) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  I bits = simd::bit_cast_int(x);
  F exponent = simd::to_float((bits >> 23) - I(127));
  F m = simd::bit_cast_float((bits & I(0x007fffff)) | I(0x3f800000));
  F t = m - F(1.0f);
  F p = t * (F(1.44182512f) +
             t * (F(-0.708674935f) +
                  t * (F(0.415397767f) + t * (F(-0.194390433f) + t * F(0.0458707517f)))));
  return exponent + p;
}

// The mip level sizes and offsets of each lane's level `l` (0 <= l < levels), gathered from the
// texture's level table (MipLevel is {int width, int height, size_t offset}: 16 bytes, the
// offset's low 32 bits first on x86, and offsets stay below 2^31 texels). The caller has built
// the chain (Texture::ensure_mips).
template <int N>
SOFTRAST_SIMD_INLINE void level_lanes(const Texture& t, const simd::Int<N>& l, simd::Int<N>& w,
                                      simd::Int<N>& h, simd::Int<N>& offset) {
  static_assert(sizeof(MipLevel) == 16 && offsetof(MipLevel, height) == 4 &&
                offsetof(MipLevel, offset) == 8);
  using I = simd::Int<N>;
  // Usually a block's lanes are all at one level: that level's entry is read once and broadcast,
  // the same values as the three gathers below (a third of the gathers of a trilinear sample).
  const int32_t first = l.lane(0);
  if (simd::bits(l == I(first)) == 0xffffu) {
    const MipLevel& level = t.level(first);
    w = I(level.width);
    h = I(level.height);
    offset = I(int32_t(level.offset));
    return;
  }
  const auto* table = reinterpret_cast<const int32_t*>(&t.level(0));
  I at = l * I(4);
  w = simd::gather<N>(table, at, kTexelRoute);
  h = simd::gather<N>(table, at + I(1), kTexelRoute);
  offset = simd::gather<N>(table, at + I(2), kTexelRoute);
}

// Samples `texture` at 16 texture coordinates with the sampler's filter and wrap modes, inline
// (the body of the out-of-line kernels below); `texture` is not empty.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_inline(const Texture& texture, const Sampler& s,
                                                 const simd::Vec2<N>& uv) {
  using I = simd::Int<N>;
  const int w = texture.width(), h = texture.height();
  return sample_level<N>(texture, s, uv, I(w), I(h), I(0), (w & (w - 1)) == 0, (h & (h - 1)) == 0,
                         s.filter == Filter::kNearest);
}

// The two mip levels of each lane and the blend between them (OpenGL's level of detail: log2 of
// the longer derivative vector in texels of the base level), as Texture::sample computes them.
template <int N>
SOFTRAST_SIMD_INLINE void trilinear_levels(const Texture& texture, const simd::Vec2<N>& duv_dx,
                                           const simd::Vec2<N>& duv_dy, simd::Int<N>& l0,
                                           simd::Int<N>& l1, simd::Float<N>& t) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  const float w = float(texture.width()), h = float(texture.height());
  F xx = duv_dx.x * F(w), xy = duv_dx.y * F(h), yx = duv_dy.x * F(w), yy = duv_dy.y * F(h);
  F a = xx * xx + xy * xy, b = yx * yx + yy * yy;
  F rho2 = simd::select(a < b, b, a);  // std::max(a, b)
  F lod = F(0.5f) * fast_log2<N>(rho2);
  F top(float(texture.levels() - 1));
  I magnify = ~(lod > F(0.0f));  // lod <= 0 or NaN: the base level
  F d = simd::select(magnify, F(0.0f), simd::select(lod < top, lod, top));
  l0 = simd::to_int(d);
  t = d - simd::to_float(l0);
  l1 = simd::select(l0 < simd::to_int(top), l0 + I(1), l0);
}

// The same with derivatives, for a kTrilinear sampler.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_inline(const Texture& texture, const Sampler& s,
                                                 const simd::Vec2<N>& uv,
                                                 const simd::Vec2<N>& duv_dx,
                                                 const simd::Vec2<N>& duv_dy) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  I l0, l1;
  F t;
  trilinear_levels<N>(texture, duv_dx, duv_dy, l0, l1, t);
  // Halving a power of two (down to 1) keeps it one, so the base level decides for every level.
  int tw = texture.width(), th = texture.height();
  bool pow2_u = (tw & (tw - 1)) == 0, pow2_v = (th & (th - 1)) == 0;
  texture.ensure_mips();
  I w0, h0, o0;
  level_lanes<N>(texture, l0, w0, h0, o0);
  simd::Vec4<N> c0 = sample_level<N>(texture, s, uv, w0, h0, o0, pow2_u, pow2_v, false);
  // No lane between levels (all magnified, or all at the top level): the second level's weight
  // is 0 everywhere, and c0 * 1 + c1 * 0 is c0 exactly (texels are finite), so skip it.
  if (!simd::any(t > F(0.0f))) return c0;
  I w1, h1, o1;
  level_lanes<N>(texture, l1, w1, h1, o1);
  simd::Vec4<N> c1 = sample_level<N>(texture, s, uv, w1, h1, o1, pow2_u, pow2_v, false);
  return lerp<N>(c0, c1, t);
}

// The lanes of one out-of-line sample, as arrays: coordinates u, v, then (with derivatives)
// du/dx, dv/dx, du/dy, dv/dy in `in`; red, green, blue, alpha in `out`.
struct SampleLanes {
  alignas(64) float in[6][simd::kLanes];
  alignas(64) float out[4][simd::kLanes];
  alignas(64) int32_t rgba8[simd::kLanes];  // sample_rgba8's result
};

// The sampler compiled once per SIMD level (src/texture/sample_kernels.cpp), called from the
// shaders: inlined into every sampling site of every shader, it made most of their code (a
// phong or pbr block function ran to a megabyte at SSE2) for no speed, since a call per 16
// pixels costs little next to the gathers. N = 4 is the baseline's (SSE4.2 shaders call it
// too), 8 needs AVX2 and 16 AVX-512, which is what the shader's level has. (The one exception is
// avx512::bilinear_texels16 above, the common case at the widest level, inlined: without the
// call's spills and the lanes' trip through memory, quad_grid texture and phong ran 4 and 6 %
// faster. At AVX2 the same case has kernels of its own, sample_plan_8 and sample_rgba8_plan_8,
// which read the row pairs: inlined there, with 16 vector registers, the shader's values spilled
// around the sample.)
void sample_lanes_4(const Texture& texture, const Sampler& s, SampleLanes& io, bool derivatives);
void sample_lanes_8(const Texture& texture, const Sampler& s, SampleLanes& io, bool derivatives);
void sample_lanes_16(const Texture& texture, const Sampler& s, SampleLanes& io, bool derivatives);
// The same without derivatives, packed as RGBA8 into io.rgba8 (sample_rgba8).
void sample_rgba8_lanes_4(const Texture& texture, const Sampler& s, SampleLanes& io);
// At AVX2, a BilinearPlan's case (plan_texels): channels into io.out, or packed into io.rgba8.
void sample_plan_8(const BilinearPlan& plan, SampleLanes& io);
void sample_rgba8_plan_8(const BilinearPlan& plan, SampleLanes& io);
void sample_rgba8_lanes_8(const Texture& texture, const Sampler& s, SampleLanes& io);
void sample_rgba8_lanes_16(const Texture& texture, const Sampler& s, SampleLanes& io);

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_out_of_line(const Texture& texture, const Sampler& s,
                                                      SampleLanes& io, bool derivatives) {
  using F = simd::Float<N>;
  if constexpr (N == 4) {
    sample_lanes_4(texture, s, io, derivatives);
  } else if constexpr (N == 8) {
    sample_lanes_8(texture, s, io, derivatives);
  } else {
    static_assert(N == 16);
    sample_lanes_16(texture, s, io, derivatives);
  }
  return {F::load(io.out[0]), F::load(io.out[1]), F::load(io.out[2]), F::load(io.out[3])};
}

}  // namespace detail

// Samples through `t` (a texture bound to its sampler) at 16 texture coordinates with the
// sampler's filter and wrap modes; an empty texture samples as opaque white. The same results as
// Texture::sample, lane by lane.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample(const SampledTexture& t, const simd::Vec2<N>& uv) {
  using F = simd::Float<N>;
  if constexpr (N == 16) {
    if (const detail::BilinearPlan* plan = t.bilinear()) {  // the common case, inline
      simd::Int<N> b0, b1, t0, t1;
      F fx, fy;
      detail::avx512::bilinear_texels16(*plan, uv, b0, b1, t0, t1, fx, fy);
      return detail::filter_rgba8<N>(b0, b1, t0, t1, fx, fy);
    }
  }
  if (t.texture().empty()) return {F(1.0f), F(1.0f), F(1.0f), F(1.0f)};
  detail::SampleLanes io;
  uv.x.store(io.in[0]);
  uv.y.store(io.in[1]);
  if constexpr (N == 8) {
    if (const detail::BilinearPlan* plan = t.bilinear()) {  // the common case, out of line
      detail::sample_plan_8(*plan, io);
      return {F::load(io.out[0]), F::load(io.out[1]), F::load(io.out[2]), F::load(io.out[3])};
    }
  }
  return detail::sample_out_of_line<N>(t.texture(), t.sampler(), io, false);
}

// The same with the pair (bound for this one call: what SampledTexture works out once).
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample(const Texture& texture, const Sampler& s,
                                          const simd::Vec2<N>& uv) {
  return sample<N>(SampledTexture::for_one_call(texture, s), uv);
}

// sample() packed as RGBA8 (red in the low byte): exactly pack_rgba8(sample(...)), lane by lane,
// for a shader that writes the texel as it is (Fragments::set_rgba8). Bilinear filtering without
// sRGB decode, the common case, rounds its 16-bit levels straight to bytes instead of going
// through float and back.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> sample_rgba8(const SampledTexture& t, const simd::Vec2<N>& uv) {
  if constexpr (N == 16) {
    if (const detail::BilinearPlan* plan = t.bilinear()) {  // the common case, inline
      simd::Int<N> b0, b1, t0, t1;
      simd::Float<N> fx, fy;
      detail::avx512::bilinear_texels16(*plan, uv, b0, b1, t0, t1, fx, fy);
      return detail::filter_rgba8_packed<N>(b0, b1, t0, t1, fx, fy);
    }
  }
  if (t.texture().empty()) return simd::Int<N>(-1);  // opaque white
  detail::SampleLanes io;
  uv.x.store(io.in[0]);
  uv.y.store(io.in[1]);
  if constexpr (N == 8) {
    if (const detail::BilinearPlan* plan = t.bilinear()) {  // the common case, out of line
      detail::sample_rgba8_plan_8(*plan, io);
      return simd::Int<N>::load(io.rgba8);
    }
  }
  if constexpr (N == 4) {
    detail::sample_rgba8_lanes_4(t.texture(), t.sampler(), io);
  } else if constexpr (N == 8) {
    detail::sample_rgba8_lanes_8(t.texture(), t.sampler(), io);
  } else {
    static_assert(N == 16);
    detail::sample_rgba8_lanes_16(t.texture(), t.sampler(), io);
  }
  return simd::Int<N>::load(io.rgba8);
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> sample_rgba8(const Texture& texture, const Sampler& s,
                                               const simd::Vec2<N>& uv) {
  return sample_rgba8<N>(SampledTexture::for_one_call(texture, s), uv);
}

// The same with the texture coordinates' change to the next pixel right and down (for example
// {f.ddx(uv.x), f.ddx(uv.y)}), which choose the mip levels of Filter::kTrilinear: the same
// results as Texture::sample(s, uv, duv_dx, duv_dy), lane by lane.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample(const Texture& texture, const Sampler& s,
                                          const simd::Vec2<N>& uv, const simd::Vec2<N>& duv_dx,
                                          const simd::Vec2<N>& duv_dy) {
  if (texture.empty() || s.filter != Filter::kTrilinear) return sample<N>(texture, s, uv);
  detail::SampleLanes io;
  uv.x.store(io.in[0]);
  uv.y.store(io.in[1]);
  duv_dx.x.store(io.in[2]);
  duv_dx.y.store(io.in[3]);
  duv_dy.x.store(io.in[4]);
  duv_dy.y.store(io.in[5]);
  return detail::sample_out_of_line<N>(texture, s, io, true);
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample(const SampledTexture& t, const simd::Vec2<N>& uv,
                                          const simd::Vec2<N>& duv_dx,
                                          const simd::Vec2<N>& duv_dy) {
  if (t.sampler().filter != Filter::kTrilinear) return sample<N>(t, uv);
  return sample<N>(t.texture(), t.sampler(), uv, duv_dx, duv_dy);
}

}  // namespace softrast

#pragma GCC diagnostic pop
