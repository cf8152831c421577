// softrast/detail/texture_simd.hpp: texture sampling for wide shaders, 16 lanes at once, with
// the same arithmetic in the same order as Texture::sample (so both give the same bits).
// Internal: included through softrast/shader.hpp; shaders call softrast::sample().
#pragma once

#include <cstring>

#include "softrast/simd.hpp"
#include "softrast/texture.hpp"

namespace softrast {
namespace detail {

// texel_floor for 16 lanes: floor(x) and x - floor(x); NaN and |x| >= 1e9 give texel 0, 0.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> texel_floor(const simd::Float<N>& x, simd::Float<N>& fraction) {
  using F = simd::Float<N>;
  simd::Int<N> ok = (x > F(-1.0e9f)) & (x < F(1.0e9f));
  F xs = simd::select(ok, x, F(0.0f));
  simd::Int<N> i = simd::to_int(xs);  // truncates towards zero
  i = i + (simd::to_float(i) > xs);   // the mask is -1 where truncation went up
  fraction = xs - simd::to_float(i);
  return i;
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> wrap_texel(Wrap mode, const simd::Int<N>& i, int size) {
  using I = simd::Int<N>;
  if (mode == Wrap::kClampToEdge) {
    return simd::select(i < I(0), I(0), simd::select(i > I(size - 1), I(size - 1), i));
  }
  if (mode == Wrap::kRepeat && (size & (size - 1)) == 0) return i & I(size - 1);
  I r;  // repeat of other sizes and mirrored repeat: a division per lane, the scalar rule
  for (int lane = 0; lane < simd::kLanes; ++lane) {
    r.p[lane / N][lane % N] = Texture::wrap(mode, i.lane(lane), size);
  }
  return r;
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> fetch(const Texture& t, const simd::Int<N>& i,
                                         const simd::Int<N>& j) {
  using F = simd::Float<N>;
  simd::Int<N> texel = simd::gather<N>(reinterpret_cast<const int32_t*>(t.texels()),
                                       j * simd::Int<N>(t.width()) + i);
  const F k(1.0f / 255.0f);
  simd::Int<N> byte(0xff);
  return {simd::to_float(texel & byte) * k, simd::to_float((texel >> 8) & byte) * k,
          simd::to_float((texel >> 16) & byte) * k, simd::to_float(texel >> 24) * k};
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> lerp(const simd::Vec4<N>& a, const simd::Vec4<N>& b,
                                        const simd::Float<N>& t) {
  simd::Float<N> s = simd::Float<N>(1.0f) - t;
  return {a.x * s + b.x * t, a.y * s + b.y * t, a.z * s + b.z * t, a.w * s + b.w * t};
}

}  // namespace detail

// Samples `texture` at 16 texture coordinates with the sampler's filter and wrap modes; an empty
// texture samples as opaque white. The same results as Texture::sample, lane by lane.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample(const Texture& texture, const Sampler& s,
                                          const simd::Vec2<N>& uv) {
  using F = simd::Float<N>;
  if (texture.empty()) return {F(1.0f), F(1.0f), F(1.0f), F(1.0f)};
  const int w = texture.width(), h = texture.height();
  F fx, fy;
  if (s.filter == Filter::kNearest) {
    simd::Int<N> i = detail::wrap_texel<N>(s.wrap_u, detail::texel_floor<N>(uv.x * F(float(w)), fx), w);
    simd::Int<N> j = detail::wrap_texel<N>(s.wrap_v, detail::texel_floor<N>(uv.y * F(float(h)), fy), h);
    return detail::fetch<N>(texture, i, j);
  }
  // Texel centres sit at half-integers: shift by half a texel, then split (GL_LINEAR).
  simd::Int<N> x0 = detail::texel_floor<N>(uv.x * F(float(w)) - F(0.5f), fx);
  simd::Int<N> y0 = detail::texel_floor<N>(uv.y * F(float(h)) - F(0.5f), fy);
  simd::Int<N> one(1);
  simd::Int<N> i0 = detail::wrap_texel<N>(s.wrap_u, x0, w);
  simd::Int<N> i1 = detail::wrap_texel<N>(s.wrap_u, x0 + one, w);
  simd::Int<N> j0 = detail::wrap_texel<N>(s.wrap_v, y0, h);
  simd::Int<N> j1 = detail::wrap_texel<N>(s.wrap_v, y0 + one, h);
  simd::Vec4<N> bottom = detail::lerp<N>(detail::fetch<N>(texture, i0, j0),
                                         detail::fetch<N>(texture, i1, j0), fx);
  simd::Vec4<N> top = detail::lerp<N>(detail::fetch<N>(texture, i0, j1),
                                      detail::fetch<N>(texture, i1, j1), fx);
  return detail::lerp<N>(bottom, top, fy);
}

}  // namespace softrast
