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
[[gnu::always_inline]] inline void make_offsets(const TriangleCoverage& t, EdgeOffsets<V>& o) {
  for (int g = 0; g < kGroups; ++g) {
    I p = pixel_index(g);
    V column = __builtin_convertvector(p & 3, V), row = __builtin_convertvector(p >> 2, V);
    for (int k = 0; k < 3; ++k) {
      o.off[k][g] = T(t.edge[k].a * kSubpixelOne) * column + T(t.edge[k].b * kSubpixelOne) * row;
    }
  }
}

// `e`: the three edge functions at the block's first sample. T is int32_t only where
// fixed_point.hpp's kSmallTriangleFx8 bound proves every value fits.
template <class V, class T>
[[gnu::always_inline]] inline uint32_t coverage_bits(const int64_t e[3],
                                                     const EdgeOffsets<V>& o) {
  uint32_t bits = 0;
  for (int g = 0; g < kGroups; ++g) {
    V all = (T(e[0]) + o.off[0][g]) | (T(e[1]) + o.off[1][g]) | (T(e[2]) + o.off[2][g]);
    bits |= lane_bits(__builtin_convertvector(all >= 0, I)) << (g * kLanes);
  }
  return bits;
}

// ---------------------------------------------------------------------------------------------
// The depth resolve of one block (tile_visibility.hpp): the fragment stage's depth, exactly
// (dx = float(px) + 0.5 - x_ref, z = clamp((a0 + dadx dx) + dady dy, 0, 1) with std::clamp's
// handling of NaN and -0, no contraction), tested against the tile's depth; where it passes,
// depth and winner id are written.
template <bool kLessEqual>
[[gnu::always_inline]] inline void resolve_lanes(const DepthPlaneRef& p, int x, int y,
                                                 uint32_t mask, int32_t id, float* depth,
                                                 int32_t* ids) {
  for (int g = 0; g < kGroups; ++g) {
    I lane = pixel_index(g);
    F dx = (__builtin_convertvector((lane & 3) + x, F) + 0.5f) - p.x_ref;
    F dy = (__builtin_convertvector((lane >> 2) + y, F) + 0.5f) - p.y_ref;
    F z = (p.z.a0 + p.z.dadx * dx) + p.z.dady * dy;
    F zero = F{} + 0.0f, one = F{} + 1.0f;
    z = (one < z) ? one : z;
    z = (z < zero) ? zero : z;
    F stored;
    I winner;
    std::memcpy(&stored, depth + g * kLanes, sizeof(F));
    std::memcpy(&winner, ids + g * kLanes, sizeof(I));
    I covered = ((int32_t(mask) >> lane) & 1) != 0;
    I pass = (kLessEqual ? (z <= stored) : (z < stored)) & covered;
    stored = pass ? z : stored;
    winner = pass ? (I{} + id) : winner;
    std::memcpy(depth + g * kLanes, &stored, sizeof(F));
    std::memcpy(ids + g * kLanes, &winner, sizeof(I));
  }
}

// ---------------------------------------------------------------------------------------------
// One record in one tile.

enum class Mode { kImmediate, kLess, kLessEqual };

// The pixels of the block at (x, y) inside the tile's region (only the image's last row and
// column of tiles are cut).
[[gnu::always_inline]] inline uint32_t region_bits(const PixelRect& r, int x, int y) {
  if (x + kBlockSize <= r.x1 && y + kBlockSize <= r.y1) return 0xffffu;
  return block_rect_mask(0, std::min(kBlockSize, r.x1 - x), 0, std::min(kBlockSize, r.y1 - y));
}

template <Mode kMode>
[[gnu::always_inline]] inline void emit(TileJob& job, const TriRecord& rec, int32_t id, int x,
                                        int y, uint32_t bits) {
  if constexpr (kMode == Mode::kImmediate) {
    job.program->shade_block(job.program->shader, *job.target, rec.interp(), x, y, bits);
  } else {
    TileVisibility& v = *job.visibility;
    int b = v.block(x, y);
    const Interpolants& in = rec.interp();
    DepthPlaneRef plane{in.x_ref, in.y_ref, in.z};
    resolve_lanes<kMode == Mode::kLessEqual>(plane, x, y, bits, id, v.depth[b], v.id[b]);
  }
}

// Exact block classification against the three edges, as tile_raster.cpp's: E is linear, so its
// extremes over the block's samples are at the corner samples picked by the signs of a and b.
struct EdgeExtents {
  int64_t lo[3], hi[3];  // added to E at the block's first sample: its minimum and maximum
};
[[gnu::always_inline]] inline EdgeExtents edge_extents(const TriangleCoverage& t, int size) {
  EdgeExtents x;
  int64_t span = int64_t(size - 1) * kSubpixelOne;
  for (int k = 0; k < 3; ++k) {
    int64_t ax = t.edge[k].a * span, by = t.edge[k].b * span;
    x.lo[k] = std::min<int64_t>(ax, 0) + std::min<int64_t>(by, 0);
    x.hi[k] = std::max<int64_t>(ax, 0) + std::max<int64_t>(by, 0);
  }
  return x;
}
enum class Test { kOutside, kInside, kPartial };
[[gnu::always_inline]] inline Test classify(const int64_t e[3], const EdgeExtents& x) {
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    if (e[k] + x.hi[k] < 0) return Test::kOutside;
    if (e[k] + x.lo[k] < 0) inside = false;
  }
  return inside ? Test::kInside : Test::kPartial;
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
};

template <Mode kMode, class V, class T>
[[gnu::always_inline]] inline void raster_record_with(TileJob& job, const TriRecord& rec,
                                                      int32_t id, const PixelRect& area,
                                                      const EdgeGrid& grid) {
  const TriangleCoverage& t = rec.coverage;
  EdgeOffsets<V> offsets;
  make_offsets<V, T>(t, offsets);
  int bx0 = area.x0 & ~(kBlockSize - 1), by0 = area.y0 & ~(kBlockSize - 1);
  auto partial_block = [&](int x, int y) {
    int64_t e[3];
    grid.at(x, y, e);
    uint32_t bits = coverage_bits<V, T>(e, offsets) & region_bits(job.region, x, y);
    if (bits != 0) emit<kMode>(job, rec, id, x, y, bits);
  };
  // Small areas (at most 16x16 pixels of blocks, the usual triangle of a dense mesh): every
  // block's coverage directly, no classification.
  if (area.x1 - bx0 <= kMidBlockSize && area.y1 - by0 <= kMidBlockSize) {
    for (int y = by0; y < area.y1; y += kBlockSize) {
      for (int x = bx0; x < area.x1; x += kBlockSize) partial_block(x, y);
    }
    return;
  }
  // Larger: 16x16 blocks, then 4x4 blocks, trivially rejected or accepted (a block inside every
  // edge is emitted without per-pixel tests); only the rest is tested pixel by pixel.
  EdgeExtents mid = edge_extents(t, kMidBlockSize), small = edge_extents(t, kBlockSize);
  int mx0 = area.x0 & ~(kMidBlockSize - 1), my0 = area.y0 & ~(kMidBlockSize - 1);
  for (int my = my0; my < area.y1; my += kMidBlockSize) {
    for (int mx = mx0; mx < area.x1; mx += kMidBlockSize) {
      int64_t e[3];
      grid.at(mx, my, e);
      Test test = classify(e, mid);
      if (test == Test::kOutside) continue;
      // Only blocks that overlap the area (the 32-bit bound in fixed_point.hpp relies on it).
      int y_end = std::min(my + kMidBlockSize, area.y1), x_end = std::min(mx + kMidBlockSize, area.x1);
      for (int y = std::max(my, by0); y < y_end; y += kBlockSize) {
        for (int x = std::max(mx, bx0); x < x_end; x += kBlockSize) {
          Test sub = test;
          if (test == Test::kPartial) {
            grid.at(x, y, e);
            sub = classify(e, small);
          }
          if (sub == Test::kInside) {
            emit<kMode>(job, rec, id, x, y, region_bits(job.region, x, y));
          } else if (sub == Test::kPartial) {
            partial_block(x, y);
          }
        }
      }
    }
  }
}

template <Mode kMode>
[[gnu::always_inline]] inline void raster_record(TileJob& job, const TriRecord& rec, int32_t id) {
  const TriangleCoverage& t = rec.coverage;
  PixelRect area = intersect(t.bounds, job.region);
  if (area.empty()) return;
  EdgeGrid grid;
  grid.x0 = area.x0;
  grid.y0 = area.y0;
  for (int k = 0; k < 3; ++k) {
    grid.origin[k] = t.edge[k].at(sample_fx8(area.x0), sample_fx8(area.y0));
    grid.step_x[k] = t.edge[k].a * kSubpixelOne;
    grid.step_y[k] = t.edge[k].b * kSubpixelOne;
  }
  if (rec.small) {
    raster_record_with<kMode, I, int32_t>(job, rec, id, area, grid);
  } else {
    raster_record_with<kMode, L, int64_t>(job, rec, id, area, grid);
  }
}

template <Mode kMode>
[[gnu::always_inline]] inline void raster_records(TileJob& job, const std::byte* arena,
                                                  const uint32_t* offsets, size_t count) {
  for (size_t i = 0; i < count; ++i) {
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

void raster_immediate(TileJob& job, const std::byte* arena, const uint32_t* offsets,
                      size_t count) {
  raster_records<Mode::kImmediate>(job, arena, offsets, count);
}
void raster_deferred(TileJob& job, const std::byte* arena, const uint32_t* offsets, size_t count) {
  if (job.less_equal) {
    raster_records<Mode::kLessEqual>(job, arena, offsets, count);
  } else {
    raster_records<Mode::kLess>(job, arena, offsets, count);
  }
}
void resolve_block(const DepthPlaneRef& plane, int x, int y, uint32_t mask, int32_t id,
                   bool less_equal, float* depth, int32_t* ids) {
  if (less_equal) {
    resolve_lanes<true>(plane, x, y, mask, id, depth, ids);
  } else {
    resolve_lanes<false>(plane, x, y, mask, id, depth, ids);
  }
}
