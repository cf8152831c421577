// texture/sample_kernels.cpp: the wide sampler (softrast/detail/texture_simd.hpp) compiled once
// per SIMD level, for the shaders to call: 4 lanes at the x86-64 baseline, 8 with AVX2, 16 with
// AVX-512 F/BW/DQ/VL. A shader running at a level calls the kernel of its own width, so the CPU
// has what the kernel needs.
#include <immintrin.h>

#include "softrast/detail/texture_simd.hpp"

namespace softrast::detail {
namespace {

template <int N>
SOFTRAST_SIMD_INLINE void sample_lanes(const Texture& texture, const Sampler& s, SampleLanes& io,
                                       bool derivatives) {
  using F = simd::Float<N>;
  simd::Vec2<N> uv{F::load(io.in[0]), F::load(io.in[1])};
  simd::Vec4<N> c = derivatives
                        ? sample_inline<N>(texture, s, uv, {F::load(io.in[2]), F::load(io.in[3])},
                                           {F::load(io.in[4]), F::load(io.in[5])})
                        : sample_inline<N>(texture, s, uv);
  c.x.store(io.out[0]);
  c.y.store(io.out[1]);
  c.z.store(io.out[2]);
  c.w.store(io.out[3]);
}

}  // namespace

[[gnu::flatten]] void sample_lanes_4(const Texture& texture, const Sampler& s, SampleLanes& io,
                                     bool derivatives) {
  sample_lanes<4>(texture, s, io, derivatives);
}

[[gnu::target("avx2"), gnu::flatten]] void sample_lanes_8(const Texture& texture, const Sampler& s,
                                                          SampleLanes& io, bool derivatives) {
  sample_lanes<8>(texture, s, io, derivatives);
}

// The common case, written with AVX-512 instructions directly: bilinear filtering of the base
// level without sRGB decode, every wrap mode. The arithmetic is sample_level's, the same
// operations in the same order (so the same bits); the way there is shorter: the floor
// instruction in place of texel_floor's truncate, compare and correct, a shift in place of the
// row multiply, comparisons straight into mask registers, and a vector modulo for repeating sizes
// that are not powers of two (sample_level wraps those lane by lane, which made a 4x4 block take
// four times as long). What is left is mostly the filter's float arithmetic: 16 conversions and
// 36 multiplications or additions per block, on the two ports that execute 512-bit operations.
namespace {

// (Vectors passed by value between these inlined helpers: no ABI crosses here.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#define SOFTRAST_AVX512_FN \
  [[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::always_inline]] inline

struct Texels16 {
  __m512 r, g, b, a;
};

// texel_floor: floor(x) and x - floor(x); NaN and |x| >= 1e9 give texel 0, fraction 0. (The
// fraction of -0 comes out +0 here and -0 there; it only ever multiplies texels, which are not
// negative, and is added to a non-negative product, so the sums are the same.)
SOFTRAST_AVX512_FN __m512i floor16(__m512 x, __m512& fraction) {
  __mmask16 ok = _mm512_cmp_ps_mask(x, _mm512_set1_ps(-1.0e9f), _CMP_GT_OQ) &
                 _mm512_cmp_ps_mask(x, _mm512_set1_ps(1.0e9f), _CMP_LT_OQ);
  __m512 xs = _mm512_maskz_mov_ps(ok, x);
  __m512 whole = _mm512_roundscale_ps(xs, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  fraction = _mm512_sub_ps(xs, whole);
  return _mm512_cvttps_epi32(whole);
}

// i mod size in [0, size) (Texture::wrap's repeat), for any size: in double, where i / size is
// close enough to exact that the floor is off by at most one, which the last two steps put right.
SOFTRAST_AVX512_FN __m256i modulo8(__m256i i, __m512d size, __m512d inverse) {
  __m512d d = _mm512_cvtepi32_pd(i);
  __m512d q =
      _mm512_roundscale_pd(_mm512_mul_pd(d, inverse), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  return _mm512_cvtpd_epi32(_mm512_sub_pd(d, _mm512_mul_pd(q, size)));  // exact: integers < 2^53
}
SOFTRAST_AVX512_FN __m512i modulo16(__m512i i, int size) {
  const __m512d s = _mm512_set1_pd(size), inverse = _mm512_set1_pd(1.0 / size);
  __m512i r =
      _mm512_inserti64x4(_mm512_castsi256_si512(modulo8(_mm512_castsi512_si256(i), s, inverse)),
                         modulo8(_mm512_extracti64x4_epi64(i, 1), s, inverse), 1);
  const __m512i n = _mm512_set1_epi32(size);
  r = _mm512_mask_add_epi32(r, _mm512_cmplt_epi32_mask(r, _mm512_setzero_si512()), r, n);
  return _mm512_mask_sub_epi32(r, _mm512_cmpge_epi32_mask(r, n), r, n);
}

// Texture::wrap, every mode.
SOFTRAST_AVX512_FN __m512i wrap16(Wrap mode, __m512i i, int size) {
  __m512i last = _mm512_set1_epi32(size - 1);
  switch (mode) {
    case Wrap::kRepeat:
      if ((size & (size - 1)) == 0) return _mm512_and_si512(i, last);
      return modulo16(i, size);
    case Wrap::kClampToEdge:
      return _mm512_min_epi32(_mm512_max_epi32(i, _mm512_setzero_si512()), last);
    case Wrap::kMirroredRepeat: {
      __m512i m = modulo16(i, 2 * size);
      __m512i mirrored = _mm512_sub_epi32(_mm512_set1_epi32(2 * size - 1), m);
      return _mm512_mask_mov_epi32(m, _mm512_cmpgt_epi32_mask(m, last), mirrored);
    }
  }
  return i;
}

// unpack_texel without decode.
SOFTRAST_AVX512_FN __m512 channel16(__m512i c) {
  return _mm512_mul_ps(_mm512_cvtepi32_ps(c), _mm512_set1_ps(1.0f / 255.0f));
}
SOFTRAST_AVX512_FN Texels16 unpack16(__m512i t) {
  const __m512i byte = _mm512_set1_epi32(0xff);
  return {channel16(_mm512_and_si512(t, byte)),
          channel16(_mm512_and_si512(_mm512_srli_epi32(t, 8), byte)),
          channel16(_mm512_and_si512(_mm512_srli_epi32(t, 16), byte)),
          channel16(_mm512_srli_epi32(t, 24))};
}

// lerp: a * (1 - t) + b * t, channel by channel.
SOFTRAST_AVX512_FN __m512 mix16(__m512 x, __m512 y, __m512 s, __m512 t) {
  return _mm512_add_ps(_mm512_mul_ps(x, s), _mm512_mul_ps(y, t));
}
SOFTRAST_AVX512_FN Texels16 lerp16(const Texels16& a, const Texels16& b, __m512 t) {
  __m512 s = _mm512_sub_ps(_mm512_set1_ps(1.0f), t);
  return {mix16(a.r, b.r, s, t), mix16(a.g, b.g, s, t), mix16(a.b, b.b, s, t),
          mix16(a.a, b.a, s, t)};
}

bool bilinear_fast_path(const Texture& t, const Sampler& s) {
  return s.filter != Filter::kNearest && !t.decodes(s);
}

SOFTRAST_AVX512_FN void bilinear16(const Texture& t, const Sampler& s, SampleLanes& io) {
  const int w = t.width(), h = t.height();
  __m512 fx, fy;
  __m512i x0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(_mm512_load_ps(io.in[0]), _mm512_set1_ps(float(w))),
                            _mm512_set1_ps(0.5f)),
              fx);
  __m512i y0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(_mm512_load_ps(io.in[1]), _mm512_set1_ps(float(h))),
                            _mm512_set1_ps(0.5f)),
              fy);
  const __m512i one = _mm512_set1_epi32(1);
  __m512i i0 = wrap16(s.wrap_u, x0, w), i1 = wrap16(s.wrap_u, _mm512_add_epi32(x0, one), w);
  __m512i j0 = wrap16(s.wrap_v, y0, h), j1 = wrap16(s.wrap_v, _mm512_add_epi32(y0, one), h);
  // Rows start at j * w: a shift when w is a power of two.
  __m512i row0, row1;
  if ((w & (w - 1)) == 0) {
    const __m128i shift = _mm_cvtsi32_si128(__builtin_ctz(unsigned(w)));
    row0 = _mm512_sll_epi32(j0, shift);
    row1 = _mm512_sll_epi32(j1, shift);
  } else {
    row0 = _mm512_mullo_epi32(j0, _mm512_set1_epi32(w));
    row1 = _mm512_mullo_epi32(j1, _mm512_set1_epi32(w));
  }
  const auto* texels = reinterpret_cast<const int32_t*>(t.texels());
  __m512i b0, b1, t0, t1;
  if (_mm512_cmpneq_epi32_mask(i1, _mm512_add_epi32(i0, one)) == 0) {
    // No lane wraps between its columns: one 64-bit load per lane and row (sample_level).
    using V = simd::Native<16>::I;
    V lo, hi;
    simd::isa::gather_pair(texels, V(_mm512_add_epi32(row0, i0)), lo, hi);
    b0 = __m512i(lo), b1 = __m512i(hi);
    simd::isa::gather_pair(texels, V(_mm512_add_epi32(row1, i0)), lo, hi);
    t0 = __m512i(lo), t1 = __m512i(hi);
  } else {
    b0 = _mm512_i32gather_epi32(_mm512_add_epi32(row0, i0), texels, 4);
    b1 = _mm512_i32gather_epi32(_mm512_add_epi32(row0, i1), texels, 4);
    t0 = _mm512_i32gather_epi32(_mm512_add_epi32(row1, i0), texels, 4);
    t1 = _mm512_i32gather_epi32(_mm512_add_epi32(row1, i1), texels, 4);
  }
  Texels16 bottom = lerp16(unpack16(b0), unpack16(b1), fx);
  Texels16 top = lerp16(unpack16(t0), unpack16(t1), fx);
  Texels16 c = lerp16(bottom, top, fy);
  _mm512_store_ps(io.out[0], c.r);
  _mm512_store_ps(io.out[1], c.g);
  _mm512_store_ps(io.out[2], c.b);
  _mm512_store_ps(io.out[3], c.a);
}

// wrap16 with a size per lane: repeat (of powers of two) or clamp to edge.
SOFTRAST_AVX512_FN __m512i wrap_levels16(Wrap mode, __m512i i, __m512i size) {
  __m512i last = _mm512_sub_epi32(size, _mm512_set1_epi32(1));
  if (mode == Wrap::kRepeat) return _mm512_and_si512(i, last);
  return _mm512_min_epi32(_mm512_max_epi32(i, _mm512_setzero_si512()), last);
}

// One mip level per lane (size w x h, first texel `offset`), for trilinear filtering: the same
// operations as bilinear16 with the sizes as vectors. Each wrap mode is clamp to edge or repeat
// with power-of-two sizes (every level of such a texture has them).
SOFTRAST_AVX512_FN Texels16 bilinear_levels16(const Texture& t, const Sampler& s, __m512 u,
                                              __m512 v, __m512i w, __m512i h, __m512i offset) {
  __m512 fx, fy;
  __m512i x0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(u, _mm512_cvtepi32_ps(w)), _mm512_set1_ps(0.5f)), fx);
  __m512i y0 =
      floor16(_mm512_sub_ps(_mm512_mul_ps(v, _mm512_cvtepi32_ps(h)), _mm512_set1_ps(0.5f)), fy);
  const __m512i one = _mm512_set1_epi32(1);
  __m512i i0 = wrap_levels16(s.wrap_u, x0, w);
  __m512i i1 = wrap_levels16(s.wrap_u, _mm512_add_epi32(x0, one), w);
  __m512i j0 = wrap_levels16(s.wrap_v, y0, h);
  __m512i j1 = wrap_levels16(s.wrap_v, _mm512_add_epi32(y0, one), h);
  __m512i row0 = _mm512_add_epi32(offset, _mm512_mullo_epi32(j0, w));
  __m512i row1 = _mm512_add_epi32(offset, _mm512_mullo_epi32(j1, w));
  const auto* texels = reinterpret_cast<const int32_t*>(t.texels());
  __m512i b0, b1, t0, t1;
  if (_mm512_cmpneq_epi32_mask(i1, _mm512_add_epi32(i0, one)) == 0) {
    using V = simd::Native<16>::I;
    V lo, hi;
    simd::isa::gather_pair(texels, V(_mm512_add_epi32(row0, i0)), lo, hi);
    b0 = __m512i(lo), b1 = __m512i(hi);
    simd::isa::gather_pair(texels, V(_mm512_add_epi32(row1, i0)), lo, hi);
    t0 = __m512i(lo), t1 = __m512i(hi);
  } else {
    b0 = _mm512_i32gather_epi32(_mm512_add_epi32(row0, i0), texels, 4);
    b1 = _mm512_i32gather_epi32(_mm512_add_epi32(row0, i1), texels, 4);
    t0 = _mm512_i32gather_epi32(_mm512_add_epi32(row1, i0), texels, 4);
    t1 = _mm512_i32gather_epi32(_mm512_add_epi32(row1, i1), texels, 4);
  }
  return lerp16(lerp16(unpack16(b0), unpack16(b1), fx), lerp16(unpack16(t0), unpack16(t1), fx), fy);
}

bool trilinear_fast_path(const Texture& t, const Sampler& s) {
  auto simple = [](Wrap mode, int size) {
    return mode == Wrap::kClampToEdge || (mode == Wrap::kRepeat && (size & (size - 1)) == 0);
  };
  return s.filter == Filter::kTrilinear && !t.decodes(s) && simple(s.wrap_u, t.width()) &&
         simple(s.wrap_v, t.height());
}

// sample_inline with derivatives (the level of detail, the two levels and their blend: the same
// operations), its bilinear lookups through bilinear_levels16.
SOFTRAST_AVX512_FN void trilinear16(const Texture& texture, const Sampler& s, SampleLanes& io) {
  using F = simd::Float<16>;
  using I = simd::Int<16>;
  const float w = float(texture.width()), h = float(texture.height());
  F xx = F::load(io.in[2]) * F(w), xy = F::load(io.in[3]) * F(h);
  F yx = F::load(io.in[4]) * F(w), yy = F::load(io.in[5]) * F(h);
  F a = xx * xx + xy * xy, b = yx * yx + yy * yy;
  F rho2 = simd::select(a < b, b, a);
  F lod = F(0.5f) * fast_log2<16>(rho2);
  F top(float(texture.levels() - 1));
  I magnify = ~(lod > F(0.0f));
  F d = simd::select(magnify, F(0.0f), simd::select(lod < top, lod, top));
  I l0 = simd::to_int(d);
  F t = d - simd::to_float(l0);
  I l1 = simd::select(l0 < simd::to_int(top), l0 + I(1), l0);
  texture.ensure_mips();
  const __m512 u = _mm512_load_ps(io.in[0]), v = _mm512_load_ps(io.in[1]);
  I w0, h0, o0;
  level_lanes<16>(texture, l0, w0, h0, o0);
  Texels16 c =
      bilinear_levels16(texture, s, u, v, __m512i(w0.p[0]), __m512i(h0.p[0]), __m512i(o0.p[0]));
  if (simd::any(t > F(0.0f))) {  // else every lane's second weight is 0 (sample_inline)
    I w1, h1, o1;
    level_lanes<16>(texture, l1, w1, h1, o1);
    Texels16 c1 =
        bilinear_levels16(texture, s, u, v, __m512i(w1.p[0]), __m512i(h1.p[0]), __m512i(o1.p[0]));
    c = lerp16(c, c1, __m512(t.p[0]));
  }
  _mm512_store_ps(io.out[0], c.r);
  _mm512_store_ps(io.out[1], c.g);
  _mm512_store_ps(io.out[2], c.b);
  _mm512_store_ps(io.out[3], c.a);
}

#undef SOFTRAST_AVX512_FN
#pragma GCC diagnostic pop

}  // namespace

// GCC 12's _mm512_undefined_ps initialises a variable with itself and -Wmaybe-uninitialized
// reports it inside every AVX-512 min/max (GCC bug 105593, fixed in GCC 13).
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void sample_lanes_16(
    const Texture& texture, const Sampler& s, SampleLanes& io, bool derivatives) {
  if (!derivatives && bilinear_fast_path(texture, s)) {
    bilinear16(texture, s, io);
    return;
  }
  if (derivatives && trilinear_fast_path(texture, s)) {
    trilinear16(texture, s, io);
    return;
  }
  sample_lanes<16>(texture, s, io, derivatives);
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace softrast::detail
