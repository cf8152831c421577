// texture/sample_kernels.cpp: the wide sampler (softrast/detail/texture_simd.hpp) compiled once
// per SIMD level, for the shaders to call: 4 lanes at the x86-64 baseline, 8 with AVX2, 16 with
// AVX-512 F/BW/DQ/VL. A shader running at a level calls the kernel of its own width, so the CPU
// has what the kernel needs.
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

// GCC 12's _mm512_undefined_ps initialises a variable with itself and -Wmaybe-uninitialized
// reports it inside every AVX-512 min/max (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void sample_lanes_16(
    const Texture& texture, const Sampler& s, SampleLanes& io, bool derivatives) {
  sample_lanes<16>(texture, s, io, derivatives);
}
#pragma GCC diagnostic pop

}  // namespace softrast::detail
