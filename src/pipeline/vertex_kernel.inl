// pipeline/vertex_kernel.inl: the body of vertex_kernels.cpp, included once per instruction set
// inside its own namespace with SOFTRAST_DOUBLES (2, 4 or 8 lanes of double) defined and the
// matching `#pragma GCC target` in force. Each step below is the scalar code's step, lane-wise;
// the comments name the scalar line it mirrors.

constexpr int kD = SOFTRAST_DOUBLES;
typedef double D __attribute__((vector_size(8 * kD)));
typedef int64_t Q __attribute__((vector_size(8 * kD)));

// std::nearbyint: the current rounding mode (round half to even by default).
[[gnu::always_inline]] inline D round_current(D v) {
#if SOFTRAST_DOUBLES == 8
  return reinterpret_cast<D>(_mm512_roundscale_pd(reinterpret_cast<__m512d>(v),
                                                  _MM_FROUND_CUR_DIRECTION | _MM_FROUND_NO_EXC));
#elif SOFTRAST_DOUBLES == 4
  return reinterpret_cast<D>(
      _mm256_round_pd(reinterpret_cast<__m256d>(v), _MM_FROUND_CUR_DIRECTION | _MM_FROUND_NO_EXC));
#else
  for (int l = 0; l < kD; ++l) v[l] = std::nearbyint(v[l]);  // SSE2 has no rounding instruction
  return v;
#endif
}

// std::clamp(v, lo, hi) = v < lo ? lo : (hi < v ? hi : v), NaN passing through.
[[gnu::always_inline]] inline D clamp_like_std(D v, double lo, double hi) {
  D lo_v = D{} + lo, hi_v = D{} + hi;
  D upper = (hi_v < v) ? hi_v : v;
  return (v < lo_v) ? lo_v : upper;
}

// viewport.cpp's snap(): nearbyint(c * 256), NaN to 0, clamped to the fixed-point range; the
// residual c * 256 - nearbyint(c * 256) where not clamped (else 0). The result is an integer
// below 2^23 in magnitude, as a double: converted straight to int32 (exact), not through int64,
// which AVX2 has no vector conversion to (GCC converted lane by lane).
typedef int32_t IN __attribute__((vector_size(4 * kD)));
[[gnu::always_inline]] inline IN snap(D window_coord, D& residual) {
  D scaled = window_coord * double(kSubpixelOne);
  D fx = round_current(scaled);
  fx = (fx == fx) ? fx : D{};
  double limit = double(kMaxCoordFx8 - 1);
  D magnitude = (fx < 0.0) ? -fx : fx;
  residual = (magnitude <= limit) ? scaled - fx : D{};
  residual = (residual == residual) ? residual : D{};
  static_assert(kMaxCoordFx8 <= (int64_t(1) << 31));
  return __builtin_convertvector(clamp_like_std(fx, -limit, limit), IN);
}

#if SOFTRAST_DOUBLES == 8
// A full group's positions: each vertex's x, y, z, w in one load, then two 4x4 transposes (the
// same floats as the lane-by-lane copy, converted to double exactly). (The stride is at least 4
// floats: a clip vertex's position.)
[[gnu::always_inline]] inline void load_positions(const float* first, size_t stride, D& x, D& y,
                                                  D& z, D& w) {
  __m128 v[8];
  for (int l = 0; l < 8; ++l) v[l] = _mm_loadu_ps(first + size_t(l) * stride);
  _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);
  _MM_TRANSPOSE4_PS(v[4], v[5], v[6], v[7]);
  x = reinterpret_cast<D>(_mm512_cvtps_pd(_mm256_set_m128(v[4], v[0])));
  y = reinterpret_cast<D>(_mm512_cvtps_pd(_mm256_set_m128(v[5], v[1])));
  z = reinterpret_cast<D>(_mm512_cvtps_pd(_mm256_set_m128(v[6], v[2])));
  w = reinterpret_cast<D>(_mm512_cvtps_pd(_mm256_set_m128(v[7], v[3])));
}

// A full group's PackedVertex records, 8 x 24 bytes, as three 64-byte stores: the six fields'
// lanes paired into (x, y), (z, inv_w), (x_residual, y_residual) 64-bit lanes, then those
// interleaved record by record.
[[gnu::always_inline]] inline void store_records(PackedVertex* out, __m256i x, __m256i y, __m256 z,
                                                 __m256 inv_w, __m256 rx, __m256 ry) {
  static_assert(sizeof(PackedVertex) == 24);
  const __m512i pair = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  auto pairs = [&](__m256i lo, __m256i hi) {
    return _mm512_permutex2var_epi32(_mm512_castsi256_si512(lo), pair, _mm512_castsi256_si512(hi));
  };
  const __m512i a = pairs(x, y), b = pairs(_mm256_castps_si256(z), _mm256_castps_si256(inv_w)),
                c = pairs(_mm256_castps_si256(rx), _mm256_castps_si256(ry));
  // Record r is a[r] b[r] c[r]; 64-bit lanes of a and b (index 8 + k: b[k]), then c's by mask.
  auto* dst = reinterpret_cast<__m512i*>(out);
  _mm512_storeu_si512(
      dst, _mm512_mask_permutexvar_epi64(
               _mm512_permutex2var_epi64(a, _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), b), 0x24,
               _mm512_setr_epi64(0, 0, 0, 0, 0, 1, 0, 0), c));
  _mm512_storeu_si512(
      dst + 1, _mm512_mask_permutexvar_epi64(
                   _mm512_permutex2var_epi64(a, _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), b),
                   0x49, _mm512_setr_epi64(2, 0, 0, 3, 0, 0, 4, 0), c));
  _mm512_storeu_si512(
      dst + 2, _mm512_mask_permutexvar_epi64(
                   _mm512_permutex2var_epi64(a, _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), b),
                   0x92, _mm512_setr_epi64(0, 5, 0, 0, 6, 0, 0, 7), c));
}
#elif SOFTRAST_DOUBLES == 4
// The same for AVX2's groups of 4: one 4x4 transpose.
[[gnu::always_inline]] inline void load_positions(const float* first, size_t stride, D& x, D& y,
                                                  D& z, D& w) {
  __m128 v[4];
  for (int l = 0; l < 4; ++l) v[l] = _mm_loadu_ps(first + size_t(l) * stride);
  _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);
  x = reinterpret_cast<D>(_mm256_cvtps_pd(v[0]));
  y = reinterpret_cast<D>(_mm256_cvtps_pd(v[1]));
  z = reinterpret_cast<D>(_mm256_cvtps_pd(v[2]));
  w = reinterpret_cast<D>(_mm256_cvtps_pd(v[3]));
}

// 4 x 24 bytes as three 32-byte stores: the fields paired into 64-bit (x, y), (z, inv_w) and
// (x_residual, y_residual) lanes, then those interleaved record by record.
[[gnu::always_inline]] inline void store_records(PackedVertex* out, __m128i x, __m128i y, __m128 z,
                                                 __m128 inv_w, __m128 rx, __m128 ry) {
  static_assert(sizeof(PackedVertex) == 24);
  const __m128i xy01 = _mm_unpacklo_epi32(x, y), xy23 = _mm_unpackhi_epi32(x, y);
  const __m128i zw01 = _mm_castps_si128(_mm_unpacklo_ps(z, inv_w));
  const __m128i zw23 = _mm_castps_si128(_mm_unpackhi_ps(z, inv_w));
  const __m128i rr01 = _mm_castps_si128(_mm_unpacklo_ps(rx, ry));
  const __m128i rr23 = _mm_castps_si128(_mm_unpackhi_ps(rx, ry));
  // Records 0 to 3 in 64-bit pieces: xy0 zw0 rr0 xy1 | zw1 rr1 xy2 zw2 | rr2 xy3 zw3 rr3.
  auto* dst = reinterpret_cast<__m256i*>(out);
  _mm256_storeu_si256(
      dst, _mm256_set_m128i(_mm_blend_epi32(rr01, xy01, 0xc), _mm_unpacklo_epi64(xy01, zw01)));
  _mm256_storeu_si256(
      dst + 1, _mm256_set_m128i(_mm_unpacklo_epi64(xy23, zw23), _mm_unpackhi_epi64(zw01, rr01)));
  _mm256_storeu_si256(
      dst + 2, _mm256_set_m128i(_mm_unpackhi_epi64(zw23, rr23), _mm_blend_epi32(rr23, xy23, 0xc)));
}
#endif

void transform_vertices(const VertexBatch& b, size_t begin, size_t end) {
  const double min_w = double(kMinClipW), width = b.width, height = b.height;
  for (size_t i = begin; i < end; i += kD) {
    size_t lanes = std::min<size_t>(kD, end - i);
    D x, y, z, w;
#if SOFTRAST_DOUBLES >= 4
    if (lanes == kD) {
      load_positions(b.data + i * size_t(b.stride), size_t(b.stride), x, y, z, w);
    } else
#endif
    {
      for (int l = 0; l < kD; ++l) {
        // Past the end, repeat the last vertex (computed, not stored).
        const float* p = b.data + (i + std::min<size_t>(l, lanes - 1)) * size_t(b.stride);
        x[l] = p[0], y[l] = p[1], z[l] = p[2], w[l] = p[3];
      }
    }
    // clip.cpp: is_finite_position, then clip_outcode's plane_distance(p) >= 0 per plane.
    Q finite = (x - x == 0.0) & (y - y == 0.0) & (z - z == 0.0) & (w - w == 0.0);
    Q code = (~Q(w - min_w >= 0.0) & 1) | (~Q(z + w >= 0.0) & 2) | (~Q(w - z >= 0.0) & 4) |
             (~Q(x + b.guard_x * w >= 0.0) & 8) | (~Q(b.guard_x * w - x >= 0.0) & 16) |
             (~Q(y + b.guard_y * w >= 0.0) & 32) | (~Q(b.guard_y * w - y >= 0.0) & 64);
    code = finite ? code : (Q{} + (int64_t(1) << kNumClipPlanes));
    // viewport.cpp: Viewport::to_window.
    D inv_w = 1.0 / w;
    D x_ndc = x * inv_w, y_ndc = y * inv_w, z_ndc = z * inv_w;
    D rx, ry;
    IN xi = snap((x_ndc + 1.0) * 0.5 * width, rx);
    IN yi = snap((1.0 - y_ndc) * 0.5 * height, ry);
    D wz = clamp_like_std((z_ndc + 1.0) * 0.5, 0.0, 1.0);
    // The six fields converted in vectors, then written: a full group by vector stores at AVX2 and
    // AVX-512, vertex by vertex otherwise.
    typedef float FN __attribute__((vector_size(4 * kD)));
    const IN outside = __builtin_convertvector(code != 0, IN);  // PackedVertex: kOutsideVolume
    xi = outside ? IN{} + kOutsideVolume : xi;
    FN zf = __builtin_convertvector(wz, FN), wf = __builtin_convertvector(inv_w, FN);
    FN rxf = __builtin_convertvector(rx, FN), ryf = __builtin_convertvector(ry, FN);
    if (b.depth_bias != 0.0f) {  // geometry_stage.hpp: the depth bias, in float
      for (int l = 0; l < kD; ++l) zf[l] = std::clamp(zf[l] + b.depth_bias, 0.0f, 1.0f);
    }
#if SOFTRAST_DOUBLES == 8
    if (lanes == kD) {
      _mm_storel_epi64(reinterpret_cast<__m128i*>(b.codes + i),
                       _mm512_cvtepi64_epi8(reinterpret_cast<__m512i>(code)));
      store_records(b.window + i, reinterpret_cast<__m256i>(xi), reinterpret_cast<__m256i>(yi),
                    reinterpret_cast<__m256>(zf), reinterpret_cast<__m256>(wf),
                    reinterpret_cast<__m256>(rxf), reinterpret_cast<__m256>(ryf));
      continue;
    }
#elif SOFTRAST_DOUBLES == 4
    if (lanes == kD) {
      for (int l = 0; l < kD; ++l) b.codes[i + size_t(l)] = uint8_t(code[l]);
      store_records(b.window + i, reinterpret_cast<__m128i>(xi), reinterpret_cast<__m128i>(yi),
                    reinterpret_cast<__m128>(zf), reinterpret_cast<__m128>(wf),
                    reinterpret_cast<__m128>(rxf), reinterpret_cast<__m128>(ryf));
      continue;
    }
#endif
    for (size_t l = 0; l < lanes; ++l) {
      b.codes[i + l] = uint8_t(code[l]);
      b.window[i + l] = {xi[l], yi[l], zf[l], wf[l], rxf[l], ryf[l]};
    }
  }
}
