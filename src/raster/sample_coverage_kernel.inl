// raster/sample_coverage_kernel.inl: block_sample_coverage's body, included by
// sample_coverage.cpp once per instruction set inside its own namespace (the vectors below are
// GCC vector extensions of 16 lanes, lowered to that set's registers).

// 16 lanes, one per pixel of a block (lane 4 * row + column).
typedef int32_t I16 __attribute__((vector_size(64)));
typedef uint32_t U16 __attribute__((vector_size(64)));
typedef int64_t L16 __attribute__((vector_size(128)));
typedef uint64_t UL16 __attribute__((vector_size(128)));
constexpr I16 kColumn = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
constexpr I16 kRow = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};
constexpr I16 kBit = {1 << 0, 1 << 1, 1 << 2,  1 << 3,  1 << 4,  1 << 5,  1 << 6,  1 << 7,
                      1 << 8, 1 << 9, 1 << 10, 1 << 11, 1 << 12, 1 << 13, 1 << 14, 1 << 15};

// Bit s of lane i: sample s of pixel i passes all three edges (E >= 0), exactly: each edge's value
// at a sample is its value at the block's sample s plus a * 256 * column + b * 256 * row, summed
// in int32 where the triangle is small (the bound in sample_coverage.cpp), else in int64.
[[gnu::always_inline]] inline I16 sample_bits(const SampleTriangle& tri, const SamplePattern& p,
                                              int x, int y) {
  I16 bits = {};
  if (tri.small) {
    I16 offset[3];
    for (int k = 0; k < 3; ++k) {
      const EdgeFunction& e = tri.edge[k];
      offset[k] = int32_t(e.a * kSubpixelOne) * kColumn + int32_t(e.b * kSubpixelOne) * kRow;
    }
    for (int s = 0; s < p.count; ++s) {
      I16 any_negative = {};
      for (int k = 0; k < 3; ++k) {
        const EdgeFunction& e = tri.edge[k];
        int32_t at_sample =
            int32_t(e.at(int64_t(x) * kSubpixelOne + p.x[s], int64_t(y) * kSubpixelOne + p.y[s]));
        any_negative |= at_sample + offset[k];
      }
      bits |= I16(U16(~any_negative) >> 31) << s;
    }
    return bits;
  }
  const L16 column = __builtin_convertvector(kColumn, L16),
            row = __builtin_convertvector(kRow, L16);
  L16 offset[3];
  for (int k = 0; k < 3; ++k) {
    const EdgeFunction& e = tri.edge[k];
    offset[k] = e.a * kSubpixelOne * column + e.b * kSubpixelOne * row;
  }
  for (int s = 0; s < p.count; ++s) {
    L16 any_negative = {};
    for (int k = 0; k < 3; ++k) {
      const EdgeFunction& e = tri.edge[k];
      any_negative |=
          e.at(int64_t(x) * kSubpixelOne + p.x[s], int64_t(y) * kSubpixelOne + p.y[s]) + offset[k];
    }
    bits |= __builtin_convertvector(UL16(~any_negative) >> 63, I16) << s;
  }
  return bits;
}

uint32_t block_sample_coverage(const SampleTriangle& tri, const SamplePattern& pattern,
                               const PixelRect& area, int x, int y, uint8_t cov[16]) {
  uint32_t pixels = area_pixels(area, x, y);
  if (pixels == 0) return 0;
  // Large triangles: blocks wholly outside or inside an edge decided at the block's corners. A
  // small triangle's blocks are nearly all partly covered, so its samples are tested directly
  // (the same coverage: sample_bits finds every sample of an inside block covered).
  if (!tri.small) {
    BlockTest test = classify(tri, pattern, x, y);
    if (test == BlockTest::kOutside) return 0;
    if (test == BlockTest::kInside) {
      const uint8_t all = uint8_t((1u << pattern.count) - 1u);
      for (int i = 0; i < 16; ++i) cov[i] = (pixels >> i & 1) ? all : 0;
      return pixels;
    }
  }
  I16 bits = sample_bits(tri, pattern, x, y) & (((I16{} + int32_t(pixels)) & kBit) != 0);
  uint32_t mask = 0;
  for (int i = 0; i < 16; ++i) {
    cov[i] = uint8_t(bits[i]);
    mask |= uint32_t(bits[i] != 0) << i;
  }
  return mask;
}
