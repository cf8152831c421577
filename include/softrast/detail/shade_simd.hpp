// softrast/detail/shade_simd.hpp: the fragment stage for shaders written against the wide types
// of softrast/simd.hpp: a whole 4x4 block at a time (16 lanes, four 2x2 quads), interpolation,
// depth test, the shader, colour packing and blending all vectorised. Compiled once per SIMD
// level inside the caller's translation unit, chosen at the draw by simd_level().
// Internal: included through softrast/shader.hpp.
#pragma once

// Wide vectors are passed by value between inlined helpers; GCC notes that the ABI of such
// parameters changed in GCC 4.6, which cannot matter here (nothing crosses a library boundary).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "softrast/detail/interpolants.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"
#include "softrast/simd.hpp"
#include "softrast/simd_level.hpp"

namespace softrast {

namespace detail {
[[noreturn]] inline void undeclared_derivatives();  // defined below
}  // namespace detail

// What a wide fragment shader sees of one 4x4 block, and what it writes. Lane i is the pixel
// (x0 + i % 4, y0 + i / 4). Every member function is always inlined: a wide shader is inlined
// into each SIMD level's block function, and an out-of-line copy compiled for baseline x86-64
// would pass and return its 16-lane values in a different ABI (a crash at -O0).
template <int N>
struct Fragments {
  using F = simd::Float<N>;
  F x, y;                    // window coordinates of the samples (pixel centres)
  F depth;                   // window depth in [0, 1]; a shader with kWritesDepth may set it
  simd::Int<N> live;         // lanes still to be written: covered and not discarded
  bool front_facing = true;  // the primitive's facing
  // The colour replaces what is stored (no blending): a shader may then write bytes that are
  // exactly what the fragment stage would make of its float colour (set_rgba8).
  bool opaque = true;
  // The pixels belong to several triangles (a shader whose reads_derivatives() is false): no
  // derivatives then; ddx and ddy stop the program.
  bool several_triangles = false;
  const F* varyings = nullptr;  // the shader's kVaryings values, perspective-correct
  simd::Vec4<N> color;          // the output, set by the shader
  // Or the output as RGBA8 (red in the low byte), for a shader whose result comes as bytes (the
  // built-in texture shader writes the filtered texel as it is): set_rgba8 replaces `color`,
  // which the fragment stage would otherwise clamp, scale and round to these bytes itself.
  // Blending starts from it as byte / 255.
  simd::Int<N> rgba8;
  bool has_rgba8 = false;

  SOFTRAST_SIMD_INLINE void set_rgba8(const simd::Int<N>& packed) {
    rgba8 = packed;
    has_rgba8 = true;
  }

  SOFTRAST_SIMD_INLINE F varying(int i) const { return varyings[i]; }
  SOFTRAST_SIMD_INLINE simd::Vec2<N> vec2(int i) const { return {varyings[i], varyings[i + 1]}; }
  SOFTRAST_SIMD_INLINE simd::Vec3<N> vec3(int i) const {
    return {varyings[i], varyings[i + 1], varyings[i + 2]};
  }
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vec4(int i) const {
    return {varyings[i], varyings[i + 1], varyings[i + 2], varyings[i + 3]};
  }
  // Change of a value to the next pixel right (ddx) or down (ddy), the same for the four pixels of
  // each 2x2 quad (coarse derivatives, as D3D's ddx_coarse).
  SOFTRAST_SIMD_INLINE F ddx(const F& v) const {
    if (several_triangles) detail::undeclared_derivatives();
    return quad_difference(v, 1);
  }
  SOFTRAST_SIMD_INLINE F ddy(const F& v) const {
    if (several_triangles) detail::undeclared_derivatives();
    return quad_difference(v, 4);
  }
  // Drops lanes (mask lanes -1) from the output; only for shaders declaring kDiscards = true.
  SOFTRAST_SIMD_INLINE void discard(const simd::Int<N>& lanes) { live = live & ~lanes; }

 private:
  // v at the quad's pixel `step` lanes after its top-left one, minus v at the top-left one.
  // Two permutes (simd::lookup16) where the level has them; it was a loop over the lanes, which
  // made trilinear texturing's four derivatives a quarter of its block function.
  SOFTRAST_SIMD_INLINE static F quad_difference(const F& v, int step) {
    alignas(64) float lanes[simd::kLanes];
    v.store(lanes);
    const simd::Int<N> top_left = simd::Int<N>::load(simd::kLaneQuadTopLeft);
    return simd::lookup16<N>(lanes, top_left + simd::Int<N>(step)) -
           simd::lookup16<N>(lanes, top_left);
  }
};

namespace detail {

template <class S>
concept WideShader = requires(const S& s, Fragments<4>& f4, Fragments<8>& f8, Fragments<16>& f16) {
  s.template shade<4>(f4);
  s.template shade<8>(f8);
  s.template shade<16>(f16);
};

template <class S>
concept DeclaresDiscards = requires {
  requires S::kDiscards;
};

template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> eval_plane(const Plane& p, const simd::Float<N>& dx,
                                               const simd::Float<N>& dy) {
  // The scalar eval_plane's operation order, so that both give the same bits.
  return simd::Float<N>(p.a0) + simd::Float<N>(p.dadx) * dx + simd::Float<N>(p.dady) * dy;
}
// Half a register's floats, and as many doubles (one register), at SSE; split and join move
// between a register (Fn) and its two halves.
template <std::size_t kBytes>
struct HalfLanes;
template <>
struct HalfLanes<16> {
  typedef float Fn __attribute__((vector_size(16)));
  typedef float F __attribute__((vector_size(8)));
  typedef double D __attribute__((vector_size(16)));
  SOFTRAST_SIMD_INLINE static void split(const Fn& x, F& low, F& high) {
    low = __builtin_shufflevector(x, x, 0, 1);
    high = __builtin_shufflevector(x, x, 2, 3);
  }
  SOFTRAST_SIMD_INLINE static void join(const F& low, const F& high, Fn& out) {
    out = __builtin_shufflevector(low, high, 0, 1, 2, 3);
  }
};
// (A named function, not a lambda: see pack_channel.)
template <class H, class DH>
SOFTRAST_SIMD_INLINE void half_plane(const DepthPlane& p, const H& x, const H& y, H& out) {
  const DH xd = __builtin_convertvector(x, DH), yd = __builtin_convertvector(y, DH);
  out = __builtin_convertvector(((DH{} + p.a0) + (DH{} + p.dadx) * xd) + (DH{} + p.dady) * yd, H);
}
// AVX2's eight lanes at once: each half converted by one VCVTPS2PD (GCC 12 made the conversion of
// a half above two conversions of two lanes, a move and an insert) and back by one VCVTPD2PS.
// The same operations in the same order as half_plane, so the same bits.
[[gnu::target("avx")]] inline __m128 plane4(const __m256d& a0, const __m256d& dadx,
                                            const __m256d& dady, __m128 x, __m128 y) {
  const __m256d xd = _mm256_cvtps_pd(x), yd = _mm256_cvtps_pd(y);
  return _mm256_cvtpd_ps(
      _mm256_add_pd(_mm256_add_pd(a0, _mm256_mul_pd(dadx, xd)), _mm256_mul_pd(dady, yd)));
}
[[gnu::target("avx")]] inline void plane8(const DepthPlane& p, const simd::Native<8>::F& x,
                                          const simd::Native<8>::F& y, simd::Native<8>::F& out) {
  const __m256d a0 = _mm256_set1_pd(0.0 + p.a0), dadx = _mm256_set1_pd(0.0 + p.dadx),
                dady = _mm256_set1_pd(0.0 + p.dady);
  const __m256 xv = __m256(x), yv = __m256(y);
  const __m128 low = plane4(a0, dadx, dady, _mm256_castps256_ps128(xv), _mm256_castps256_ps128(yv));
  const __m128 high =
      plane4(a0, dadx, dady, _mm256_extractf128_ps(xv, 1), _mm256_extractf128_ps(yv, 1));
  out = simd::Native<8>::F(_mm256_insertf128_ps(_mm256_castps128_ps256(low), high, 1));
}
// Depth: the plane in double, rounded to float once, as the scalar eval_plane and the tile
// kernels' depth resolve compute it (the same operations, so the same bits). At SSE (and AVX2, by
// plane8) each part's lanes go in two halves, each converted to one register of doubles: a vector
// of doubles twice the register's width, broadcast from a scalar, went through the stack lane by
// lane there (scalar stores, then wide loads that could not take them from the store buffer: a
// third of the AVX2 texture shader's samples).
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> eval_plane(const DepthPlane& p, const simd::Float<N>& dx,
                                               const simd::Float<N>& dy) {
  using Fn = typename simd::Native<N>::F;
  constexpr int kHalf = int(sizeof(Fn) / sizeof(float)) / 2;
  simd::Float<N> z;
  if constexpr (kHalf == 8) {
    // AVX-512: the 16 doubles are two registers, and GCC broadcasts into them directly.
    using D = typename simd::Native<N>::D;
    const D a0 = D{} + p.a0, dadx = D{} + p.dadx, dady = D{} + p.dady;
    for (int k = 0; k < simd::Float<N>::kParts; ++k) {
      D x = __builtin_convertvector(dx.p[k], D), y = __builtin_convertvector(dy.p[k], D);
      z.p[k] = __builtin_convertvector((a0 + dadx * x) + dady * y, Fn);
    }
  } else if constexpr (kHalf == 4) {
    for (int k = 0; k < simd::Float<N>::kParts; ++k) plane8(p, dx.p[k], dy.p[k], z.p[k]);
  } else {
    using Half = HalfLanes<sizeof(Fn)>;
    for (int k = 0; k < simd::Float<N>::kParts; ++k) {
      typename Half::F x_low, x_high, y_low, y_high, low, high;
      Half::split(dx.p[k], x_low, x_high);
      Half::split(dy.p[k], y_low, y_high);
      half_plane<typename Half::F, typename Half::D>(p, x_low, y_low, low);
      half_plane<typename Half::F, typename Half::D>(p, x_high, y_high, high);
      Half::join(low, high, z.p[k]);
    }
  }
  return z;
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> depth_passes(DepthFunc f, const simd::Float<N>& z,
                                               const simd::Float<N>& stored) {
  switch (f) {
    case DepthFunc::kNever:
      return simd::Int<N>(0);
    case DepthFunc::kLess:
      return z < stored;
    case DepthFunc::kEqual:
      return z == stored;
    case DepthFunc::kLessEqual:
      return z <= stored;
    case DepthFunc::kGreater:
      return z > stored;
    case DepthFunc::kNotEqual:
      return z != stored;
    case DepthFunc::kGreaterEqual:
      return z >= stored;
    case DepthFunc::kAlways:
      return simd::Int<N>(-1);
  }
  return simd::Int<N>(0);
}

// A named always-inline function, not a lambda: a lambda is not inlined at -O0, and compiled on
// its own (without the caller's AVX-512 target) it mishandled Float<16> and crashed the debug
// preset's tests.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> pack_channel(const simd::Float<N>& v) {
  using F = simd::Float<N>;
  F clamped = simd::min(simd::max(v, F(0.0f)), F(1.0f));
  return simd::to_int(clamped * F(255.0f) + F(0.5f));
}

// pack_rgba8 for 16 lanes: clamp to [0, 1] (NaN to 0), x * 255 + 0.5 truncated, R in the low byte.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> pack_rgba8(const simd::Vec4<N>& c) {
  return pack_channel(c.x) | pack_channel(c.y) << 8 | pack_channel(c.z) << 16 |
         pack_channel(c.w) << 24;
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> unpack_rgba8(const simd::Int<N>& p) {
  using F = simd::Float<N>;
  const F k(1.0f / 255.0f);
  simd::Int<N> byte(0xff);
  return {simd::to_float(p & byte) * k, simd::to_float((p >> 8) & byte) * k,
          simd::to_float((p >> 16) & byte) * k, simd::to_float(p >> 24) * k};
}

// blend_pixel for 16 lanes, the same formulas in the same order.
template <int N>
SOFTRAST_SIMD_INLINE simd::Int<N> blend(BlendMode mode, const simd::Vec4<N>& colour,
                                        const simd::Int<N>& dst_packed) {
  using F = simd::Float<N>;
  simd::Vec4<N> src = colour;
  if (mode == BlendMode::kOpaque) return pack_rgba8(src);
  const F zero(0.0f), one(1.0f);
  src = {simd::clamp(src.x, zero, one), simd::clamp(src.y, zero, one),
         simd::clamp(src.z, zero, one), simd::clamp(src.w, zero, one)};
  simd::Vec4<N> dst = unpack_rgba8(dst_packed);
  if (mode == BlendMode::kAdditive) {
    return pack_rgba8(simd::Vec4<N>{src.x + dst.x, src.y + dst.y, src.z + dst.z, src.w + dst.w});
  }
  F inv = one - src.w;
  simd::Vec4<N> out{src.x * src.w + dst.x * inv, src.y * src.w + dst.y * inv,
                    src.z * src.w + dst.z * inv, src.w + dst.w * inv};
  return pack_rgba8(out);
}

[[noreturn]] inline void undeclared_discard() {
  std::fprintf(stderr,
               "softrast: a shader discarded pixels without declaring kDiscards = true; the "
               "deferred path cannot honour that\n");
  std::abort();
}

[[noreturn]] inline void undeclared_derivatives() {
  std::fprintf(stderr,
               "softrast: a shader read derivatives (ddx, ddy) although its reads_derivatives() "
               "returned false\n");
  std::abort();
}

// w = 1 / inv_w, with shade_quad's guard: an |inv_w| below 1e-30 (zero included; NaN is not:
// the scalar test's -1e-30 < inv_w < 1e-30 in one comparison) divides as 1e-30 would. The
// division does not wait for the test: lanes the guard moves take the quotient 1 / 1e-30 (the
// same IEEE division, done once by the compiler), chosen after it. That takes the comparison off
// the block's longest chain, which a textured block's time follows (its texel addresses wait for
// w): quad_grid texture 4 % faster.
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> guarded_w(const simd::Float<N>& inv_w) {
  using F = simd::Float<N>;
  constexpr float kGuarded = 1.0f / 1.0e-30f;
  return simd::select(simd::abs(inv_w) < F(1.0e-30f), F(kGuarded), F(1.0f) / inv_w);
}

template <class S>
concept CheapToShade = requires {
  requires S::kCheapToShade;
};

// Whether shader `s` reads derivatives in this draw: its reads_derivatives(), if it has one;
// otherwise it is taken to.
template <class S>
bool reads_derivatives(const S& s) {
  if constexpr (requires {
                  { s.reads_derivatives() } -> std::convertible_to<bool>;
                }) {
    return s.reads_derivatives();
  } else {
    return true;
  }
}

// Shades the covered pixels (`mask`) of the 4x4 block at (x, y) with shader S on N-lane vectors.
// kCommon compiles the state most draws use (depth less with writes, opaque) with its branches
// resolved; `target.resolved` means visibility is already decided (see ShadeTarget).
//
// kHalf (a block of two parts, AVX2's two registers of 8 lanes; kCommon only): only the two rows
// from y (0 and 1, or 2 and 3 of the block) are covered, `mask` their 8 bits. Part 0 takes them
// and part 1 is made a copy of it, so each lane of part 0 gets the operations, and the bits, of
// the whole-block path; the compiler drops what part 1 would add, since only part 0 is stored.
// Quads stay whole (a quad's four lanes are in one part), so derivatives are the whole block's.
// Most blocks of small triangles are such halves (spheres_1m: 84 % of the fragment stage's).
template <class S, int N, bool kCommon, bool kHalf = false>
SOFTRAST_SIMD_INLINE void shade_block_wide(const S& shader, const ShadeTarget& target,
                                           const Interpolants& in, int x, int y, uint32_t mask) {
  static_assert(!kHalf || (kCommon && simd::Float<N>::kParts == 2 && !WritesDepth<S>));
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  constexpr int kN = S::kVaryings > 0 ? S::kVaryings : 1;
  constexpr bool kLateDepth = WritesDepth<S>;
  Framebuffer& fb = *target.framebuffer;
  const RenderState& st = *target.state;
  const bool resolved = target.resolved;
  const bool depth_test = !resolved && (kCommon || st.depth_test);
  const DepthFunc depth_func = kCommon ? DepthFunc::kLess : st.depth_func;
  const bool depth_write = kCommon || st.depth_write;
  const BlendMode blend_mode = (kCommon || resolved) ? BlendMode::kOpaque : st.blend;

  Fragments<N> f;
  f.x = simd::to_float(I(x) + simd::lane_column<N>()) + F(0.5f);
  f.y = simd::to_float(I(y) + simd::lane_row<N>()) + F(0.5f);
  if constexpr (kHalf) {
    f.x.p[1] = f.x.p[0];
    f.y.p[1] = f.y.p[0];
  }
  F dx = f.x - F(in.x_ref), dy = f.y - F(in.y_ref);
  F z = simd::clamp(eval_plane<N>(in.z, dx, dy), F(0.0f), F(1.0f));
  f.live = simd::lanes_of<N>(mask);
  if constexpr (kHalf) f.live.p[1] = typename simd::Native<N>::I{};
  f.opaque = blend_mode == BlendMode::kOpaque;

  // The framebuffer stores a block's 16 pixels together (framebuffer.hpp): one aligned vector
  // load or store each for depth and colour. Blocks cut by the image's edge exist whole, and
  // only covered pixels (never padding) are live.
  float* depth_at = fb.depth_block(x, y);
  F stored;
  if constexpr (kHalf) stored = F(0.0f);  // (GCC cannot tell that the write below needs the test)
  if (depth_test) {
    if constexpr (kHalf) {
      std::memcpy(&stored.p[0], depth_at, sizeof stored.p[0]);
      stored.p[1] = stored.p[0];
    } else {
      stored = F::load(depth_at);
    }
    if (!kLateDepth) {  // early depth test: the shader cannot change depth
      f.live = f.live & depth_passes<N>(depth_func, z, stored);
      if (!simd::any(f.live)) return;
    }
  }

  // Helper pixels outside the primitive extrapolate, past the horizon too, where 1/w is negative:
  // the varyings there are the projective continuation (what GPUs and llvmpipe compute), which
  // keeps derivatives finite (clamping 1/w to a tiny positive value made them huge and sent
  // trilinear lookups to the last mip level). Only a 1/w too close to 0 to divide by is moved.
  F inv_w = eval_plane<N>(in.inv_w, dx, dy);
  F w = guarded_w<N>(inv_w);
  F var[kN];
  for (int i = 0; i < S::kVaryings; ++i) var[i] = eval_plane<N>(in.var[i], dx, dy) * w;
  f.varyings = var;
  f.depth = z;
  f.front_facing = in.front_facing;
  f.color = {F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
  const I covered = f.live;
  shader.template shade<N>(f);
  // The opaque output packed at once: f.color is dead from here. (Packed at the write, below,
  // the four vectors of f.color were kept across the rest, spilled where a shader's two output
  // forms join: about 20 instructions a call of the texture shader's blocks, quad_grid texture
  // 396.8 M -> 388.8 M in three frames.)
  I packed{};
  if (blend_mode == BlendMode::kOpaque) packed = f.has_rgba8 ? f.rgba8 : pack_rgba8<N>(f.color);
  if constexpr (!DeclaresDiscards<S>) {
    if (resolved && simd::bits(f.live) != simd::bits(covered)) undeclared_discard();
  }

  if (kLateDepth) {
    z = simd::clamp(f.depth, F(0.0f), F(1.0f));
    z = simd::select(z >= F(0.0f), z, F(0.0f));  // NaN
    if (depth_test) f.live = f.live & depth_passes<N>(depth_func, z, stored);
  }
  const uint32_t live = simd::bits(f.live);
  if (live == 0) return;
  int32_t* color_at = reinterpret_cast<int32_t*>(fb.color_block(x, y));
  if constexpr (kHalf) {  // part 0 alone, to the block's rows from y
    if (depth_test && depth_write) {
      const F out = live == 0xffu ? z : simd::select(f.live, z, stored);
      std::memcpy(depth_at, &out.p[0], sizeof out.p[0]);
    }
    if (live == 0xffu) {
      std::memcpy(color_at, &packed.p[0], sizeof packed.p[0]);
    } else {
      I old;
      std::memcpy(&old.p[0], color_at, sizeof old.p[0]);
      old.p[1] = old.p[0];
      const I out = simd::select(f.live, packed, old);
      std::memcpy(color_at, &out.p[0], sizeof out.p[0]);
    }
    return;
  }
  // The live lanes only (simd::store_lanes: masked stores at AVX-512, where blending into the
  // loaded depth kept `stored` live across the shader, spilled and reloaded around the early test:
  // about 1 % of quad_grid's and diablo3's time).
  if (depth_test && depth_write) simd::store_lanes(f.live, live, z, depth_at);
  if (blend_mode == BlendMode::kOpaque) {
    simd::store_lanes(f.live, live, packed, color_at);
    return;
  }
  if (f.has_rgba8) f.color = unpack_rgba8<N>(f.rgba8);
  I old = I::load(color_at);
  simd::select(f.live, blend<N>(blend_mode, f.color, old), old).store(color_at);
}

// Where shade_mixed_wide's lanes find their triangles' plane coefficients: x_ref(), y_ref(),
// inv_w(j) (a0, dadx, dady for j = 0, 1, 2) and var(i, j), each a vector whose lane l holds the
// coefficient of the triangle that covers pixel l (triangle 0's where none does: finite, never
// written). Three sources give the same values (copies, no arithmetic).

// The depth of each covered pixel of a MixedBlock from its own triangle's plane, clamped to
// [0, 1] as shade_block_wide computes it; `z` (the stored depth) elsewhere. One plane at a time.
template <int N>
SOFTRAST_SIMD_INLINE void mixed_depth_by_triangle(const MixedBlock& block, const simd::Float<N>& px,
                                                  const simd::Float<N>& py, simd::Float<N>& z) {
  using F = simd::Float<N>;
  for (int k = 0; k < block.count; ++k) {
    const Interpolants& in = *block.winner[k];
    F own = eval_plane<N>(in.z, px - F(in.x_ref), py - F(in.y_ref));
    z = simd::select(simd::lanes_of<N>(block.mask[k]), simd::clamp(own, F(0.0f), F(1.0f)), z);
  }
}

// Any number of triangles, below AVX-512: the coefficients as a table in memory (entry k of a
// row: triangle k's), one permute per row. (MixedMerged, AVX-512's, made spheres_1m phong 7 %
// slower at AVX2, whose selects are twice as many, 8-lane, instructions.)
template <class S, int N>
struct MixedTable {
  static_assert(N < 16);
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  static constexpr int kN = S::kVaryings > 0 ? S::kVaryings : 1;
  enum { kXRef, kYRef, kInvW, kVar = kInvW + 3, kRows = kVar + 3 * kN };
  alignas(64) float table[kRows][16];
  I lane_winner;

  SOFTRAST_SIMD_INLINE explicit MixedTable(const MixedBlock& block) : lane_winner(0) {
    for (int k = 0; k < block.count; ++k) {
      const Interpolants& in = *block.winner[k];
      table[kXRef][k] = in.x_ref;
      table[kYRef][k] = in.y_ref;
      table[kInvW][k] = in.inv_w.a0;
      table[kInvW + 1][k] = in.inv_w.dadx;
      table[kInvW + 2][k] = in.inv_w.dady;
      for (int i = 0; i < S::kVaryings; ++i) {
        table[kVar + 3 * i][k] = in.var[i].a0;
        table[kVar + 3 * i + 1][k] = in.var[i].dadx;
        table[kVar + 3 * i + 2][k] = in.var[i].dady;
      }
      lane_winner = simd::select(simd::lanes_of<N>(block.mask[k]), I(k), lane_winner);
    }
  }
  SOFTRAST_SIMD_INLINE F row(int r) const { return simd::lookup16<N>(table[r], lane_winner); }
  SOFTRAST_SIMD_INLINE F x_ref() const { return row(kXRef); }
  SOFTRAST_SIMD_INLINE F y_ref() const { return row(kYRef); }
  SOFTRAST_SIMD_INLINE F inv_w(int j) const { return row(kInvW + j); }
  SOFTRAST_SIMD_INLINE F var(int i, int j) const { return row(kVar + 3 * i + j); }
  // mixed_depth_by_triangle's depths of the covered pixels, one plane at a time.
  SOFTRAST_SIMD_INLINE void depth(const MixedBlock& block, const F& px, const F& py, const F&,
                                  const F&, F& z) const {
    mixed_depth_by_triangle<N>(block, px, py, z);
  }
};

// Two triangles (most blocks of several: a mesh's edges cut blocks in two): each coefficient
// broadcast from the two records and blended by the second triangle's lanes, one blend per
// register. The table above is written float by float and read back 64 bytes at a time, which
// the store buffer cannot forward: its loads wait for every store before them. (At AVX-512, two
// records loaded whole and one two-source permute per coefficient measured the same as this;
// three or four triangles by two permutes and a blend, no faster than the table.)
template <class S, int N>
struct MixedPair {
  using F = simd::Float<N>;
  const Interpolants& first;
  const Interpolants& second;
  simd::Int<N> second_lanes;

  SOFTRAST_SIMD_INLINE explicit MixedPair(const MixedBlock& block)
      : first(*block.winner[0]),
        second(*block.winner[1]),
        second_lanes(simd::lanes_of<N>(block.mask[1])) {}
  SOFTRAST_SIMD_INLINE F pick(float a, float b) const {
    return simd::select(second_lanes, F(b), F(a));
  }
  SOFTRAST_SIMD_INLINE F x_ref() const { return pick(first.x_ref, second.x_ref); }
  SOFTRAST_SIMD_INLINE F y_ref() const { return pick(first.y_ref, second.y_ref); }
  static float coefficient(const Plane& p, int j) {
    return j == 0 ? p.a0 : j == 1 ? p.dadx : p.dady;
  }
  SOFTRAST_SIMD_INLINE F inv_w(int j) const {
    return pick(coefficient(first.inv_w, j), coefficient(second.inv_w, j));
  }
  SOFTRAST_SIMD_INLINE F var(int i, int j) const {
    return pick(coefficient(first.var[i], j), coefficient(second.var[i], j));
  }
  // At AVX-512 each lane's depth plane is picked (the two planes' coefficients blended by the
  // second triangle's lanes) and evaluated once, eval_plane's operations on per-lane
  // coefficients and the lane's own offsets (MixedMerged's depth, the same bits); elsewhere one
  // plane at a time. Evaluated for both triangles, the depth was about 60 of a block's 480
  // instructions.
  SOFTRAST_SIMD_INLINE void depth(const MixedBlock& block, const F& px, const F& py, const F& dx,
                                  const F& dy, F& z) const {
    if constexpr (N == 16) {
      using D = typename simd::Native<N>::D;
      const uint32_t bits = block.mask[1];
      D a0, dadx, dady;
      simd::isa::pick(bits, first.z.a0, second.z.a0, a0);
      simd::isa::pick(bits, first.z.dadx, second.z.dadx, dadx);
      simd::isa::pick(bits, first.z.dady, second.z.dady, dady);
      const D x = __builtin_convertvector(dx.p[0], D), y = __builtin_convertvector(dy.p[0], D);
      z.p[0] = __builtin_convertvector((a0 + dadx * x) + dady * y, typename simd::Native<N>::F);
      z = simd::clamp(z, F(0.0f), F(1.0f));  // lanes no triangle covers: the first's, never used
    } else {
      mixed_depth_by_triangle<N>(block, px, py, z);
    }
  }
};

// Any number of triangles at AVX-512, built in registers: every coefficient row starts as
// triangle 0's value, and each further triangle's value is broadcast into its own lanes (one
// masked broadcast per row and triangle). MixedTable's float stores and whole-row loads missed
// store forwarding: its first row's permute took a sixth of spheres_1m gouraud's mixed-block
// samples, where most blocks hold three to eight triangles (spheres_1m phong, one thread: 54.3
// -> 52.1 ms).
template <class S, int N>
struct MixedMerged {
  static_assert(N == 16);
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  using D = typename simd::Native<N>::D;
  static constexpr int kN = S::kVaryings > 0 ? S::kVaryings : 1;
  F ref[2];    // x_ref, y_ref
  F w[3];      // inv_w's a0, dadx, dady
  F v[kN][3];  // var[i]'s a0, dadx, dady
  // The depth planes' a0, dadx, dady, lanes 0 to 7 and 8 to 15.
  simd::isa::D8 z_low[3], z_high[3];

  SOFTRAST_SIMD_INLINE explicit MixedMerged(const MixedBlock& block) {
    using P = MixedPair<S, N>;
    const Interpolants& first = *block.winner[0];
    ref[0] = F(first.x_ref);
    ref[1] = F(first.y_ref);
    for (int j = 0; j < 3; ++j) w[j] = F(P::coefficient(first.inv_w, j));
    for (int i = 0; i < S::kVaryings; ++i) {
      for (int j = 0; j < 3; ++j) v[i][j] = F(P::coefficient(first.var[i], j));
    }
    const double* planes[3] = {&first.z.a0, &first.z.dadx, &first.z.dady};
    for (int j = 0; j < 3; ++j) z_low[j] = z_high[j] = simd::isa::D8{} + *planes[j];
    for (int k = 1; k < block.count; ++k) {
      const Interpolants& t = *block.winner[k];
      const I lanes = simd::lanes_of<N>(block.mask[k]);
      ref[0] = simd::select(lanes, F(t.x_ref), ref[0]);
      ref[1] = simd::select(lanes, F(t.y_ref), ref[1]);
      for (int j = 0; j < 3; ++j) w[j] = simd::select(lanes, F(P::coefficient(t.inv_w, j)), w[j]);
      for (int i = 0; i < S::kVaryings; ++i) {
        for (int j = 0; j < 3; ++j) {
          v[i][j] = simd::select(lanes, F(P::coefficient(t.var[i], j)), v[i][j]);
        }
      }
      simd::isa::merge(block.mask[k], t.z.a0, z_low[0], z_high[0]);
      simd::isa::merge(block.mask[k], t.z.dadx, z_low[1], z_high[1]);
      simd::isa::merge(block.mask[k], t.z.dady, z_low[2], z_high[2]);
    }
  }
  SOFTRAST_SIMD_INLINE F x_ref() const { return ref[0]; }
  SOFTRAST_SIMD_INLINE F y_ref() const { return ref[1]; }
  SOFTRAST_SIMD_INLINE F inv_w(int j) const { return w[j]; }
  SOFTRAST_SIMD_INLINE F var(int i, int j) const { return v[i][j]; }
  // Each lane's depth plane evaluated once, as MixedPair's (the same bits; lanes no triangle
  // covers get the first's, never used).
  SOFTRAST_SIMD_INLINE void depth(const MixedBlock&, const F&, const F&, const F& dx, const F& dy,
                                  F& depth) const {
    D z[3];
    for (int j = 0; j < 3; ++j) simd::isa::join(z_low[j], z_high[j], z[j]);
    const D x = __builtin_convertvector(dx.p[0], D), y = __builtin_convertvector(dy.p[0], D);
    depth.p[0] = __builtin_convertvector((z[0] + z[1] * x) + z[2] * y, typename simd::Native<N>::F);
    depth = simd::clamp(depth, F(0.0f), F(1.0f));
  }
};

// Shades a block whose pixels several triangles of one facing cover (MixedBlock) with shader S
// on N-lane vectors. Each lane takes its own triangle's plane coefficients (`coef`, above), and
// then runs shade_block_wide's operations in the same order: every pixel gets the bits its
// triangle's own call would give it. Resolved (deferred tiles): the pixels are the ones each
// triangle won, and their depth is already in the framebuffer (the value that call would
// compute). Otherwise (immediate tiles, BlockBatch): the triangles cover disjoint pixels, and
// each lane is depth-tested and written as that call would do it.
template <class S, int N, class Coefficients>
SOFTRAST_SIMD_INLINE void shade_mixed_with(const S& shader, const ShadeTarget& target,
                                           const MixedBlock& block, int x, int y,
                                           const Coefficients& coef) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  constexpr int kN = S::kVaryings > 0 ? S::kVaryings : 1;
  Framebuffer& fb = *target.framebuffer;
  uint32_t all = 0;
  for (int k = 0; k < block.count; ++k) all |= block.mask[k];
  const F x_ref = coef.x_ref(), y_ref = coef.y_ref();
  const F a0 = coef.inv_w(0), dadx = coef.inv_w(1), dady = coef.inv_w(2);

  Fragments<N> f;
  f.x = simd::to_float(I(x) + simd::lane_column<N>()) + F(0.5f);
  f.y = simd::to_float(I(y) + simd::lane_row<N>()) + F(0.5f);
  F dx = f.x - x_ref, dy = f.y - y_ref;
  f.live = simd::lanes_of<N>(all);
  float* depth_at = fb.depth_block(x, y);
  const F stored = F::load(depth_at);
  F z = stored;
  if (!target.resolved) {
    // Immediate (the state deferred shading needs: opaque, depth test less or less-equal with
    // writes): each lane's depth from its own triangle's plane, as shade_block_wide computes it,
    // and the early test.
    coef.depth(block, f.x, f.y, dx, dy, z);
    // LESS or LEQUAL (the only tests a batch is made for), without a switch.
    I passes = z < stored;
    if (target.state->depth_func == DepthFunc::kLessEqual) passes = passes | (z == stored);
    f.live = f.live & passes;
    if (!simd::any(f.live)) return;
  }
  f.depth = z;
  // eval_plane's operations, with per-lane coefficients.
  F inv_w = a0 + dadx * dx + dady * dy;
  F w = guarded_w<N>(inv_w);
  F var[kN];
  for (int i = 0; i < S::kVaryings; ++i) {
    var[i] = (coef.var(i, 0) + coef.var(i, 1) * dx + coef.var(i, 2) * dy) * w;
  }
  f.varyings = var;
  f.front_facing = block.front_facing;
  f.several_triangles = true;
  f.color = {F(0.0f), F(0.0f), F(0.0f), F(1.0f)};
  const uint32_t shaded = simd::bits(f.live);
  shader.template shade<N>(f);
  const I packed = f.has_rgba8 ? f.rgba8 : pack_rgba8<N>(f.color);  // (as shade_block_wide)
  const uint32_t live = simd::bits(f.live);
  if (live != shaded) undeclared_discard();
  int32_t* color_at = reinterpret_cast<int32_t*>(fb.color_block(x, y));
  if (!target.resolved) simd::store_lanes(f.live, live, z, depth_at);
  simd::store_lanes(f.live, live, packed, color_at);
}

template <class S, int N>
SOFTRAST_SIMD_INLINE void shade_mixed_wide(const S& shader, const ShadeTarget& target,
                                           const MixedBlock& block, int x, int y) {
  if (block.count == 2) {
    shade_mixed_with<S, N>(shader, target, block, x, y, MixedPair<S, N>(block));
  } else if constexpr (N == 16) {
    shade_mixed_with<S, N>(shader, target, block, x, y, MixedMerged<S, N>(block));
  } else {
    shade_mixed_with<S, N>(shader, target, block, x, y, MixedTable<S, N>(block));
  }
}

template <class S, int N>
SOFTRAST_SIMD_INLINE void shade_block_level(const void* shader, const ShadeTarget& target,
                                            const Interpolants& interp, int x, int y,
                                            uint32_t mask) {
  const S& s = *static_cast<const S*>(shader);
#if defined(SOFTRAST_SHADERS_BASELINE_ONLY)
  // The general variant alone (the same results; half the code to build and instrument).
  shade_block_wide<S, N, false>(s, target, interp, x, y, mask);
#else
  const RenderState& st = *target.state;
  bool common = !WritesDepth<S> && st.depth_test && st.depth_func == DepthFunc::kLess &&
                st.depth_write && st.blend == BlendMode::kOpaque;
  if (common || target.resolved) {
    if constexpr (simd::Float<N>::kParts == 2 && !WritesDepth<S>) {  // AVX2: halves alone
      if ((mask & 0xffu) == 0)
        return shade_block_wide<S, N, true, true>(s, target, interp, x, y + 2, mask >> 8);
      if ((mask >> 8) == 0)
        return shade_block_wide<S, N, true, true>(s, target, interp, x, y, mask);
    }
    shade_block_wide<S, N, true>(s, target, interp, x, y, mask);
  } else {
    shade_block_wide<S, N, false>(s, target, interp, x, y, mask);
  }
#endif
}

// One entry point per SIMD level. `flatten` inlines the shader and everything it calls, so the
// whole block is compiled for the level's instruction set.
template <class S>
[[gnu::flatten]] void shade_block_sse2(const void* shader, const ShadeTarget& target,
                                       const Interpolants& interp, int x, int y, uint32_t mask) {
  shade_block_level<S, 4>(shader, target, interp, x, y, mask);
}
template <class S>
[[gnu::target("sse4.2"), gnu::flatten]] void shade_block_sse4(const void* shader,
                                                              const ShadeTarget& target,
                                                              const Interpolants& interp, int x,
                                                              int y, uint32_t mask) {
  shade_block_level<S, 4>(shader, target, interp, x, y, mask);
}
template <class S>
[[gnu::target("avx2,fma"), gnu::flatten]] void shade_block_avx2(const void* shader,
                                                                const ShadeTarget& target,
                                                                const Interpolants& interp, int x,
                                                                int y, uint32_t mask) {
  shade_block_level<S, 8>(shader, target, interp, x, y, mask);
}
template <class S>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void shade_block_avx512(
    const void* shader, const ShadeTarget& target, const Interpolants& interp, int x, int y,
    uint32_t mask) {
  shade_block_level<S, 16>(shader, target, interp, x, y, mask);
}

template <class S>
[[gnu::flatten]] void shade_mixed_sse2(const void* shader, const ShadeTarget& target,
                                       const MixedBlock& block, int x, int y) {
  shade_mixed_wide<S, 4>(*static_cast<const S*>(shader), target, block, x, y);
}
template <class S>
[[gnu::target("sse4.2"), gnu::flatten]] void shade_mixed_sse4(const void* shader,
                                                              const ShadeTarget& target,
                                                              const MixedBlock& block, int x,
                                                              int y) {
  shade_mixed_wide<S, 4>(*static_cast<const S*>(shader), target, block, x, y);
}
template <class S>
[[gnu::target("avx2,fma"), gnu::flatten]] void shade_mixed_avx2(const void* shader,
                                                                const ShadeTarget& target,
                                                                const MixedBlock& block, int x,
                                                                int y) {
  shade_mixed_wide<S, 8>(*static_cast<const S*>(shader), target, block, x, y);
}
template <class S>
[[gnu::target("avx512f,avx512bw,avx512dq,avx512vl"), gnu::flatten]] void shade_mixed_avx512(
    const void* shader, const ShadeTarget& target, const MixedBlock& block, int x, int y) {
  shade_mixed_wide<S, 16>(*static_cast<const S*>(shader), target, block, x, y);
}

// SOFTRAST_SHADERS_BASELINE_ONLY (the fuzz and sanitizer builds define it) compiles each shader
// for the baseline alone, in its general variant only: the sanitizers' instrumentation of every
// shader at four levels made the two files that hold the built-in shaders take most of an hour
// to build. Shading is then SSE2 at every simd_level(); the tile and vertex kernels still follow
// it.
template <class S>
ShadeBlockFn wide_shade_block([[maybe_unused]] SimdLevel level) {
#if defined(SOFTRAST_SHADERS_BASELINE_ONLY)
  return &shade_block_sse2<S>;
#else
  switch (level) {
    case SimdLevel::kAvx512:
      return &shade_block_avx512<S>;
    case SimdLevel::kAvx2:
      return &shade_block_avx2<S>;
    case SimdLevel::kSse4:
      return &shade_block_sse4<S>;
    case SimdLevel::kSse2:
      break;
  }
  return &shade_block_sse2<S>;
#endif
}

template <class S>
ShadeMixedFn wide_shade_mixed([[maybe_unused]] SimdLevel level) {
#if defined(SOFTRAST_SHADERS_BASELINE_ONLY)
  return &shade_mixed_sse2<S>;
#else
  switch (level) {
    case SimdLevel::kAvx512:
      return &shade_mixed_avx512<S>;
    case SimdLevel::kAvx2:
      return &shade_mixed_avx2<S>;
    case SimdLevel::kSse4:
      return &shade_mixed_sse4<S>;
    case SimdLevel::kSse2:
      break;
  }
  return &shade_mixed_sse2<S>;
#endif
}

}  // namespace detail
}  // namespace softrast

#pragma GCC diagnostic pop
