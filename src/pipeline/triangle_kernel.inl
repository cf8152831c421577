// pipeline/triangle_kernel.inl: the body of triangle_kernels.cpp, included once per instruction
// set inside its own namespace with SOFTRAST_TRIANGLE_LANES (8 or 16) defined and the matching
// `#pragma GCC target` in force. Each step is a step of the scalar front end, lane-wise; the
// comments name the scalar code it mirrors.

constexpr int kL = SOFTRAST_TRIANGLE_LANES;
typedef int32_t I __attribute__((vector_size(4 * kL)));
typedef uint32_t U __attribute__((vector_size(4 * kL)));
typedef double D __attribute__((vector_size(8 * kL)));
typedef int64_t Q __attribute__((vector_size(8 * kL)));
typedef float F __attribute__((vector_size(4 * kL)));

// Bit l set where lane l of the mask (0 or -1) is set.
[[gnu::always_inline]] inline uint32_t lane_bits(I mask) {
#if SOFTRAST_TRIANGLE_LANES == 16
  return _mm512_movepi32_mask(__m512i(mask));
#else
  return uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(__m256i(mask))));
#endif
}

// The three index streams of kL consecutive triangles (3 kL indices from p).
[[gnu::always_inline]] inline void load_indices(const uint32_t* p, I& i0, I& i1, I& i2) {
#if SOFTRAST_TRIANGLE_LANES == 16
  const __m512i a = _mm512_loadu_si512(p), b = _mm512_loadu_si512(p + 16),
                c = _mm512_loadu_si512(p + 32);
  // First the elements from a and b (every third from k), then the rest from c.
  auto pick = [&](__m512i from_ab, __m512i with_c) {
    return I(_mm512_permutex2var_epi32(_mm512_permutex2var_epi32(a, from_ab, b), with_c, c));
  };
  i0 = pick(_mm512_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0),
            _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29));
  i1 = pick(_mm512_setr_epi32(1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0),
            _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30));
  i2 = pick(_mm512_setr_epi32(2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0),
            _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31));
#else
  const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)),
                b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 8)),
                c = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 16));
  // Each stream takes every third element of a, b and c in a rotating pattern: blend the three,
  // then put the elements in order.
  i0 = I(_mm256_permutevar8x32_epi32(_mm256_blend_epi32(_mm256_blend_epi32(a, b, 0x92), c, 0x24),
                                     _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)));
  i1 = I(_mm256_permutevar8x32_epi32(_mm256_blend_epi32(_mm256_blend_epi32(a, b, 0x24), c, 0x49),
                                     _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)));
  i2 = I(_mm256_permutevar8x32_epi32(_mm256_blend_epi32(_mm256_blend_epi32(a, b, 0x49), c, 0x92),
                                     _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7)));
#endif
}

// Four rows of 8 bits (bytes 0 to 3, column c at bit c) as two 4x4 masks (bit 4 row + column):
// columns 0 to 3 in the low 16 bits, 4 to 7 in the high.
[[gnu::always_inline]] inline U block_mask(U rows) {
  rows &= 0x0f0f0f0fu;
  rows = (rows | rows >> 4) & 0x00ff00ffu;
  return (rows | rows >> 8) & 0xffffu;
}
[[gnu::always_inline]] inline U block_pair(U rows) {
  return block_mask(rows) | block_mask(rows >> 4) << 16;
}

[[gnu::always_inline]] inline I min3(I a, I b, I c) {
  I m = a < b ? a : b;
  return m < c ? m : c;
}
[[gnu::always_inline]] inline I max3(I a, I b, I c) {
  I m = a > b ? a : b;
  return m > c ? m : c;
}
// (Helpers of double vectors are macros: at AVX2 a D is wider than a register, and GCC notes the
// ABI of a function that returns one.)
#define SOFTRAST_TO_DOUBLE(v) __builtin_convertvector((v), D)
// An integer-valued double below 2^51 in magnitude to int64, exactly: added to 1.5 * 2^52 its
// integer is the low bits of the sum's mantissa.
#define SOFTRAST_EXACT_INT64(v) (Q((v) + (D{} + 0x1.8p52)) - Q(D{} + 0x1.8p52))

// A vector to an aligned row of kL floats.
[[gnu::always_inline]] inline void store_row(float* row, F v) {
#if SOFTRAST_TRIANGLE_LANES == 16
  _mm512_store_ps(row, __m512(v));
#else
  _mm256_store_ps(row, __m256(v));
#endif
}

// Four consecutive floats of every lane, from base + index[l] * stride (the first `count` of
// them; the others 0, not read), as four vectors: out[f] lane l = base[index[l] * stride + f].
// One 128-bit load per lane, then a 4x4 transpose within each 128-bit part: part c of the vector
// m holds lane 4c + m. The first `count` also stored, to rows[f] (each vector from its register:
// copied through the stack, they had cost a third of the loads).
[[gnu::always_inline]] inline void load_quads(const float* base, const uint32_t* index,
                                              size_t stride, int count, F (&out)[4],
                                              float (*rows)[kL]) {
  auto at = [&](int l) { return base + size_t(index[l]) * stride; };
#if SOFTRAST_TRIANGLE_LANES == 16
  const __mmask8 mask = __mmask8((1u << count) - 1);
  auto quad = [&](int l) { return _mm_maskz_loadu_ps(mask, at(l)); };
  __m512 m[4];
  for (int k = 0; k < 4; ++k) {
    m[k] = _mm512_insertf32x4(
        _mm512_insertf32x4(_mm512_insertf32x4(_mm512_zextps128_ps512(quad(k)), quad(k + 4), 1),
                           quad(k + 8), 2),
        quad(k + 12), 3);
  }
  const __m512d t0 = _mm512_castps_pd(_mm512_unpacklo_ps(m[0], m[1]));
  const __m512d t1 = _mm512_castps_pd(_mm512_unpackhi_ps(m[0], m[1]));
  const __m512d t2 = _mm512_castps_pd(_mm512_unpacklo_ps(m[2], m[3]));
  const __m512d t3 = _mm512_castps_pd(_mm512_unpackhi_ps(m[2], m[3]));
  out[0] = F(_mm512_castpd_ps(_mm512_unpacklo_pd(t0, t2)));
  out[1] = F(_mm512_castpd_ps(_mm512_unpackhi_pd(t0, t2)));
  out[2] = F(_mm512_castpd_ps(_mm512_unpacklo_pd(t1, t3)));
  out[3] = F(_mm512_castpd_ps(_mm512_unpackhi_pd(t1, t3)));
#else
  const __m128i mask = _mm_cmpgt_epi32(_mm_set1_epi32(count), _mm_setr_epi32(0, 1, 2, 3));
  auto quad = [&](int l) { return _mm_maskload_ps(at(l), mask); };
  __m256 m[4];
  for (int k = 0; k < 4; ++k) m[k] = _mm256_set_m128(quad(k + 4), quad(k));
  const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(m[0], m[1]));
  const __m256d t1 = _mm256_castps_pd(_mm256_unpackhi_ps(m[0], m[1]));
  const __m256d t2 = _mm256_castps_pd(_mm256_unpacklo_ps(m[2], m[3]));
  const __m256d t3 = _mm256_castps_pd(_mm256_unpackhi_ps(m[2], m[3]));
  out[0] = F(_mm256_castpd_ps(_mm256_unpacklo_pd(t0, t2)));
  out[1] = F(_mm256_castpd_ps(_mm256_unpackhi_pd(t0, t2)));
  out[2] = F(_mm256_castpd_ps(_mm256_unpacklo_pd(t1, t3)));
  out[3] = F(_mm256_castpd_ps(_mm256_unpackhi_pd(t1, t3)));
#endif
  for (int f = 0; f < 4; ++f) {
    if (f < count) store_row(rows[f], out[f]);
  }
}

// setup_planes (raster/setup.cpp) for every lane: the same double operations in the same order,
// so the same bits where a lane is ready. Half the lanes at a time, in vectors of one register
// (GCC splits wider double vectors, and turns their compares and selects into scalar code).
// out.vertex, out.x, out.y, out.area: the clockwise vertices and the signed snapped area.
typedef double DH __attribute__((vector_size(4 * kL)));
typedef float FH __attribute__((vector_size(2 * kL)));
typedef int32_t IH __attribute__((vector_size(2 * kL)));
typedef int64_t QH __attribute__((vector_size(4 * kL)));
constexpr int kH = kL / 2;

// The first or second half (h) of a row of kL values as a vector of kH.
template <class V, class T>
[[gnu::always_inline]] inline V half(const T* row, int h) {
  V v;
  std::memcpy(&v, row + h * kH, sizeof v);
  return v;
}
template <class T, class V>
[[gnu::always_inline]] inline void store_half(T* row, int h, const V& v) {
  std::memcpy(row + h * kH, &v, sizeof v);
}
// Half a group's floats or int32 in double, each by one conversion instruction:
// __builtin_convertvector made each two conversions of half as many lanes and an insert (GCC 12,
// at AVX2 and AVX-512), 42 of them per group for three varyings. The same values.
#if SOFTRAST_TRIANGLE_LANES == 16
[[gnu::always_inline]] inline DH half_double(FH v) {
  return DH(_mm512_cvtps_pd(__m256(v)));
}
[[gnu::always_inline]] inline DH half_double(IH v) {
  // (The masked form: the unmasked one of GCC 12's header reads an undefined vector, which
  // -Wuninitialized reports where it is inlined; GCC bug 105593.)
  return DH(_mm512_maskz_cvtepi32_pd(__mmask8(0xff), __m256i(v)));
}
#else
[[gnu::always_inline]] inline DH half_double(FH v) {
  return DH(_mm256_cvtps_pd(__m128(v)));
}
[[gnu::always_inline]] inline DH half_double(IH v) {
  return DH(_mm256_cvtepi32_pd(__m128i(v)));
}
#endif

// The lanes (as masks) where the area, given by halves, is negative and where it is not zero
// (`< 0.0` and `!= 0.0` of C++: the unordered not-equal, although an area is never NaN).
[[gnu::always_inline]] inline void area_signs(const DH (&area)[2], I& negative, I& nonzero) {
#if SOFTRAST_TRIANGLE_LANES == 16
  const __m512d zero = _mm512_setzero_pd();
  const __m512d low = __m512d(area[0]), high = __m512d(area[1]);
  const unsigned below = _mm512_cmp_pd_mask(low, zero, _CMP_LT_OQ) |
                         unsigned(_mm512_cmp_pd_mask(high, zero, _CMP_LT_OQ)) << 8;
  const unsigned other = _mm512_cmp_pd_mask(low, zero, _CMP_NEQ_UQ) |
                         unsigned(_mm512_cmp_pd_mask(high, zero, _CMP_NEQ_UQ)) << 8;
  negative = I(_mm512_movm_epi32(__mmask16(below)));
  nonzero = I(_mm512_movm_epi32(__mmask16(other)));
#else
  // The 64-bit masks' low halves in lane order: the first two of each 128-bit part of both
  // halves, then the parts put in order.
  const __m256d zero = _mm256_setzero_pd();
  const __m256d low = __m256d(area[0]), high = __m256d(area[1]);
  const __m256 below =
      _mm256_shuffle_ps(_mm256_castpd_ps(_mm256_cmp_pd(low, zero, _CMP_LT_OQ)),
                        _mm256_castpd_ps(_mm256_cmp_pd(high, zero, _CMP_LT_OQ)), 0x88);
  const __m256 other =
      _mm256_shuffle_ps(_mm256_castpd_ps(_mm256_cmp_pd(low, zero, _CMP_NEQ_UQ)),
                        _mm256_castpd_ps(_mm256_cmp_pd(high, zero, _CMP_NEQ_UQ)), 0x88);
  negative = I(_mm256_permute4x64_epi64(_mm256_castps_si256(below), 0xd8));
  nonzero = I(_mm256_permute4x64_epi64(_mm256_castps_si256(other), 0xd8));
#endif
}

// (Macros, not lambdas: GCC gives a lambda that returns a vector the default target's ABI.)
#define SOFTRAST_HALF_FLOAT(v) __builtin_convertvector((v), FH)
// Vertex k's float f (z, 1/w, x and y residual) for half h of the lanes, in double.
#define SOFTRAST_FIELD(k, f) half_double(half<FH>(vertex_floats[k][f], h))

[[gnu::always_inline]] inline void setup_plane_lanes(const TriangleBatch& b, TriangleLanes& out) {
  // z, 1/w and the residuals of each vertex (PackedVertex's floats 2 to 5), by lane.
  alignas(64) float vertex_floats[3][4][kL];
  // scaled_inv_w: lanes whose largest 1/w (in std::max's order) is outside [2^-20, 2^20] go to
  // the scalar setup, which rescales it.
  F largest;
  for (int k = 0; k < 3; ++k) {
    static_assert(sizeof(PackedVertex) == 6 * sizeof(float) && offsetof(PackedVertex, z) == 8);
    F q[4];
    load_quads(&b.window->z, out.vertex[k], 6, 4, q, vertex_floats[k]);
    largest = k == 0 ? q[1] : (largest < q[1] ? q[1] : largest);
  }
  out.scalar_planes = out.ready & lane_bits(~((largest <= 0x1p20f) & (largest >= 0x1p-20f)));
  // The varyings, by lane: var_floats[k][i] for vertex k's varying i.
  alignas(64) float var_floats[3][kMaxVaryings][kL];
  for (int first = 0; first < b.num_varyings; first += 4) {
    const int count = std::min(4, b.num_varyings - first);
    for (int k = 0; k < 3; ++k) {
      F q[4];
      load_quads(b.varyings + first, out.vertex[k], b.stride, count, q, var_floats[k] + first);
    }
  }
  for (int h = 0; h < 2; ++h) {
    // A half with no lane ready (back faces, specks, the end of a mesh's front half): no planes
    // are read from it.
    if (((out.ready >> (h * kH)) & ((1u << kH) - 1u)) == 0) continue;
    // The snapped basis (to_pixels: times 2^-8, exact) and the exact one (the residuals).
    const DH px = DH{} + 0x1p-8;
    const IH x0 = half<IH>(out.x[0], h), y0 = half<IH>(out.y[0], h);
    const DH gdx1 = half_double(half<IH>(out.x[1], h) - x0) * px;
    const DH gdx2 = half_double(half<IH>(out.x[2], h) - x0) * px;
    const DH gdy1 = half_double(half<IH>(out.y[1], h) - y0) * px;
    const DH gdy2 = half_double(half<IH>(out.y[2], h) - y0) * px;
    const DH rx0 = px * SOFTRAST_FIELD(0, 2), ry0 = px * SOFTRAST_FIELD(0, 3);
    const DH edx1 = gdx1 + (px * SOFTRAST_FIELD(1, 2) - rx0),
             edx2 = gdx2 + (px * SOFTRAST_FIELD(2, 2) - rx0);
    const DH edy1 = gdy1 + (px * SOFTRAST_FIELD(1, 3) - ry0),
             edy2 = gdy2 + (px * SOFTRAST_FIELD(2, 3) - ry0);
    const DH exact_area2 = edx1 * edy2 - edx2 * edy1;
    // double(|area|): the area is an integer below 2^49, exact through 1.5 * 2^52.
    const QH area = half<QH>(out.area, h);
    const DH abs_area = DH((area < 0 ? -area : area) + QH(DH{} + 0x1.8p52)) - (DH{} + 0x1.8p52);
    const QH moved = (rx0 != 0.0) | (ry0 != 0.0) | (edx1 != gdx1) | (edx2 != gdx2) |
                     (edy1 != gdy1) | (edy2 != gdy2);
    const QH exact = moved & (exact_area2 >= (abs_area * 0x1p-16) * (1.0 / 16.0));
    const DH inv_area2 = (exact ? DH{} + 1.0 : DH{} + 65536.0) / (exact ? exact_area2 : abs_area);
    const DH dx1 = exact ? edx1 : gdx1, dx2 = exact ? edx2 : gdx2;
    const DH dy1 = exact ? edy1 : gdy1, dy2 = exact ? edy2 : gdy2;
    const DH ox = exact ? rx0 : DH{}, oy = exact ? ry0 : DH{};
    const QH shifted = (ox != 0.0) | (oy != 0.0);
    // make_plane.
    auto plane = [&](const DH& a0, const DH& a1, const DH& a2, DH& p0, DH& pdx, DH& pdy) {
      const DH da1 = a1 - a0, da2 = a2 - a0;
      pdx = (da1 * dy2 - da2 * dy1) * inv_area2;
      pdy = (da2 * dx1 - da1 * dx2) * inv_area2;
      p0 = shifted ? a0 - pdx * ox - pdy * oy : a0;
    };
    store_half(out.x_ref, h, SOFTRAST_HALF_FLOAT(half_double(x0) * px));
    store_half(out.y_ref, h, SOFTRAST_HALF_FLOAT(half_double(y0) * px));
    DH p[3];
    plane(SOFTRAST_FIELD(0, 0), SOFTRAST_FIELD(1, 0), SOFTRAST_FIELD(2, 0), p[0], p[1], p[2]);
    for (int c = 0; c < 3; ++c) store_half(out.z[c], h, p[c]);
    const DH w[3] = {SOFTRAST_FIELD(0, 1), SOFTRAST_FIELD(1, 1), SOFTRAST_FIELD(2, 1)};
    plane(w[0], w[1], w[2], p[0], p[1], p[2]);
    for (int c = 0; c < 3; ++c) store_half(out.inv_w[c], h, SOFTRAST_HALF_FLOAT(p[c]));
    for (int i = 0; i < b.num_varyings; ++i) {
#define SOFTRAST_VAR(k) half_double(half<FH>(var_floats[k][i], h)) * w[k]
      plane(SOFTRAST_VAR(0), SOFTRAST_VAR(1), SOFTRAST_VAR(2), p[0], p[1], p[2]);
#undef SOFTRAST_VAR
      for (int c = 0; c < 3; ++c) store_half(out.var[i][c], h, SOFTRAST_HALF_FLOAT(p[c]));
    }
  }
}
#undef SOFTRAST_HALF_FLOAT
#undef SOFTRAST_FIELD

// Corner k's (x, y) of every lane, read at the vertex the index buffer names (p: the group's
// indices, three per lane, every one valid): one 64-bit load per lane, the pairs sorted into x
// and y four lanes at a time (as simd::isa::pairs_loads sorts them). Straight from the indices,
// without the index vectors' trip through the stack that the gather takes.
[[gnu::always_inline]] inline void corner_xy(const int32_t* base, const uint32_t* p, int k, I& x,
                                             I& y) {
  auto pair = [&](int l) {
    return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + size_t(p[3 * l + k]) * 6));
  };
  __m128i low4[kL / 4], high4[kL / 4];
  for (int g = 0; g < kL / 4; ++g) {
    const __m128i p01 = _mm_unpacklo_epi32(pair(4 * g), pair(4 * g + 1));      // x0 x1 y0 y1
    const __m128i p23 = _mm_unpacklo_epi32(pair(4 * g + 2), pair(4 * g + 3));  // x2 x3 y2 y3
    low4[g] = _mm_unpacklo_epi64(p01, p23);
    high4[g] = _mm_unpackhi_epi64(p01, p23);
  }
#if SOFTRAST_TRIANGLE_LANES == 16
  using simd::isa::join;
  x = I(join(join(low4[0], low4[1]), join(low4[2], low4[3])));
  y = I(join(join(high4[0], high4[1]), join(high4[2], high4[3])));
#else
  x = I(simd::isa::join(low4[0], low4[1]));
  y = I(simd::isa::join(high4[0], high4[1]));
#endif
}

// triangle_bounds inside the scissor from the clockwise corners (ceil_div(min - 128, 256) is
// (min + 127) >> 8, floor_div(max - 128, 256) + 1 is ((max - 128) >> 8) + 1), and the corners'
// extents.
struct LaneBounds {
  I x0, y0, x1, y1;
  I width_fx8, height_fx8;  // max - min of the corners' x and y, in 1/256 pixel
};
[[gnu::always_inline]] inline LaneBounds lane_bounds(const I (&vx)[3], const I (&vy)[3],
                                                     const PixelRect& scissor) {
  const I xmin = min3(vx[0], vx[1], vx[2]), xmax = max3(vx[0], vx[1], vx[2]);
  const I ymin = min3(vy[0], vy[1], vy[2]), ymax = max3(vy[0], vy[1], vy[2]);
  LaneBounds r;
  r.x0 = (xmin + (kSubpixelHalf - 1)) >> kSubpixelBits;
  r.y0 = (ymin + (kSubpixelHalf - 1)) >> kSubpixelBits;
  r.x1 = ((xmax - kSubpixelHalf) >> kSubpixelBits) + 1;
  r.y1 = ((ymax - kSubpixelHalf) >> kSubpixelBits) + 1;
  const I sx0 = I{} + scissor.x0, sy0 = I{} + scissor.y0;
  const I sx1 = I{} + scissor.x1, sy1 = I{} + scissor.y1;
  r.x0 = r.x0 > sx0 ? r.x0 : sx0;
  r.y0 = r.y0 > sy0 ? r.y0 : sy0;
  r.x1 = r.x1 < sx1 ? r.x1 : sx1;
  r.y1 = r.y1 < sy1 ? r.y1 : sy1;
  r.width_fx8 = xmax - xmin;
  r.height_fx8 = ymax - ymin;
  return r;
}

// Edge k's a, b and bias as make_edge(vertex k, vertex k + 1) makes them: a = -dy, b = dx, and
// -1 unless the edge is top or left (is_top_left), else 0.
[[gnu::always_inline]] inline void lane_edge(const I (&vx)[3], const I (&vy)[3], int k, I& a, I& b,
                                             I& bias) {
  const int j = (k + 1) % 3;
  const I dx = vx[j] - vx[k], dy = vy[j] - vy[k];
  a = -dy;
  b = dx;
  bias = ~((dy < 0) | ((dy == 0) & (dx > 0)));
}

void select_triangles(const TriangleBatch& b, size_t first, int count, TriangleLanes& out) {
  const uint32_t* p = b.indices + 3 * first;
  alignas(64) uint32_t tail[3 * kL];
  if (count < kL) {  // the last group of a chunk: its indices, then zeros (lanes not valid)
    std::memset(tail, 0, sizeof tail);
    std::memcpy(tail, p, sizeof(uint32_t) * 3 * size_t(count));
    p = tail;
  }
  I i0, i1, i2;
  load_indices(p, i0, i1, i2);
  I lane;
  for (int l = 0; l < kL; ++l) lane[l] = l;
  // GeometryStage::valid for each index; the others read vertex 0 (never used).
  const U n = U{} + uint32_t(b.vertex_count);
  const I valid = I(U(i0) < n) & I(U(i1) < n) & I(U(i2) < n) & (lane < count);
  i0 &= valid, i1 &= valid, i2 &= valid;
  // (x, y) of each corner: one 64-bit load per lane (PackedVertex is six 32-bit fields).
  const auto* base = reinterpret_cast<const int32_t*>(b.window);
  static_assert(sizeof(PackedVertex) == 6 * sizeof(int32_t));
  I x0, y0, x1, y1, x2, y2;
  if (lane_bits(valid) == (1u << kL) - 1 && simd::loads_for_gathers<kL>()) {
    corner_xy(base, p, 0, x0, y0);
    corner_xy(base, p, 1, x1, y1);
    corner_xy(base, p, 2, x2, y2);
  } else {
    simd::isa::gather_pair(base, i0 * 6, x0, y0);
    simd::isa::gather_pair(base, i1 * 6, x1, y1);
    simd::isa::gather_pair(base, i2 * 6, x2, y2);
  }
  // WindowVertices::triangle: every code 0 is the trivial accept; the rest is the scalar path's.
  const I accepted =
      valid & (x0 != kOutsideVolume) & (x1 != kOutsideVolume) & (x2 != kOutsideVolume);
  out.scalar = lane_bits(valid & ~accepted);
  x0 &= accepted, y0 &= accepted, x1 &= accepted, y1 &= accepted, x2 &= accepted, y2 &= accepted;

  // signed_area_fx16, then is_culled (zero area is never kept): half the lanes at a time, each
  // half one register of doubles, and the halves' signs joined in registers (through memory, the
  // two halves' stores and the whole vector's load missed store forwarding: at AVX2 a sixth of
  // the kernel's time stalled there).
  const I ex1 = x1 - x0, ey1 = y1 - y0, ex2 = x2 - x0, ey2 = y2 - y0;
  DH area[2];
  for (int h = 0; h < 2; ++h) {
#define SOFTRAST_PART(v) half_double(half<IH>(reinterpret_cast<const int32_t*>(&(v)), h))
    area[h] = SOFTRAST_PART(ex1) * SOFTRAST_PART(ey2) - SOFTRAST_PART(ex2) * SOFTRAST_PART(ey1);
#undef SOFTRAST_PART
  }
  I negative, nonzero;
  area_signs(area, negative, nonzero);
  const I front = nonzero & (b.front_face == FrontFace::kCounterClockwise ? negative : ~negative);
  I culled = I{};
  if (b.cull == CullMode::kBack) culled = ~front;
  if (b.cull == CullMode::kFront) culled = front;
  const I kept = accepted & nonzero & ~culled;
  out.ready = 0;
  if (lane_bits(kept) == 0) return;  // a closed mesh's back half: groups culled whole

  // setup_triangle_coverage: clockwise order (a counter-clockwise triangle swaps vertices 1 and
  // 2), then the bounds inside the scissor (triangle_bounds: ceil_div(min - 128, 256) is
  // (min + 127) >> 8, floor_div(max - 128, 256) + 1 is ((max - 128) >> 8) + 1).
  const I ccw = negative;
  const I vx[3] = {x0, ccw ? x2 : x1, ccw ? x1 : x2};
  const I vy[3] = {y0, ccw ? y2 : y1, ccw ? y1 : y2};
  const I vi[3] = {i0, ccw ? i2 : i1, ccw ? i1 : i2};
  const LaneBounds bounds = lane_bounds(vx, vy, b.scissor);
  const I bx0 = bounds.x0, by0 = bounds.y0, bx1 = bounds.x1, by1 = bounds.y1;
  const I inside = (bx0 < bx1) & (by0 < by1);
  out.ready = lane_bits(kept & inside);
  // The edges' a, b and bias, for the speck test below (finish_triangles makes the edges' c).
  I edge_a[3], edge_b[3], bias[3];
  for (int k = 0; k < 3; ++k) lane_edge(vx, vy, k, edge_a[k], edge_b[k], bias[k]);

  // A triangle whose bounds are at most 5x5 pixels and whose edges pass no sample inside them
  // (a sliver or a speck between pixel centres: a sixth of spheres_1m's records) covers no pixel:
  // it is dropped here, before its record, planes and bins are made. The others keep the coverage
  // found here (TriRecord::blocks), which the tile kernels take as it is. Bounds of 5 pixels fit
  // the 2x2 blocks from their first pixel's block wherever they start in it (3 + 5 <= 8); on
  // spheres_1m, bounds of 5 are three quarters of the triangles that 4 left to the edge tests.
  // Its samples are tested as the tile kernels test them: E = a x + b y + c at the sample,
  // covered when all three are >= 0. Edge k's c is bias - (a xk + b yk), with vertex k's xk and
  // yk, so E is a (x - xk) + b (y - yk) + bias, exactly, in int32: the vertices span at most 6
  // pixels (1536 in 1/256), so |a|, |b| <= 1536, and the 25 samples lie within 2304 of every
  // vertex: |E| <= 2 * 1536 * 2304 < 2^23.
  const I width = bx1 - bx0, height = by1 - by0;
  const I speck = kept & inside & (width <= 5) & (height <= 5) &
                  (bounds.width_fx8 <= 6 * kSubpixelOne) & (bounds.height_fx8 <= 6 * kSubpixelOne);
  if (lane_bits(speck) != 0) {
    // Every value below is 0 in the other lanes (unused; no overflow there).
    const I sx = (bx0 * kSubpixelOne + kSubpixelHalf) & speck;
    const I sy = (by0 * kSubpixelOne + kSubpixelHalf) & speck;
    I e[3], step_x[3], step_y[3];
    for (int k = 0; k < 3; ++k) {
      const I a = edge_a[k] & speck, b = edge_b[k] & speck;
      e[k] = a * (sx - (vx[k] & speck)) + b * (sy - (vy[k] & speck)) + (bias[k] & speck);
      step_x[k] = a * kSubpixelOne;
      step_y[k] = b * kSubpixelOne;
    }
    // The samples outside as bits 8 row + column (the bounds' 5x5 pixels in the first five bits
    // of five bytes, rows of an 8x8 area of pixels): rows 0 to 3 in `outside`, row 4 in
    // `outside4`. Each row's bits are the sign bits of the or of the three values, shifted in
    // from its last sample to its first. Samples past the bounds are tested too, and cut after.
    U outside = U{}, outside4 = U{};
    for (int k = 0; k < 3; ++k) e[k] += 4 * step_x[k] + 4 * step_y[k];  // the last sample
    for (int row = 4; row >= 0; --row) {
      I c[3] = {e[0], e[1], e[2]};
      U bits = U{};
      for (int column = 4; column >= 0; --column) {
        bits = (bits << 1) | (U(c[0] | c[1] | c[2]) >> 31);
        for (int k = 0; k < 3; ++k) c[k] -= step_x[k];
      }
      if (row == 4) {
        outside4 = bits;
      } else {
        outside = (outside << 8) | bits;
      }
      for (int k = 0; k < 3; ++k) e[k] -= step_y[k];
    }
    // The bounds: `width` bits of each of `height` bytes (both 1 to 5 in specks; 5 and 4
    // elsewhere, to keep the shift counts in range).
    const U columns = (U{} + 0xffu) >> U(8 - (speck ? width : 5));
    const U rows = (U{} + 0xffffffffu) >> U(32 - 8 * (speck & (height < 4) ? height : 4));
    I covered = I(~outside & (columns | columns << 8 | columns << 16 | columns << 24) & rows);
    covered &= speck;
    const I covered4 = I(~outside4 & columns) & (speck & (height == 5));
    out.ready &= ~lane_bits(speck & ~((covered | covered4) != 0));
    // The same bits as blocks (TriRecord::blocks): the 8x8 area moved to the first of the 2x2
    // blocks that hold the bounds (by 8 rows + columns of the bounds' offset in its block), as
    // two halves of 32 bits, rows 0 to 3 and rows 4 to 7; each half's left and right 4x4 block.
    // Row 4 of the bounds lands in the lower half, at row (by0 & 3) of it.
    const U shift = U((by0 & 3) * 8 + (bx0 & 3));  // at most 27
    const U upper = U(covered) << shift;
    // What moved past bit 31 (0 if nothing), and row 4.
    const U lower = ((U(covered) >> 1) >> (31 - shift)) | (U(covered4) << shift);
    const U top = block_pair(upper), bottom = block_pair(lower);
    std::memcpy(out.blocks[0], &top, sizeof top);
    std::memcpy(out.blocks[1], &bottom, sizeof bottom);
  } else {
    std::memset(out.blocks, 0, sizeof out.blocks);
  }

  for (int h = 0; h < 2; ++h) {  // SOFTRAST_EXACT_INT64 half by half
    store_half(out.area, h, QH(area[h] + (DH{} + 0x1.8p52)) - QH(DH{} + 0x1.8p52));
  }
  for (int k = 0; k < 3; ++k) {
    std::memcpy(out.vertex[k], &vi[k], sizeof vi[k]);
    std::memcpy(out.x[k], &vx[k], sizeof vx[k]);
    std::memcpy(out.y[k], &vy[k], sizeof vy[k]);
  }
}

// The rest of the ready lanes' coverage, from their clockwise corners (out.x, out.y): the bounds
// and the 32-bit flag as select_triangles found them, and the edge functions (c = dy xi - dx yi,
// plus the bias).
[[gnu::always_inline]] inline void finish_coverage(const TriangleBatch& b, TriangleLanes& out) {
  I vx[3], vy[3];
  for (int k = 0; k < 3; ++k) {
    std::memcpy(&vx[k], out.x[k], sizeof vx[k]);
    std::memcpy(&vy[k], out.y[k], sizeof vy[k]);
  }
  const LaneBounds bounds = lane_bounds(vx, vy, b.scissor);
  std::memcpy(out.bounds[0], &bounds.x0, sizeof bounds.x0);
  std::memcpy(out.bounds[1], &bounds.y0, sizeof bounds.y0);
  std::memcpy(out.bounds[2], &bounds.x1, sizeof bounds.x1);
  std::memcpy(out.bounds[3], &bounds.y1, sizeof bounds.y1);
  // BinnedDraw::add_triangle: the 32-bit coverage path's extents.
  out.small = lane_bits((bounds.width_fx8 <= int32_t(kSmallTriangleFx8)) &
                        (bounds.height_fx8 <= int32_t(kSmallTriangleFx8)));
  for (int k = 0; k < 3; ++k) {
    I a, bb, bias;
    lane_edge(vx, vy, k, a, bb, bias);
    const D c = SOFTRAST_TO_DOUBLE(-a) * SOFTRAST_TO_DOUBLE(vx[k]) -
                SOFTRAST_TO_DOUBLE(bb) * SOFTRAST_TO_DOUBLE(vy[k]);
    const Q edge_c = SOFTRAST_EXACT_INT64(c) + __builtin_convertvector(bias, Q);
    std::memcpy(out.edge_a[k], &a, sizeof a);
    std::memcpy(out.edge_b[k], &bb, sizeof bb);
    std::memcpy(out.edge_c[k], &edge_c, sizeof edge_c);
  }
}

void finish_triangles(const TriangleBatch& b, TriangleLanes& out) {
  if (out.ready == 0) return;
  finish_coverage(b, out);
  setup_plane_lanes(b, out);
}

void setup_triangles(const TriangleBatch& b, size_t first, int count, TriangleLanes& out) {
  select_triangles(b, first, count, out);
  finish_triangles(b, out);
}

#if SOFTRAST_TRIANGLE_LANES == 16
// What select_triangles found for `from`'s lanes in `mask` (vertex, x, y, area, blocks), in lane
// order, to `to`'s lanes at, at + 1, ... (at + their number <= kL). AVX-512 only: AVX2 has no
// compress, and gathering with a lane-by-lane copy made spheres_1m 4 % slower there.
void append_lanes(const TriangleLanes& from, uint32_t mask, TriangleLanes& to, int at) {
  const int n = __builtin_popcount(mask);
  if (n == 0) return;
  // Lane at + i of the result takes the i-th chosen lane: the chosen lanes' numbers in order (one
  // compress), moved up by `at` lanes (one permute); then each row put in that order by a
  // permute and stored whole-row aligned, masked to lanes at to at + n - 1. (A compress is two
  // operations on the one port that shuffles, a permute one; stored from lane `at` instead, each
  // row was a store split across two cache lines, and the stores backed up: a third of the
  // append's time.)
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const __m512i order = _mm512_permutexvar_epi32(
      _mm512_and_si512(_mm512_sub_epi32(lane, _mm512_set1_epi32(at)), _mm512_set1_epi32(15)),
      _mm512_maskz_compress_epi32(__mmask16(mask), lane));
  const __mmask16 stored = __mmask16(((1u << n) - 1u) << at);
  auto row = [&](const auto* src, auto* dst) {
    _mm512_mask_store_epi32(dst, stored, _mm512_permutexvar_epi32(order, _mm512_load_si512(src)));
  };
  // 64-bit rows (two registers of 8 lanes): each half of the result from both of the source's.
  const __m512i low8 = _mm512_cvtepu32_epi64(_mm512_castsi512_si256(order));
  const __m512i high8 = _mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(order, 1));
  const __mmask8 stored_low = __mmask8(stored), stored_high = __mmask8(stored >> 8);
  auto row64 = [&](const int64_t* src, int64_t* dst) {
    const __m512i a = _mm512_load_si512(src), c = _mm512_load_si512(src + 8);
    if (stored_low != 0) {
      _mm512_mask_store_epi64(dst, stored_low, _mm512_permutex2var_epi64(a, low8, c));
    }
    if (stored_high != 0) {
      _mm512_mask_store_epi64(dst + 8, stored_high, _mm512_permutex2var_epi64(a, high8, c));
    }
  };
  for (int k = 0; k < 3; ++k) {
    row(from.vertex[k], to.vertex[k]);
    row(from.x[k], to.x[k]);
    row(from.y[k], to.y[k]);
  }
  for (int k = 0; k < 2; ++k) row(from.blocks[k], to.blocks[k]);
  row64(from.area, to.area);
  to.ready |= stored;
}
#endif

#undef SOFTRAST_TO_DOUBLE
#undef SOFTRAST_EXACT_INT64
