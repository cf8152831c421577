// shaders/shading_math.hpp: wide helpers of the lit shaders: Blinn-Phong at one light, powers,
// the sRGB encoding of the output and normal-map decoding. All SOFTRAST_SIMD_INLINE, so they
// compile inside each shader's per-ISA fragment stage.
#pragma once

// Wide vectors are passed by value between inlined helpers; see shade_simd.hpp.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

#include "softrast/detail/texture_simd.hpp"
#include "softrast/simd.hpp"

namespace softrast::detail {

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec3<N> cross(const simd::Vec3<N>& a, const simd::Vec3<N>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// 2^x for x in [-125, 127] to within 3e-6 relative: the nearest integer i into the exponent
// bits, the Taylor polynomial of degree 5 for 2^t, t = x - i in [-0.5, 0.5]. Below -125 the
// result is about 2^-125 or less, never negative.
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> fast_exp2(const simd::Float<N>& x) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  F c = simd::clamp(x, F(-125.0f), F(127.0f));
  F r = c + F(0.5f);
  I i = simd::to_int(r);            // truncates towards zero
  i = i + (simd::to_float(i) > r);  // floor(c + 0.5)
  F t = c - simd::to_float(i);      // in [-0.5, 0.5]
  F p = F(1.0f) +
        t * (F(0.693147182f) +
             t * (F(0.240226507f) +
                  t * (F(0.0555041087f) + t * (F(0.00961812911f) + t * F(0.00133335581f)))));
  return simd::bit_cast_float(simd::bit_cast_int(p) + ((i) << 23));
}

// x^e for x >= 0 (0 where x is 0 and e > 0): exp2(e * log2(x)).
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> fast_pow(const simd::Float<N>& x, float e) {
  using F = simd::Float<N>;
  F r = fast_exp2<N>(F(e) * fast_log2<N>(simd::max(x, F(1.0e-30f))));
  return simd::select(x > F(0.0f), r, F(e > 0.0f ? 0.0f : 1.0f));
}

// x^32 by five squarings: SCENES.md's shininess, exact as its reference computes it. A base below
// kPow32Floor gives 0: its power is below 2^-125, so small that it cannot change an 8-bit colour
// (added to the lit colour it vanishes in the rounding unless that colour is below 2^-100, which
// is 0 in 8 bits), and mostly denormal, which Intel cores make and read through a microcode assist
// of about a hundred cycles per instruction (spheres_1m phong, where the highlight fades: 3.5 % of
// the frame at one thread on a Xeon, the same as with denormals flushed to zero).
inline constexpr float kPow32Floor = 0.0655f;  // 0.0655^32 = 1.3e-38, 2^-126 = 1.18e-38
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> pow32(const simd::Float<N>& base) {
  using F = simd::Float<N>;
  F x = simd::select(base < F(kPow32Floor), F(0.0f), base);
  for (int k = 0; k < 5; ++k) x = x * x;
  return x;
}

// Blinn-Phong at one light, per lane: `diffuse` is max(n.l, 0), `specular` the highlight
// max(n.h, 0)^shininess where the light reaches the surface (n.l > 0), else 0. Unit vectors: n
// the normal, l towards the light, view towards the eye. A light's visibility (a shadow term)
// multiplies both.
template <int N>
struct LightTerms {
  simd::Float<N> diffuse, specular;
};
template <int N>
SOFTRAST_SIMD_INLINE LightTerms<N> blinn_phong(const simd::Vec3<N>& n, const simd::Vec3<N>& l,
                                               const simd::Vec3<N>& view, float shininess) {
  using F = simd::Float<N>;
  simd::Vec3<N> h = simd::normalize_fast(l + view);
  F d = simd::max(simd::dot(n, l), F(0.0f));
  F nh = simd::max(simd::dot(n, h), F(0.0f));
  F highlight = shininess == 32.0f ? pow32<N>(nh) : fast_pow<N>(nh, shininess);
  return {d, simd::select(d > F(0.0f), highlight, F(0.0f))};
}

// The sRGB transfer function (linear_to_srgb of texture.hpp) with the fast log and exp:
// within 5e-5 of the exact curve on [0, 1], so the 8-bit output agrees with it but where the
// exact value is within that distance of a rounding boundary. Clamps to [0, 1] (NaN to 0).
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> encode_srgb(const simd::Float<N>& linear) {
  using F = simd::Float<N>;
  F c = simd::min(simd::max(linear, F(0.0f)), F(1.0f));
  F curve =
      F(1.055f) * fast_exp2<N>(F(1.0f / 2.4f) * fast_log2<N>(simd::max(c, F(1.0e-6f)))) - F(0.055f);
  return simd::select(c <= F(0.0031308f), c * F(12.92f), curve);
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> encode_srgb(const simd::Vec4<N>& c) {
  return {encode_srgb<N>(c.x), encode_srgb<N>(c.y), encode_srgb<N>(c.z), c.w};
}

// A normal map's texel as a vector: rgb * 2 - 1, x and y times `scale` (MTL's -bm).
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec3<N> map_normal(const simd::Vec4<N>& texel, float scale) {
  using F = simd::Float<N>;
  F s(2.0f * scale), o(-scale);
  return {texel.x * s + o, texel.y * s + o, texel.z * F(2.0f) - F(1.0f)};
}

// The normal of a tangent-space map value m in the frame of the unit normal n and the tangent
// t (w: the handedness, the sign of the bitangent): t made orthogonal to n, b = w * (n x t),
// normalize(m.x t + m.y b + m.z n). A degenerate tangent leaves n.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec3<N> tangent_to_world(const simd::Vec3<N>& m, const simd::Vec3<N>& n,
                                                    const simd::Vec3<N>& t,
                                                    const simd::Float<N>& w) {
  using F = simd::Float<N>;
  simd::Vec3<N> to = t - n * simd::dot(n, t);
  F len2 = simd::dot(to, to);
  simd::Int<N> ok = len2 > F(1.0e-20f);
  simd::Vec3<N> tu = to * (F(1.0f) / simd::sqrt(simd::select(ok, len2, F(1.0f))));
  simd::Vec3<N> b = cross<N>(n, tu) * simd::select(w < F(0.0f), F(-1.0f), F(1.0f));
  simd::Vec3<N> r = simd::normalize_fast(tu * m.x + b * m.y + n * m.z);
  return {simd::select(ok, r.x, n.x), simd::select(ok, r.y, n.y), simd::select(ok, r.z, n.z)};
}

}  // namespace softrast::detail

#pragma GCC diagnostic pop
