// pipeline/tile_kernel.inl: the body of the tile kernels (tile_kernels.hpp), written once and
// included by tile_kernels.cpp once per instruction set, inside its own namespace, with
// SOFTRAST_LANES (4, 8 or 16 lanes of 32 bits) defined and the matching `#pragma GCC target` in
// force. Vectors are GCC vector extensions; only pointers and scalars cross the entry points, so
// the ABIs of the three copies never meet.

constexpr int kLanes = SOFTRAST_LANES;
constexpr int kGroups = 16 / kLanes;  // a 4x4 block is kGroups vectors of kLanes pixels
typedef float F __attribute__((vector_size(4 * kLanes)));
typedef int32_t I __attribute__((vector_size(4 * kLanes)));
typedef int64_t L __attribute__((vector_size(8 * kLanes)));
typedef double D __attribute__((vector_size(8 * kLanes)));

// Lane l of group g is pixel p = g * kLanes + l of the block: column p & 3, row p >> 2 (the bit
// of the coverage masks).
[[gnu::always_inline]] inline I pixel_index(int g) {
  I v;
  for (int l = 0; l < kLanes; ++l) v[l] = g * kLanes + l;
  return v;
}

// The sign bits of the lanes (all-ones or zero) as bits 0 .. kLanes-1.
[[gnu::always_inline]] inline uint32_t lane_bits(I v) {
#if SOFTRAST_LANES == 16
  return uint32_t(_mm512_movepi32_mask(reinterpret_cast<__m512i>(v)));
#elif SOFTRAST_LANES == 8
  return uint32_t(_mm256_movemask_ps(reinterpret_cast<__m256>(v)));
#else
  return uint32_t(_mm_movemask_ps(reinterpret_cast<__m128>(v)));
#endif
}

// ---------------------------------------------------------------------------------------------
// Coverage of one 4x4 block: E(pixel) = E(block's first sample) + a * 256 * column + b * 256 *
// row for each edge; a pixel is covered when all three are >= 0, i.e. when the bitwise or of the
// three is (the sign bit of the or is set iff one of them is negative).

template <class V>
struct EdgeOffsets {
  V off[3][kGroups];
};

template <class V, class T>
[[gnu::always_inline]] inline void make_offsets(const TriRecord& t, EdgeOffsets<V>& o) {
  for (int g = 0; g < kGroups; ++g) {
    I p = pixel_index(g);
    V column = __builtin_convertvector(p & 3, V), row = __builtin_convertvector(p >> 2, V);
    for (int k = 0; k < 3; ++k) {
      o.off[k][g] = T(t.edge(k).a * kSubpixelOne) * column + T(t.edge(k).b * kSubpixelOne) * row;
    }
  }
}

// The exact 64-bit path in the level's native vectors of int64 (2, 4 or 8 lanes): the broadcast
// of each edge value and the sign bits written out, because GCC lowers the kLanes-wide int64
// vectors above (two native registers) through the stack, lane by lane, and turns the 64-bit
// comparison into 32-bit lanes by scalar extraction: that made the partial blocks of large
// triangles cost several times a 32-bit block. `off`: EdgeOffsets<L>'s 3 x 16 values, pixel order.
#if SOFTRAST_LANES == 16
typedef int64_t LN __attribute__((vector_size(64)));
[[gnu::always_inline]] inline LN splat64(int64_t v) {
  return reinterpret_cast<LN>(_mm512_set1_epi64(v));
}
[[gnu::always_inline]] inline uint32_t sign_bits64(LN v) {
  return uint32_t(_mm512_movepi64_mask(reinterpret_cast<__m512i>(v)));
}
#elif SOFTRAST_LANES == 8
typedef int64_t LN __attribute__((vector_size(32)));
[[gnu::always_inline]] inline LN splat64(int64_t v) {
  return reinterpret_cast<LN>(_mm256_set1_epi64x(v));
}
[[gnu::always_inline]] inline uint32_t sign_bits64(LN v) {
  return uint32_t(_mm256_movemask_pd(reinterpret_cast<__m256d>(v)));
}
#else
typedef int64_t LN __attribute__((vector_size(16)));
[[gnu::always_inline]] inline LN splat64(int64_t v) {
  return reinterpret_cast<LN>(_mm_set1_epi64x(v));
}
[[gnu::always_inline]] inline uint32_t sign_bits64(LN v) {
  return uint32_t(_mm_movemask_pd(reinterpret_cast<__m128d>(v)));
}
#endif
constexpr int kNative64 = int(sizeof(LN) / 8);

[[gnu::always_inline]] inline uint32_t coverage_bits_64(const int64_t e[3], const int64_t* off) {
  LN e0 = splat64(e[0]), e1 = splat64(e[1]), e2 = splat64(e[2]);
  uint32_t negative = 0;
  for (int part = 0; part < 16 / kNative64; ++part) {
    LN a, b, c;
    std::memcpy(&a, off + part * kNative64, sizeof(LN));
    std::memcpy(&b, off + 16 + part * kNative64, sizeof(LN));
    std::memcpy(&c, off + 32 + part * kNative64, sizeof(LN));
    negative |= sign_bits64((e0 + a) | (e1 + b) | (e2 + c)) << (part * kNative64);
  }
  return ~negative & 0xffffu;
}

// `e`: the three edge functions at the block's first sample. T is int32_t only where
// fixed_point.hpp's kSmallTriangleFx8 bound proves every value fits.
template <class V, class T>
[[gnu::always_inline]] inline uint32_t coverage_bits(const int64_t e[3], const EdgeOffsets<V>& o) {
  if constexpr (sizeof(T) == 8) {
    static_assert(sizeof(o.off) == 3 * 16 * sizeof(int64_t));
    return coverage_bits_64(e, reinterpret_cast<const int64_t*>(o.off));
  } else {
    // A pixel is outside where the or of its three values is negative: its sign bit, read
    // straight off (GCC had made `all >= 0` a minimum and a comparison first).
    static_assert(std::is_same_v<V, I>);
    uint32_t outside = 0;
    for (int g = 0; g < kGroups; ++g) {
      V all = (T(e[0]) + o.off[0][g]) | (T(e[1]) + o.off[1][g]) | (T(e[2]) + o.off[2][g]);
      outside |= lane_bits(all) << (g * kLanes);
    }
    return ~outside & 0xffffu;
  }
}

// ---------------------------------------------------------------------------------------------
// The depth resolve of one block (tile_visibility.hpp): the fragment stage's depth, exactly, tested
// against the tile's depth; where it passes, depth and winner id are written.
//
// The fragment stage computes dx = (float(px) + 0.5f) - x_ref and z = clamp(float((a0 + dadx * dx)
// + dady * dy), 0, 1), the plane in double (interpolants.hpp: DepthPlane), with std::clamp (NaN
// stays NaN, -0 stays -0), without contraction. Here float(px) + 0.5f is formed as (float(x) +
// 0.5f) + column: both are exact (integers and half-integers below 2^23, the image is at most
// 16384 wide), so only the subtraction of x_ref rounds, as there. std::clamp(z, 0, 1) is `z < 0 ?
// 0 : (1 < z ? 1 : z)`, which is exactly max(0, min(1, z)) with x86's operand order (MINPS returns
// its second operand unless the first is smaller, so NaN and -0 come through as z).

// A triangle's depth plane over an area of at most a tile, as its two halves: the fragment
// stage's (a0 + dadx * dx) + dady * dy is the sum of a term per block column and a term per block
// row, each computed once from the same operands (so each block's z is the same double sum, for
// one addition and one rounding to float).
struct DepthTerms {
  static constexpr int kMax = kTileSize / kBlockSize;
  D x_term[kMax][kGroups];  // a0 + dadx * dx, block column i (pixels x0 + 4 i ..)
  D y_term[kMax][kGroups];  // dady * dy, block row j
  int x0, y0;
  int32_t id;
  // A plane of constant depth (see depth_terms): every pixel's z is z_const, the terms are unset.
  bool constant;
  float z_const;
};

// Terms for the blocks of [x0, x1) x [y0, y1); x0 and y0 multiples of 4, at most a tile.
[[gnu::always_inline]] inline void depth_terms(const Interpolants& in, int32_t id, int x0, int x1,
                                               int y0, int y1, DepthTerms& d) {
  d.x0 = x0;
  d.y0 = y0;
  d.id = id;
  // A polygon parallel to the image (a sprite, a user interface, a screen-aligned quad) has a
  // plane of constant depth: both gradients zero. Its (a0 + dadx * dx) + dady * dy is then a0
  // exactly at every pixel (the products are zeros, dx and dy being finite, and adding a zero of
  // either sign to a finite non-zero a0 returns a0), so every pixel's z is float(a0), the same
  // bits, without a double addition and a conversion per pixel (about half the cost of an 8-lane
  // group at AVX2). A zero or non-finite a0 keeps the general path (-0 + +0 is +0, NaN payloads).
  d.constant = in.z.dadx == 0.0 && in.z.dady == 0.0 && std::isfinite(in.z.a0) && in.z.a0 != 0.0;
  d.z_const = float(in.z.a0);
  if (d.constant) return;
  F x_ref = F{} + in.x_ref, y_ref = F{} + in.y_ref;
  D a0 = D{} + in.z.a0, dadx = D{} + in.z.dadx, dady = D{} + in.z.dady;
  for (int g = 0; g < kGroups; ++g) {
    I p = pixel_index(g);
    F column = __builtin_convertvector(p & 3, F), row = __builtin_convertvector(p >> 2, F);
    for (int i = 0; x0 + kBlockSize * i < x1; ++i) {
      F dx = ((F{} + (float(x0 + kBlockSize * i) + 0.5f)) + column) - x_ref;
      d.x_term[i][g] = a0 + dadx * __builtin_convertvector(dx, D);
    }
    for (int j = 0; y0 + kBlockSize * j < y1; ++j) {
      F dy = ((F{} + (float(y0 + kBlockSize * j) + 0.5f)) + row) - y_ref;
      d.y_term[j][g] = dady * __builtin_convertvector(dy, D);
    }
  }
}

// min(1, z) and max(0, z) with the operand order of std::clamp (see above).
[[gnu::always_inline]] inline F clamp01(F z) {
#if SOFTRAST_LANES == 16
  __m512 m = _mm512_min_ps(_mm512_set1_ps(1.0f), reinterpret_cast<__m512>(z));
  return reinterpret_cast<F>(_mm512_max_ps(_mm512_setzero_ps(), m));
#elif SOFTRAST_LANES == 8
  __m256 m = _mm256_min_ps(_mm256_set1_ps(1.0f), reinterpret_cast<__m256>(z));
  return reinterpret_cast<F>(_mm256_max_ps(_mm256_setzero_ps(), m));
#else
  __m128 m = _mm_min_ps(_mm_set1_ps(1.0f), reinterpret_cast<__m128>(z));
  return reinterpret_cast<F>(_mm_max_ps(_mm_setzero_ps(), m));
#endif
}

// Depth test of the lanes of `mask` (bits of the group's pixels) and the write of the winners.
// kBlend (AVX2): by blends and whole stores instead of masked stores (core/store_mode.hpp).
template <bool kLessEqual, bool kBlend>
[[gnu::always_inline]] inline void test_and_write(F z, uint32_t mask, int32_t id, float* depth,
                                                  int32_t* ids) {
#if SOFTRAST_LANES == 16
  // AVX-512: the test runs under the coverage mask and the winners are masked stores.
  __m512 stored = _mm512_loadu_ps(depth);
  __mmask16 pass = _mm512_mask_cmp_ps_mask(__mmask16(mask), reinterpret_cast<__m512>(z), stored,
                                           kLessEqual ? _CMP_LE_OQ : _CMP_LT_OQ);
  _mm512_mask_storeu_ps(depth, pass, reinterpret_cast<__m512>(z));
  _mm512_mask_storeu_epi32(ids, pass, _mm512_set1_epi32(id));
#else
  F stored;
  std::memcpy(&stored, depth, sizeof(F));
  I bit = I{} + 1;
  for (int l = 0; l < kLanes; ++l) bit[l] <<= l;
  I covered = ((I{} + int32_t(mask)) & bit) != 0;
  I pass = (kLessEqual ? (z <= stored) : (z < stored)) & covered;
#if SOFTRAST_LANES == 8
  if constexpr (!kBlend) {
    // AVX2: the winners' depth and id by masked stores (VMASKMOVPS, VPMASKMOVD), as AVX-512
    // does; blending into the loaded values and storing them whole read the ids for nothing.
    _mm256_maskstore_ps(depth, reinterpret_cast<__m256i>(pass), reinterpret_cast<__m256>(z));
    _mm256_maskstore_epi32(ids, reinterpret_cast<__m256i>(pass), _mm256_set1_epi32(id));
    return;
  }
#endif
  I winner;
  std::memcpy(&winner, ids, sizeof(I));
  stored = pass ? z : stored;
  winner = pass ? (I{} + id) : winner;
  std::memcpy(depth, &stored, sizeof(F));
  std::memcpy(ids, &winner, sizeof(I));
#endif
}

template <bool kLessEqual, bool kBlend>
[[gnu::always_inline]] inline void resolve_lanes(const DepthTerms& d, int x, int y, uint32_t mask,
                                                 float* depth, int32_t* ids) {
  if (d.constant) {
    const F z = clamp01(F{} + d.z_const);
    for (int g = 0; g < kGroups; ++g) {
      uint32_t group_mask = (mask >> (g * kLanes)) & ((1u << kLanes) - 1u);
      if (kGroups > 1 && group_mask == 0) continue;
      test_and_write<kLessEqual, kBlend>(z, group_mask, d.id, depth + g * kLanes, ids + g * kLanes);
    }
    return;
  }
  const D* x_term = d.x_term[(x - d.x0) >> 2];
  const D* y_term = d.y_term[(y - d.y0) >> 2];
  for (int g = 0; g < kGroups; ++g) {
    uint32_t group_mask = (mask >> (g * kLanes)) & ((1u << kLanes) - 1u);
    if (kGroups > 1 && group_mask == 0) continue;
    F z = clamp01(__builtin_convertvector(x_term[g] + y_term[g], F));
    test_and_write<kLessEqual, kBlend>(z, group_mask, d.id, depth + g * kLanes, ids + g * kLanes);
  }
}

// ---------------------------------------------------------------------------------------------
// One record in one tile.

// The deferred modes: the depth function, and the AVX2 resolve's way of writing (kBlend: see
// test_and_write).
enum class Mode { kImmediate, kLess, kLessEqual, kLessBlend, kLessEqualBlend };
constexpr bool is_less_equal(Mode m) {
  return m == Mode::kLessEqual || m == Mode::kLessEqualBlend;
}
constexpr bool is_blend(Mode m) {
  return m == Mode::kLessBlend || m == Mode::kLessEqualBlend;
}

// The pixels of the block at (x, y) inside the tile's region (only the image's last row and
// column of tiles are cut).
[[gnu::always_inline]] inline uint32_t region_bits(const PixelRect& r, int x, int y) {
  if (x + kBlockSize <= r.x1 && y + kBlockSize <= r.y1) return 0xffffu;
  return block_rect_mask(0, std::min(kBlockSize, r.x1 - x), 0, std::min(kBlockSize, r.y1 - y));
}

// Copies a block's depth in from the framebuffer before its first test: one 64-byte line.
[[gnu::always_inline]] inline void load_depth(TileVisibility& v, int b, int x, int y) {
  const float* from = v.framebuffer->depth_block(x, y);
#if SOFTRAST_LANES == 16
  _mm512_store_ps(v.depth[b], _mm512_load_ps(from));
#elif SOFTRAST_LANES == 8
  _mm256_store_ps(v.depth[b], _mm256_load_ps(from));
  _mm256_store_ps(v.depth[b] + 8, _mm256_load_ps(from + 8));
#else
  for (int k = 0; k < 16; k += 4) _mm_store_ps(v.depth[b] + k, _mm_load_ps(from + k));
#endif
  v.mark_loaded(b);
}

// Where a record's covered blocks go: the fragment stage, or the tile's depth resolve.
template <Mode kMode>
struct BlockTarget {
  TileJob& job;
  const TriRecord& rec;
  DepthTerms depth;

  BlockTarget(TileJob& j, const TriRecord& r, int32_t id, const PixelRect& area) : job(j), rec(r) {
    if constexpr (kMode != Mode::kImmediate) {
      depth_terms(r.interp(), id, area.x0 & ~(kBlockSize - 1), area.x1, area.y0 & ~(kBlockSize - 1),
                  area.y1, depth);
    }
  }
  [[gnu::always_inline]] void operator()(int x, int y, uint32_t bits) {
    if (job.prefetch != nullptr) job.prefetch->step();
    if constexpr (kMode == Mode::kImmediate) {
      if (job.batch != nullptr) {
        job.batch->add(rec.interp(), x, y, bits);
      } else {
        job.program->shade_block(job.program->shader, *job.target, rec.interp(), x, y, bits);
      }
    } else {
      TileVisibility& v = *job.visibility;
      int b = v.block_index(x, y);
      if (!v.loaded(b)) load_depth(v, b, x, y);
      resolve_lanes<is_less_equal(kMode), is_blend(kMode)>(depth, x, y, bits, v.depth[b], v.id[b]);
    }
  }
  // A whole 16x16 area at (x, y), inside the triangle and the tile's region, into the depth
  // resolve (deferred modes only): its 16 blocks in a row, the loads of their depth checked four
  // at a time (the four blocks of a row of the area are four consecutive bits of `touched`).
  [[gnu::always_inline]] void inside_mid_block(int x, int y) {
    static_assert(kMidBlockSize == 4 * kBlockSize && TileVisibility::kBlocksPerRow % 4 == 0);
    TileVisibility& v = *job.visibility;
    for (int j = 0; j < 4; ++j) {
      if (job.prefetch != nullptr) job.prefetch->step();
      int row_y = y + kBlockSize * j;
      int b = v.block_index(x, row_y);
      uint32_t missing = ~uint32_t(v.touched[b >> 6] >> (b & 63)) & 0xfu;
      for (; missing != 0; missing &= missing - 1) {
        int i = __builtin_ctz(missing);
        load_depth(v, b + i, x + kBlockSize * i, row_y);
      }
      for (int i = 0; i < 4; ++i) {
        resolve_lanes<is_less_equal(kMode), is_blend(kMode)>(depth, x + kBlockSize * i, row_y,
                                                             0xffffu, v.depth[b + i], v.id[b + i]);
      }
    }
  }
};

// Exact block classification against the three edges, as tile_raster.cpp's: E is linear, so its
// extremes over the block's samples are at the corner samples picked by the signs of a and b.
// The three edges' values sit in the first three lanes of one vector of four int64 (the fourth
// lane 0, never negative), so a block's test is two additions and two sign masks, and stepping to
// the next block one addition (as scalars, the three edges' values, extents and steps did not fit
// the registers: each block reloaded them and multiplied its position out, about 45 instructions).
typedef int64_t E4 __attribute__((vector_size(32)));
struct EdgeExtents {
  E4 lo, hi;  // added to E at the block's first sample: its minimum and maximum
};
[[gnu::always_inline]] inline EdgeExtents edge_extents(const TriRecord& t, int size) {
  EdgeExtents x{};
  int64_t span = int64_t(size - 1) * kSubpixelOne;
  for (int k = 0; k < 3; ++k) {
    int64_t ax = t.edge(k).a * span, by = t.edge(k).b * span;
    x.lo[k] = std::min<int64_t>(ax, 0) + std::min<int64_t>(by, 0);
    x.hi[k] = std::max<int64_t>(ax, 0) + std::max<int64_t>(by, 0);
  }
  return x;
}
// The sign bits of the four lanes as bits 0 to 3.
[[gnu::always_inline]] inline uint32_t sign_bits4(const E4& v) {
#if SOFTRAST_LANES == 4
  __m128i lo, hi;
  std::memcpy(&lo, &v, 16);
  std::memcpy(&hi, reinterpret_cast<const char*>(&v) + 16, 16);
  return uint32_t(_mm_movemask_pd(_mm_castsi128_pd(lo)) |
                  (_mm_movemask_pd(_mm_castsi128_pd(hi)) << 2));
#else
  return uint32_t(_mm256_movemask_pd(reinterpret_cast<__m256d>(v)));
#endif
}
enum class Test { kOutside, kInside, kPartial };
[[gnu::always_inline]] inline Test classify(const E4& e, const EdgeExtents& x) {
  if (sign_bits4(e + x.hi) != 0) return Test::kOutside;
  return sign_bits4(e + x.lo) != 0 ? Test::kPartial : Test::kInside;
}

// Edge values at the first sample of block (x, y), from those at (x0, y0) (exact int64).
struct EdgeGrid {
  int64_t origin[3], step_x[3], step_y[3];  // per pixel
  int x0, y0;
  void at(int x, int y, int64_t e[3]) const {
    for (int k = 0; k < 3; ++k) {
      e[k] = origin[k] + step_x[k] * (x - x0) + step_y[k] * (y - y0);
    }
  }
  // The same in a vector (by reference: no wide vector is passed or returned by value in the
  // baseline copy of this file, whose ABI has no 32-byte registers).
  [[gnu::always_inline]] void at(int x, int y, E4& e) const {
    int64_t values[3];
    at(x, y, values);
    e = E4{values[0], values[1], values[2], 0};
  }
  // The change of the values from one block to the next right.
  [[gnu::always_inline]] void block_step_x(E4& d) const {
    d = E4{};
    for (int k = 0; k < 3; ++k) d[k] = step_x[k] * kBlockSize;
  }
};

// The blocks of a small triangle's area (the 32-bit bound of fixed_point.hpp holds) classified
// several at once: each block is a lane of kGroups vectors, and one pass of additions and sign
// masks tells which lie outside an edge and which some edge cuts (classify's test, exactly, at
// every block), so that only the blocks the triangle reaches are visited. (Block by block, the
// hierarchical walk below spent about 9 % of diablo3's frame classifying blocks, most of them
// outside a medium triangle's edges, on branches that its varying shapes make unpredictable.)
//
// Every value of a lane whose block overlaps the area is a sample value of that block, so it fits
// in int32; the other lanes are computed in unsigned arithmetic, wrapping harmlessly, and masked
// off.
typedef uint32_t U __attribute__((vector_size(4 * kLanes)));

// Adds group g's bits to `outside` (the lanes' blocks outside an edge) and `cut` (those some edge
// cuts); `v`: E at each lane's block's first sample, `x` the block's extents.
[[gnu::always_inline]] inline void classify_lanes(const U v[3], const EdgeExtents& x, int g,
                                                  uint32_t& outside, uint32_t& cut) {
  const U far =
      (v[0] + uint32_t(x.hi[0])) | (v[1] + uint32_t(x.hi[1])) | (v[2] + uint32_t(x.hi[2]));
  const U near =
      (v[0] + uint32_t(x.lo[0])) | (v[1] + uint32_t(x.lo[1])) | (v[2] + uint32_t(x.lo[2]));
  outside |= lane_bits(I(far)) << (g * kLanes);
  cut |= lane_bits(I(near)) << (g * kLanes);
}

// The blocks of `reached`: bit i the block at(i) (a pair of x and y), emitted whole unless `cut`
// has it, then through partial_block with the edge values at_block(i, e) gives.
template <class At, class Values, class Emit, class Region, class Partial>
[[gnu::always_inline]] inline void visit_reached(uint32_t reached, uint32_t cut, const At& at,
                                                 const Values& at_block, Emit& emit, Region& region,
                                                 Partial& partial_block) {
  for (uint32_t left = reached; left != 0; left &= left - 1) {
    const int i = __builtin_ctz(left);
    const auto [x, y] = at(i);
    if (((cut >> i) & 1u) == 0) {
      emit(x, y, region(x, y));
    } else {
      int64_t e[3];
      at_block(i, e);
      partial_block(x, y, e);
    }
  }
}

// An area wider or taller than 4x4 blocks, a row of blocks at a time (at most 16 in a tile).
template <class Emit, class Region, class Partial>
[[gnu::always_inline]] inline void raster_block_rows(const TriRecord& t, const PixelRect& area,
                                                     const EdgeGrid& grid, Emit& emit,
                                                     Region& region, Partial& partial_block) {
  const EdgeExtents x = edge_extents(t, kBlockSize);
  U column[3][kGroups];           // E's change from the row's first block to the lane's block
  uint32_t step[3], row_step[3];  // E's change to the next block right, and down
  for (int k = 0; k < 3; ++k) {
    step[k] = uint32_t(t.edge(k).a * (kSubpixelOne * kBlockSize));
    row_step[k] = uint32_t(t.edge(k).b * (kSubpixelOne * kBlockSize));
    for (int g = 0; g < kGroups; ++g) column[k][g] = U(pixel_index(g)) * step[k];
  }
  const int bx0 = area.x0 & ~(kBlockSize - 1), by0 = area.y0 & ~(kBlockSize - 1);
  const int columns = (area.x1 - bx0 + kBlockSize - 1) / kBlockSize;  // at most 16 in a tile
  int64_t row[3];
  grid.at(bx0, by0, row);
  uint32_t e_row[3] = {uint32_t(row[0]), uint32_t(row[1]), uint32_t(row[2])};
  for (int y = by0; y < area.y1; y += kBlockSize) {
    uint32_t outside = 0, cut = 0;
    for (int g = 0; g < kGroups; ++g) {
      const U v[3] = {(U{} + e_row[0]) + column[0][g], (U{} + e_row[1]) + column[1][g],
                      (U{} + e_row[2]) + column[2][g]};
      classify_lanes(v, x, g, outside, cut);
    }
    visit_reached(
        ~outside & ((1u << columns) - 1u), cut,
        [&](int i) { return std::pair<int, int>(bx0 + kBlockSize * i, y); },
        [&](int i, int64_t e[3]) {
          for (int k = 0; k < 3; ++k) e[k] = int32_t(e_row[k] + uint32_t(i) * step[k]);
        },
        emit, region, partial_block);
    for (int k = 0; k < 3; ++k) e_row[k] += row_step[k];
  }
}

// An area of at most 4x4 blocks (16x16 pixels), all its blocks at once: lane p the block p & 3
// columns right and p >> 2 rows down of the first (pixel_index's layout, in blocks: the pixel
// offsets `o` times 4).
template <class Emit, class Region, class Partial>
[[gnu::always_inline]] inline void raster_block_square(const TriRecord& t, const PixelRect& area,
                                                       const EdgeGrid& grid,
                                                       const EdgeOffsets<I>& o, Emit& emit,
                                                       Region& region, Partial& partial_block) {
  const EdgeExtents x = edge_extents(t, kBlockSize);
  const int bx0 = area.x0 & ~(kBlockSize - 1), by0 = area.y0 & ~(kBlockSize - 1);
  int64_t origin[3];
  grid.at(bx0, by0, origin);
  uint32_t outside = 0, cut = 0;
  for (int g = 0; g < kGroups; ++g) {
    U v[3];
    for (int k = 0; k < 3; ++k) v[k] = (U{} + uint32_t(origin[k])) + (U(o.off[k][g]) << 2);
    classify_lanes(v, x, g, outside, cut);
  }
  const int columns = (area.x1 - bx0 + kBlockSize - 1) / kBlockSize,
            rows = (area.y1 - by0 + kBlockSize - 1) / kBlockSize;
  const auto at = [&](int i) {
    return std::pair<int, int>(bx0 + kBlockSize * (i & 3), by0 + kBlockSize * (i >> 2));
  };
  visit_reached(
      ~outside & block_rect_mask(0, columns, 0, rows), cut, at,
      [&](int i, int64_t e[3]) {
        const auto [bx, by] = at(i);
        for (int k = 0; k < 3; ++k) {
          e[k] = origin[k] + grid.step_x[k] * (bx - bx0) + grid.step_y[k] * (by - by0);
        }
      },
      emit, region, partial_block);
}

template <Mode kMode, class V, class T>
[[gnu::always_inline]] inline void raster_record_with(TileJob& job, const TriRecord& rec,
                                                      int32_t id, const PixelRect& area,
                                                      const EdgeGrid& grid) {
  const TriRecord& t = rec;
  BlockTarget<kMode> emit(job, rec, id, area);
  EdgeOffsets<V> offsets;
  make_offsets<V, T>(t, offsets);
  int bx0 = area.x0 & ~(kBlockSize - 1), by0 = area.y0 & ~(kBlockSize - 1);
  // Whether every block of the tile's region is whole (the region's right and bottom edges on
  // block boundaries, as they are but for images whose size is not a multiple of 4): then no
  // block needs region_bits. A local, so that the loops below keep it in a register.
  const bool whole_blocks = ((job.region.x1 | job.region.y1) & (kBlockSize - 1)) == 0;
  auto region = [&](int x, int y) {
    return whole_blocks ? 0xffffu : region_bits(job.region, x, y);
  };
  // `e`: the edge values at the block's first sample.
  auto partial_block = [&](int x, int y, const int64_t e[3]) {
    uint32_t bits = coverage_bits<V, T>(e, offsets) & region(x, y);
    if (bits != 0) emit(x, y, bits);
  };
  // Small areas (at most 16x16 pixels of blocks, the usual triangle of a dense mesh): past 2x2
  // blocks, a triangle on the 32-bit path has them classified at once (raster_block_square);
  // otherwise every block's coverage directly, no classification, the edge values stepped from
  // block to block (the exact int64 sums grid.at gives).
  if (area.x1 - bx0 <= kMidBlockSize && area.y1 - by0 <= kMidBlockSize) {
    if constexpr (sizeof(T) == 4) {
      if ((area.x1 - bx0) * (area.y1 - by0) > 4 * kBlockSize * kBlockSize) {
        raster_block_square(t, area, grid, offsets, emit, region, partial_block);
        return;
      }
    }
    int64_t row[3];
    grid.at(bx0, by0, row);
    for (int y = by0; y < area.y1; y += kBlockSize) {
      int64_t e[3] = {row[0], row[1], row[2]};
      for (int x = bx0; x < area.x1; x += kBlockSize) {
        partial_block(x, y, e);
        for (int k = 0; k < 3; ++k) e[k] += grid.step_x[k] * kBlockSize;
      }
      for (int k = 0; k < 3; ++k) row[k] += grid.step_y[k] * kBlockSize;
    }
    return;
  }
  if constexpr (sizeof(T) == 4) {
    raster_block_rows(t, area, grid, emit, region, partial_block);
    return;
  }
  // Larger, past the 32-bit bound: 16x16 blocks, then 4x4 blocks, trivially rejected or accepted
  // (a block inside every edge is emitted without per-pixel tests); only the rest is tested pixel
  // by pixel.
  const EdgeExtents mid = edge_extents(t, kMidBlockSize), small = edge_extents(t, kBlockSize);
  E4 next_block, e;
  grid.block_step_x(next_block);
  int mx0 = area.x0 & ~(kMidBlockSize - 1), my0 = area.y0 & ~(kMidBlockSize - 1);
  for (int my = my0; my < area.y1; my += kMidBlockSize) {
    for (int mx = mx0; mx < area.x1; mx += kMidBlockSize) {
      grid.at(mx, my, e);
      Test test = classify(e, mid);
      if (test == Test::kOutside) continue;
      if constexpr (kMode != Mode::kImmediate) {
        // The usual case of large triangles: the whole area inside, no edge or region cuts it.
        if (test == Test::kInside && mx >= bx0 && my >= by0 && mx + kMidBlockSize <= area.x1 &&
            my + kMidBlockSize <= area.y1) {
          emit.inside_mid_block(mx, my);
          continue;
        }
      }
      // Only blocks that overlap the area (the 32-bit bound in fixed_point.hpp relies on it).
      int y_end = std::min(my + kMidBlockSize, area.y1),
          x_end = std::min(mx + kMidBlockSize, area.x1);
      const int x_begin = std::max(mx, bx0);
      for (int y = std::max(my, by0); y < y_end; y += kBlockSize) {
        if (test == Test::kInside) {
          for (int x = x_begin; x < x_end; x += kBlockSize) emit(x, y, region(x, y));
          continue;
        }
        // A partial area: each block classified, the edge values stepped from block to block.
        grid.at(x_begin, y, e);
        for (int x = x_begin; x < x_end; x += kBlockSize, e += next_block) {
          Test sub = classify(e, small);
          if (sub == Test::kInside) {
            emit(x, y, region(x, y));
          } else if (sub == Test::kPartial) {
            const int64_t values[3] = {e[0], e[1], e[2]};
            partial_block(x, y, values);
          }
        }
      }
    }
  }
}

// A speck whose coverage the SIMD setup computed (TriRecord::blocks): its blocks in this tile, in
// the order the loops above take them. Its covered pixels lie inside its bounds, so inside the
// scissor, and a block lies inside one tile: the blocks that overlap `area` (the bounds inside the
// tile's region) are the tile's, and their masks need no cut by the region.
template <Mode kMode>
[[gnu::always_inline]] inline void raster_speck(TileJob& job, const TriRecord& rec, int32_t id,
                                                const PixelRect& area) {
  BlockTarget<kMode> emit(job, rec, id, area);
  const int bx = rec.bounds.x0 & ~(kBlockSize - 1), by = rec.bounds.y0 & ~(kBlockSize - 1);
  for (uint64_t blocks = rec.blocks; blocks != 0;) {
    const int i = __builtin_ctzll(blocks) >> 4;
    const uint32_t bits = uint32_t(blocks >> (16 * i)) & 0xffffu;
    blocks &= ~(uint64_t(0xffffu) << (16 * i));
    const int x = bx + kBlockSize * (i & 1), y = by + kBlockSize * (i >> 1);
    if (x + kBlockSize > area.x0 && x < area.x1 && y + kBlockSize > area.y0 && y < area.y1) {
      emit(x, y, bits);
    }
  }
}

// The same out of line, for the deferred modes: inline, it cost the partial blocks of large
// triangles registers (overdraw gouraud: the depth resolve 870.3 M -> 885.1 M instructions).
template <Mode kMode>
[[gnu::noinline]] void raster_speck_out_of_line(TileJob& job, const TriRecord& rec, int32_t id,
                                                const PixelRect& area) {
  raster_speck<kMode>(job, rec, id, area);
}

template <Mode kMode>
[[gnu::always_inline]] inline void raster_record(TileJob& job, const TriRecord& rec, int32_t id) {
  const TriRecord& t = rec;
  PixelRect area = intersect(t.bounds, job.region);
  if (area.empty()) return;
  if (rec.blocks != 0) {
    if constexpr (kMode == Mode::kImmediate) {
      raster_speck<kMode>(job, rec, id, area);
    } else {
      raster_speck_out_of_line<kMode>(job, rec, id, area);
    }
    return;
  }
  EdgeGrid grid;
  grid.x0 = area.x0 & ~(kBlockSize - 1);
  grid.y0 = area.y0 & ~(kBlockSize - 1);
  for (int k = 0; k < 3; ++k) {
    grid.origin[k] = t.edge(k).at(sample_fx8(grid.x0), sample_fx8(grid.y0));
    grid.step_x[k] = t.edge(k).a * kSubpixelOne;
    grid.step_y[k] = t.edge(k).b * kSubpixelOne;
  }
  if (rec.small && area.x1 - grid.x0 <= kBlockSize && area.y1 - grid.y0 <= kBlockSize) {
    // Inside one block (the usual triangle of a dense mesh): that block's coverage, nothing else.
    EdgeOffsets<I> offsets;
    make_offsets<I, int32_t>(t, offsets);
    uint32_t bits =
        coverage_bits<I, int32_t>(grid.origin, offsets) & region_bits(job.region, grid.x0, grid.y0);
    if (bits != 0) BlockTarget<kMode>(job, rec, id, area)(grid.x0, grid.y0, bits);
    return;
  }
  if (rec.small) {
    raster_record_with<kMode, I, int32_t>(job, rec, id, area, grid);
  } else {
    raster_record_with<kMode, L, int64_t>(job, rec, id, area, grid);
  }
}

// Asks the cache for the record kRecordPrefetchAhead places on in the bin: a batch's records
// outgrow the L2 cache, and a tile reads its own among those of its neighbours, so each was a miss
// to L3 when the raster reached it (spheres_1m: a sixth of the tile kernel's time on the record's
// first load). Four lines: the edges before the header (TriRecord; for a speck, the end of the
// record before it, usually one the tile has just read), the header and the first planes (a
// record of three varyings is 120 bytes from its header, of phong's six 160). Eight records ahead
// measured the same as four on a Zen 5 (spheres_1m, one thread).
constexpr size_t kRecordPrefetchAhead = 4;
[[gnu::always_inline]] inline void prefetch_record(const std::byte* record) {
  for (int line = -1; line < 3; ++line) {
    prefetch_line(record + 64 * line);
  }
}

template <Mode kMode>
[[gnu::always_inline]] inline void raster_records(TileJob& job, const std::byte* arena,
                                                  const uint32_t* offsets, size_t count) {
  for (size_t i = 0; i < count; ++i) {
    if (i + kRecordPrefetchAhead < count)
      prefetch_record(arena + offsets[i + kRecordPrefetchAhead]);
    const TriRecord& rec = *reinterpret_cast<const TriRecord*>(arena + offsets[i]);
    int32_t id = 0;
    if constexpr (kMode != Mode::kImmediate) {
      id = job.next_id++;
      job.interps[id] = &rec.interp();
    }
    raster_record<kMode>(job, rec, id);
  }
}

// ---------------------------------------------------------------------------------------------
// Entry points.

void raster_immediate(TileJob& job, const std::byte* arena, const uint32_t* offsets, size_t count) {
  raster_records<Mode::kImmediate>(job, arena, offsets, count);
}
void raster_deferred(TileJob& job, const std::byte* arena, const uint32_t* offsets, size_t count) {
  if (kLanes == 8 && !avx2_masked_stores()) {
    if (job.less_equal) {
      raster_records<Mode::kLessEqualBlend>(job, arena, offsets, count);
    } else {
      raster_records<Mode::kLessBlend>(job, arena, offsets, count);
    }
  } else if (job.less_equal) {
    raster_records<Mode::kLessEqual>(job, arena, offsets, count);
  } else {
    raster_records<Mode::kLess>(job, arena, offsets, count);
  }
}
void resolve_block(const DepthPlaneRef& plane, int x, int y, uint32_t mask, int32_t id,
                   bool less_equal, float* depth, int32_t* ids) {
  Interpolants in;
  in.x_ref = plane.x_ref;
  in.y_ref = plane.y_ref;
  in.z = plane.z;
  DepthTerms d;
  depth_terms(in, id, x, x + kBlockSize, y, y + kBlockSize, d);
  const bool blend = kLanes == 8 && !avx2_masked_stores();
  if (less_equal) {
    blend ? resolve_lanes<true, true>(d, x, y, mask, depth, ids)
          : resolve_lanes<true, false>(d, x, y, mask, depth, ids);
  } else {
    blend ? resolve_lanes<false, true>(d, x, y, mask, depth, ids)
          : resolve_lanes<false, false>(d, x, y, mask, depth, ids);
  }
}
