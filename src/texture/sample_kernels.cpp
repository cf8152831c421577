// texture/sample_kernels.cpp: the wide sampler (softrast/detail/texture_simd.hpp) compiled once
// per SIMD level, for the shaders to call: 4 lanes at the x86-64 baseline, 8 with AVX2, 16 with
// AVX-512 F/BW/DQ/VL. A shader running at a level calls the kernel of its own width, so the CPU
// has what the kernel needs.
#include <immintrin.h>

#include "softrast/detail/shade_block.hpp"
#include "softrast/detail/shade_simd.hpp"  // pack_rgba8
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

// sample_rgba8: bilinear without decode filtered straight to bytes, else the float channels
// packed as the fragment stage packs them.
template <int N>
SOFTRAST_SIMD_INLINE void sample_rgba8_lanes(const Texture& texture, const Sampler& s,
                                             SampleLanes& io) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  simd::Vec2<N> uv{F::load(io.in[0]), F::load(io.in[1])};
  I packed;
  if (s.filter == Filter::kBilinear && !texture.decodes(s)) {
    const int w = texture.width(), h = texture.height();
    I b0, b1, t0, t1;
    F fx, fy;
    bilinear_texels<N>(texture, s, uv, I(w), I(h), I(0), (w & (w - 1)) == 0, (h & (h - 1)) == 0, b0,
                       b1, t0, t1, fx, fy);
    packed = filter_rgba8_packed<N>(b0, b1, t0, t1, fx, fy);
  } else {
    packed = pack_rgba8<N>(sample_inline<N>(texture, s, uv));
  }
  packed.store(io.rgba8);
}

}  // namespace

[[gnu::flatten]] void sample_rgba8_lanes_4(const Texture& texture, const Sampler& s,
                                           SampleLanes& io) {
  sample_rgba8_lanes<4>(texture, s, io);
}

[[gnu::target("avx2"), gnu::flatten]] void sample_rgba8_lanes_8(const Texture& texture,
                                                                const Sampler& s, SampleLanes& io) {
  sample_rgba8_lanes<8>(texture, s, io);
}

[[gnu::target("avx2"), gnu::flatten]] void sample_plan_8(const BilinearPlan& plan,
                                                         SampleLanes& io) {
  using F = simd::Float<8>;
  simd::Int<8> b0, b1, t0, t1;
  F fx, fy;
  plan_texels<8>(plan, {F::load(io.in[0]), F::load(io.in[1])}, b0, b1, t0, t1, fx, fy);
  const simd::Vec4<8> c = filter_rgba8<8>(b0, b1, t0, t1, fx, fy);
  c.x.store(io.out[0]);
  c.y.store(io.out[1]);
  c.z.store(io.out[2]);
  c.w.store(io.out[3]);
}

[[gnu::target("avx2"), gnu::flatten]] void sample_rgba8_plan_8(const BilinearPlan& plan,
                                                               SampleLanes& io) {
  using F = simd::Float<8>;
  simd::Int<8> b0, b1, t0, t1;
  F fx, fy;
  plan_texels<8>(plan, {F::load(io.in[0]), F::load(io.in[1])}, b0, b1, t0, t1, fx, fy);
  filter_rgba8_packed<8>(b0, b1, t0, t1, fx, fy).store(io.rgba8);
}

[[gnu::flatten]] void sample_lanes_4(const Texture& texture, const Sampler& s, SampleLanes& io,
                                     bool derivatives) {
  sample_lanes<4>(texture, s, io, derivatives);
}

[[gnu::target("avx2"), gnu::flatten]] void sample_lanes_8(const Texture& texture, const Sampler& s,
                                                          SampleLanes& io, bool derivatives) {
  sample_lanes<8>(texture, s, io, derivatives);
}

// The common cases, written with AVX-512 instructions directly: bilinear filtering of the base
// level, and trilinear, without sRGB decode, every wrap mode. The arithmetic is sample_level's,
// the same operations in the same order (so the same bits); the way there is shorter: the floor
// instruction in place of texel_floor's truncate, compare and correct, a shift in place of the
// row multiply, comparisons straight into mask registers. The filter is filter_rgba8's, in
// 16-bit lanes (it was float arithmetic: 16 conversions and 36 multiplications or additions per
// block, two thirds of the kernel's time without its gathers).
namespace {

// (Vectors passed by value between these inlined helpers: no ABI crosses here.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#define SOFTRAST_AVX512_FN \
  [[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::always_inline]] inline

struct Texels16 {
  __m512 r, g, b, a;
};

// wrap_texel (texture_simd.hpp) on native vectors: sizes per lane, every mode.
SOFTRAST_AVX512_FN __m512i wrap16(Wrap mode, __m512i i, __m512i size, bool pow2) {
  simd::Int<16> index, sizes;
  index.p[0] = simd::Native<16>::I(i);
  sizes.p[0] = simd::Native<16>::I(size);
  return __m512i(wrap_texel<16>(mode, index, sizes, pow2).p[0]);
}

SOFTRAST_AVX512_FN simd::Int<16> as_lanes(__m512i v) {
  simd::Int<16> r;
  r.p[0] = simd::Native<16>::I(v);
  return r;
}
SOFTRAST_AVX512_FN simd::Float<16> as_lanes(__m512 v) {
  simd::Float<16> r;
  r.p[0] = simd::Native<16>::F(v);
  return r;
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

// sample_level's bilinear branch for one level per lane (size w x h, first texel `offset`): the
// texels (bilinear_texels) and then the filter; `row_shift` is log2(w) when every lane has that
// power-of-two width (the rows start at j << it), else -1 (j * w).
// With `pairs` (the chain's row pairs, Texture::row_pair_chain, for a sampler that clamps each
// axis or repeats it over a power-of-two size; `pair_row0`: each lane's level's row 0 there), the
// texels come from them where every lane's columns are neighbours and no repeated row wraps
// (avx512::bilinear_texels16's way), else from the level's rows.
SOFTRAST_AVX512_FN void bilinear16_texels(const Texture& t, const Sampler& s, __m512 u, __m512 v,
                                          __m512i w, __m512i h, __m512i offset, bool pow2_u,
                                          bool pow2_v, int row_shift, __m512i& b0, __m512i& b1,
                                          __m512i& t0, __m512i& t1, __m512& fx, __m512& fy,
                                          const int64_t* pairs = nullptr,
                                          __m512i pair_row0 = __m512i{}) {
  __m512i x0 = avx512::floor16(
      _mm512_sub_ps(_mm512_mul_ps(u, _mm512_cvtepi32_ps(w)), _mm512_set1_ps(0.5f)), fx);
  __m512i y0 = avx512::floor16(
      _mm512_sub_ps(_mm512_mul_ps(v, _mm512_cvtepi32_ps(h)), _mm512_set1_ps(0.5f)), fy);
  const __m512i one = _mm512_set1_epi32(1);
  __m512i i0 = wrap16(s.wrap_u, x0, w, pow2_u);
  __m512i i1 = wrap16(s.wrap_u, _mm512_add_epi32(x0, one), w, pow2_u);
  if (pairs != nullptr) {
    using V = simd::Native<16>::I;
    __mmask16 wraps;
    const V r = avx512::pair_row16(s.wrap_v == Wrap::kRepeat, V(y0), V(h) - 1, wraps);
    if ((_mm512_cmpneq_epi32_mask(i1, _mm512_add_epi32(i0, one)) | wraps) == 0) {
      const V rows = row_shift >= 0 ? r << row_shift : r * V(w);
      V lb, rb, lt, rt;
      avx512::load_row_pairs16(pairs, V(pair_row0) + rows + V(i0), lb, rb, lt, rt);
      b0 = __m512i(lb), b1 = __m512i(rb), t0 = __m512i(lt), t1 = __m512i(rt);
      return;
    }
  }
  __m512i j0 = wrap16(s.wrap_v, y0, h, pow2_v);
  __m512i j1 = wrap16(s.wrap_v, _mm512_add_epi32(y0, one), h, pow2_v);
  __m512i row0, row1;
  if (row_shift >= 0) {
    const __m128i shift = _mm_cvtsi32_si128(row_shift);
    row0 = _mm512_sll_epi32(j0, shift);
    row1 = _mm512_sll_epi32(j1, shift);
  } else {
    row0 = _mm512_mullo_epi32(j0, w);
    row1 = _mm512_mullo_epi32(j1, w);
  }
  row0 = _mm512_add_epi32(offset, row0);
  row1 = _mm512_add_epi32(offset, row1);
  using V = simd::Native<16>::I;
  V lb, rb, lt, rt;
  avx512::gather_bilinear16(reinterpret_cast<const int32_t*>(t.texels()), V(row0), V(row1), V(i0),
                            V(i1), lb, rb, lt, rt);
  b0 = __m512i(lb), b1 = __m512i(rb), t0 = __m512i(lt), t1 = __m512i(rt);
}

SOFTRAST_AVX512_FN Texels16 bilinear16(const Texture& t, const Sampler& s, __m512 u, __m512 v,
                                       __m512i w, __m512i h, __m512i offset, bool pow2_u,
                                       bool pow2_v, int row_shift, const int64_t* pairs = nullptr,
                                       __m512i pair_row0 = __m512i{}) {
  __m512i b0, b1, t0, t1;
  __m512 fx, fy;
  bilinear16_texels(t, s, u, v, w, h, offset, pow2_u, pow2_v, row_shift, b0, b1, t0, t1, fx, fy,
                    pairs, pair_row0);
  simd::Vec4<16> c = filter_rgba8<16>(as_lanes(b0), as_lanes(b1), as_lanes(t0), as_lanes(t1),
                                      as_lanes(fx), as_lanes(fy));
  return {__m512(c.x.p[0]), __m512(c.y.p[0]), __m512(c.z.p[0]), __m512(c.w.p[0])};
}

SOFTRAST_AVX512_FN void store16(const Texels16& c, SampleLanes& io) {
  _mm512_store_ps(io.out[0], c.r);
  _mm512_store_ps(io.out[1], c.g);
  _mm512_store_ps(io.out[2], c.b);
  _mm512_store_ps(io.out[3], c.a);
}

// bilinear16_texels's row_shift for levels of widths `w` (a power of two when pow2): log2 of the
// width where every lane's level has the same one (usually: a block's lanes share their levels),
// else -1. (A named function, not a lambda: see shade_simd.hpp's pack_channel.)
SOFTRAST_AVX512_FN int row_shift16(const simd::Int<16>& w, bool pow2) {
  const int32_t first = w.lane(0);
  return pow2 && simd::bits(w == simd::Int<16>(first)) == 0xffffu ? __builtin_ctz(unsigned(first))
                                                                  : -1;
}

// Each lane's level's row 0 in the chain's row pairs (level_lanes' way: one read where the lanes
// share their level).
SOFTRAST_AVX512_FN __m512i level_row0_16(const int32_t* level_row0, const simd::Int<16>& l) {
  const int32_t first = l.lane(0);
  if (simd::bits(l == simd::Int<16>(first)) == 0xffffu) return _mm512_set1_epi32(level_row0[first]);
  return __m512i(simd::gather<16>(level_row0, l, kTexelRoute).p[0]);
}

// sample_inline, both forms, for bilinear and trilinear samplers without sRGB decode.
SOFTRAST_AVX512_FN void filtered16(const Texture& texture, const Sampler& s, SampleLanes& io,
                                   bool derivatives) {
  const int w = texture.width(), h = texture.height();
  // Halving a power of two (down to 1) keeps it one, so the base level decides for every level.
  const bool pow2_u = (w & (w - 1)) == 0, pow2_v = (h & (h - 1)) == 0;
  const __m512 u = _mm512_load_ps(io.in[0]), v = _mm512_load_ps(io.in[1]);
  if (!derivatives) {
    store16(bilinear16(texture, s, u, v, _mm512_set1_epi32(w), _mm512_set1_epi32(h),
                       _mm512_setzero_si512(), pow2_u, pow2_v,
                       pow2_u ? __builtin_ctz(unsigned(w)) : -1),
            io);
    return;
  }
  using F = simd::Float<16>;
  using I = simd::Int<16>;
  I l0, l1;
  F t;
  trilinear_levels<16>(texture, {F::load(io.in[2]), F::load(io.in[3])},
                       {F::load(io.in[4]), F::load(io.in[5])}, l0, l1, t);
  texture.ensure_mips();
  // The chain's row pairs where the texels are read by loads and each axis clamps or repeats
  // over a power of two.
  const auto paired = [&](Wrap mode, bool pow2) {
    return mode == Wrap::kClampToEdge || (mode == Wrap::kRepeat && pow2);
  };
  Texture::RowPairChain chain;
  if (simd::loads_for_gathers<16>() && paired(s.wrap_u, pow2_u) && paired(s.wrap_v, pow2_v)) {
    chain = texture.row_pair_chain();
  }
  const auto* pairs = reinterpret_cast<const int64_t*>(chain.pairs);
  I w0, h0, o0;
  level_lanes<16>(texture, l0, w0, h0, o0);
  Texels16 c = bilinear16(texture, s, u, v, __m512i(w0.p[0]), __m512i(h0.p[0]), __m512i(o0.p[0]),
                          pow2_u, pow2_v, row_shift16(w0, pow2_u), pairs,
                          pairs ? level_row0_16(chain.level_row0, l0) : __m512i{});
  if (simd::any(t > F(0.0f))) {  // else every lane's second weight is 0 (sample_inline)
    I w1, h1, o1;
    level_lanes<16>(texture, l1, w1, h1, o1);
    Texels16 c1 = bilinear16(texture, s, u, v, __m512i(w1.p[0]), __m512i(h1.p[0]), __m512i(o1.p[0]),
                             pow2_u, pow2_v, row_shift16(w1, pow2_u), pairs,
                             pairs ? level_row0_16(chain.level_row0, l1) : __m512i{});
    c = lerp16(c, c1, __m512(t.p[0]));
  }
  store16(c, io);
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
  // derivatives is set for kTrilinear samplers only (sample()).
  if (s.filter != Filter::kNearest && !texture.decodes(s)) {
    filtered16(texture, s, io, derivatives);
    return;
  }
  sample_lanes<16>(texture, s, io, derivatives);
}

[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void sample_rgba8_lanes_16(
    const Texture& texture, const Sampler& s, SampleLanes& io) {
  if (s.filter == Filter::kBilinear && !texture.decodes(s)) {
    const int w = texture.width(), h = texture.height();
    const bool pow2_u = (w & (w - 1)) == 0, pow2_v = (h & (h - 1)) == 0;
    __m512i b0, b1, t0, t1;
    __m512 fx, fy;
    bilinear16_texels(texture, s, _mm512_load_ps(io.in[0]), _mm512_load_ps(io.in[1]),
                      _mm512_set1_epi32(w), _mm512_set1_epi32(h), _mm512_setzero_si512(), pow2_u,
                      pow2_v, pow2_u ? __builtin_ctz(unsigned(w)) : -1, b0, b1, t0, t1, fx, fy);
    filter_rgba8_packed<16>(as_lanes(b0), as_lanes(b1), as_lanes(t0), as_lanes(t1), as_lanes(fx),
                            as_lanes(fy))
        .store(io.rgba8);
    return;
  }
  sample_rgba8_lanes<16>(texture, s, io);
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace softrast::detail
