// pipeline/triangle_kernel.inl: the body of triangle_kernels.cpp, included once per instruction
// set inside its own namespace with SOFTRAST_TRIANGLE_LANES (8 or 16) defined and the matching
// `#pragma GCC target` in force. Each step is a step of the scalar front end, lane-wise; the
// comments name the scalar code it mirrors.

constexpr int kL = SOFTRAST_TRIANGLE_LANES;
typedef int32_t I __attribute__((vector_size(4 * kL)));
typedef uint32_t U __attribute__((vector_size(4 * kL)));
typedef double D __attribute__((vector_size(8 * kL)));
typedef int64_t Q __attribute__((vector_size(8 * kL)));

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
// A 64-bit lane mask (0 or -1) as a 32-bit one.
#define SOFTRAST_NARROW(mask) __builtin_convertvector((mask), I)

void setup_triangles(const TriangleBatch& b, size_t first, int count, TriangleLanes& out) {
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
  simd::isa::gather_pair(base, i0 * 6, x0, y0);
  simd::isa::gather_pair(base, i1 * 6, x1, y1);
  simd::isa::gather_pair(base, i2 * 6, x2, y2);
  // WindowVertices::triangle: every code 0 is the trivial accept; the rest is the scalar path's.
  const I accepted =
      valid & (x0 != kOutsideVolume) & (x1 != kOutsideVolume) & (x2 != kOutsideVolume);
  out.scalar = lane_bits(valid & ~accepted);
  x0 &= accepted, y0 &= accepted, x1 &= accepted, y1 &= accepted, x2 &= accepted, y2 &= accepted;

  // signed_area_fx16, then is_culled (zero area is never kept).
  const D area = SOFTRAST_TO_DOUBLE(x1 - x0) * SOFTRAST_TO_DOUBLE(y2 - y0) -
                 SOFTRAST_TO_DOUBLE(x2 - x0) * SOFTRAST_TO_DOUBLE(y1 - y0);
  const I negative = SOFTRAST_NARROW(area < 0.0), nonzero = SOFTRAST_NARROW(area != 0.0);
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
  const I xmin = min3(x0, x1, x2), xmax = max3(x0, x1, x2);
  const I ymin = min3(y0, y1, y2), ymax = max3(y0, y1, y2);
  I bx0 = (xmin + (kSubpixelHalf - 1)) >> kSubpixelBits;
  I by0 = (ymin + (kSubpixelHalf - 1)) >> kSubpixelBits;
  I bx1 = ((xmax - kSubpixelHalf) >> kSubpixelBits) + 1;
  I by1 = ((ymax - kSubpixelHalf) >> kSubpixelBits) + 1;
  const I sx0 = I{} + b.scissor.x0, sy0 = I{} + b.scissor.y0;
  const I sx1 = I{} + b.scissor.x1, sy1 = I{} + b.scissor.y1;
  bx0 = bx0 > sx0 ? bx0 : sx0;
  by0 = by0 > sy0 ? by0 : sy0;
  bx1 = bx1 < sx1 ? bx1 : sx1;
  by1 = by1 < sy1 ? by1 : sy1;
  const I inside = (bx0 < bx1) & (by0 < by1);
  out.ready = lane_bits(kept & inside);
  // BinnedDraw::add_triangle: the 32-bit coverage path's extents.
  out.small = lane_bits((xmax - xmin <= int32_t(kSmallTriangleFx8)) &
                        (ymax - ymin <= int32_t(kSmallTriangleFx8)));

  // Edge functions as make_edge(vertex k, vertex k + 1) makes them: a = -dy, b = dx,
  // c = dy xi - dx yi, one less unless the edge is top or left (is_top_left).
  I edge_a[3], edge_b[3];
  Q edge_c[3];
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3;
    const I dx = vx[j] - vx[k], dy = vy[j] - vy[k];
    edge_a[k] = -dy;
    edge_b[k] = dx;
    const I top_left = (dy < 0) | ((dy == 0) & (dx > 0));
    edge_c[k] = SOFTRAST_EXACT_INT64(SOFTRAST_TO_DOUBLE(dy) * SOFTRAST_TO_DOUBLE(vx[k]) -
                                     SOFTRAST_TO_DOUBLE(dx) * SOFTRAST_TO_DOUBLE(vy[k])) +
                __builtin_convertvector(~top_left, Q);  // -1 where not top-left
  }

  // A triangle whose bounds are at most 4x4 pixels and whose edges pass no sample inside them
  // (a sliver or a speck between pixel centres: a sixth of spheres_1m's records) covers no pixel:
  // it is dropped here, before its record, planes and bins are made. Its samples are tested as
  // the tile kernels test them: E = a x + b y + c at the sample, covered when all three are >= 0.
  // E at the bounds' first sample is exact in double (products of 16.8 coordinates,
  // fixed_point.hpp). The vertices span at most 6 pixels (1536 in 1/256), so |a|, |b| <= 1536,
  // and the 16 samples lie within 2304 of every vertex: |E| <= 2 * 1536 * 2304 < 2^23, int32.
  const I width = bx1 - bx0, height = by1 - by0;
  const I speck = kept & inside & (width <= 4) & (height <= 4) & (xmax - xmin <= 6 * kSubpixelOne) &
                  (ymax - ymin <= 6 * kSubpixelOne);
  if (lane_bits(speck) != 0) {
    const D sx = SOFTRAST_TO_DOUBLE(bx0) * double(kSubpixelOne) + double(kSubpixelHalf);
    const D sy = SOFTRAST_TO_DOUBLE(by0) * double(kSubpixelOne) + double(kSubpixelHalf);
    I e[3], step_x[3], step_y[3];
    for (int k = 0; k < 3; ++k) {
      const D at = SOFTRAST_TO_DOUBLE(edge_a[k]) * sx + SOFTRAST_TO_DOUBLE(edge_b[k]) * sy +
                   __builtin_convertvector(edge_c[k], D);
      e[k] = speck ? __builtin_convertvector(at, I) : I{};  // other lanes: unused, kept finite
      step_x[k] = (speck & edge_a[k]) * kSubpixelOne;
      step_y[k] = (speck & edge_b[k]) * kSubpixelOne;
    }
    I covered = I{};
    for (int row = 0; row < 4; ++row) {
      I r[3] = {e[0] + step_y[0] * row, e[1] + step_y[1] * row, e[2] + step_y[2] * row};
      const I row_ok = height > row;
      for (int column = 0; column < 4; ++column) {
        const I all =
            (r[0] + step_x[0] * column) | (r[1] + step_x[1] * column) | (r[2] + step_x[2] * column);
        covered |= (all >= 0) & row_ok & (width > column);
      }
    }
    out.ready &= ~lane_bits(speck & ~covered);
  }

  std::memcpy(out.bounds[0], &bx0, sizeof bx0);
  std::memcpy(out.bounds[1], &by0, sizeof by0);
  std::memcpy(out.bounds[2], &bx1, sizeof bx1);
  std::memcpy(out.bounds[3], &by1, sizeof by1);
  const Q area_q = SOFTRAST_EXACT_INT64(area);
  std::memcpy(out.area, &area_q, sizeof area_q);
  for (int k = 0; k < 3; ++k) {
    std::memcpy(out.vertex[k], &vi[k], sizeof vi[k]);
    std::memcpy(out.x[k], &vx[k], sizeof vx[k]);
    std::memcpy(out.y[k], &vy[k], sizeof vy[k]);
    std::memcpy(out.edge_a[k], &edge_a[k], sizeof edge_a[k]);
    std::memcpy(out.edge_b[k], &edge_b[k], sizeof edge_b[k]);
    std::memcpy(out.edge_c[k], &edge_c[k], sizeof edge_c[k]);
  }
}

#undef SOFTRAST_TO_DOUBLE
#undef SOFTRAST_EXACT_INT64
#undef SOFTRAST_NARROW
