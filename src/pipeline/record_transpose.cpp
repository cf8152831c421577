// pipeline/record_transpose.cpp: write_records in AVX2, eight lanes at a time (a 16-lane group of
// the AVX-512 kernel as two halves).
#include "pipeline/record_transpose.hpp"

#include "core/isa_target.hpp"

#include <immintrin.h>

#include <cstddef>

namespace softrast::detail {

// The records' 32-bit words, as the rows below make them.
static_assert(offsetof(TriRecord, bounds) == 0 && sizeof(PixelRect) == 16);
static_assert(offsetof(TriRecord, blocks) == 16 && offsetof(TriRecord, small) == 24);
static_assert(sizeof(TriRecord) == 32);
static_assert(offsetof(RecordEdges, edge) == 0 && sizeof(RecordEdge) == 16 &&
              offsetof(RecordEdge, b) == 4 && offsetof(RecordEdge, c) == 8);
static_assert(offsetof(Interpolants, x_ref) == 0 && offsetof(Interpolants, y_ref) == 4);
static_assert(offsetof(Interpolants, z) == 8 && offsetof(Interpolants, inv_w) == 32);
static_assert(offsetof(Interpolants, num_varyings) == 44);
static_assert(offsetof(Interpolants, front_facing) == 48 && offsetof(Interpolants, var) == 52);
static_assert(sizeof(Plane) == 12 && sizeof(DepthPlane) == 24 && sizeof(bool) == 1);

SOFTRAST_TARGET_BEGIN_AVX2
namespace {

// Lanes [0, 8) of an array of 32-bit fields.
[[gnu::always_inline]] inline __m256i row(const void* p) {
  return _mm256_load_si256(static_cast<const __m256i*>(p));
}

// The low (kPick 0x88) or high (0xdd) words of eight 64-bit lanes, lanes 0-3 in a and 4-7 in b.
template <int kPick>
[[gnu::always_inline]] inline __m256i words_of(__m256i a, __m256i b) {
  // Per 128-bit half, the even (odd) words of a then b: lanes 0 1 4 5 | 2 3 6 7.
  const __m256 w = _mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), kPick);
  return _mm256_permute4x64_epi64(_mm256_castps_si256(w), 0xd8);
}

// The low and high words of lanes [0, 8) of an array of 64-bit fields.
[[gnu::always_inline]] inline void word_rows(const void* p, __m256i& low, __m256i& high) {
  const __m256i a = row(p), b = row(static_cast<const std::byte*>(p) + 32);
  low = words_of<0x88>(a, b);
  high = words_of<0xdd>(a, b);
}

// Rows [0, 8) (row j: word j of lanes 0-7) transposed: lane l's words [8 block, 8 block + 8) to
// dest[l] + 32 block, all eight (write_records' room past a record's end).
[[gnu::always_inline]] inline void transpose_store(const __m256i* r, std::byte* const* dest,
                                                   int block) {
  const __m256i t0 = _mm256_unpacklo_epi32(r[0], r[1]), t1 = _mm256_unpackhi_epi32(r[0], r[1]);
  const __m256i t2 = _mm256_unpacklo_epi32(r[2], r[3]), t3 = _mm256_unpackhi_epi32(r[2], r[3]);
  const __m256i t4 = _mm256_unpacklo_epi32(r[4], r[5]), t5 = _mm256_unpackhi_epi32(r[4], r[5]);
  const __m256i t6 = _mm256_unpacklo_epi32(r[6], r[7]), t7 = _mm256_unpackhi_epi32(r[6], r[7]);
  // u[l]: words 0-3 (low half) or 4-7 (high half) of lanes l and l + 4.
  const __m256i u[8] = {
      _mm256_unpacklo_epi64(t0, t2), _mm256_unpackhi_epi64(t0, t2), _mm256_unpacklo_epi64(t1, t3),
      _mm256_unpackhi_epi64(t1, t3), _mm256_unpacklo_epi64(t4, t6), _mm256_unpackhi_epi64(t4, t6),
      _mm256_unpacklo_epi64(t5, t7), _mm256_unpackhi_epi64(t5, t7),
  };
  auto at = [&](int l) { return reinterpret_cast<__m256i*>(dest[l] + 32 * block); };
  for (int l = 0; l < 4; ++l) {
    _mm256_storeu_si256(at(l), _mm256_permute2x128_si256(u[l], u[4 + l], 0x20));
    _mm256_storeu_si256(at(l + 4), _mm256_permute2x128_si256(u[l], u[4 + l], 0x31));
  }
}

// Lanes [h, h + 8) of the group, the rows of each block of eight words made just before it is
// stored.
[[gnu::always_inline]] inline void records8(const TriangleLanes& lanes, int h, int num_varyings,
                                            FrontFace front_face, std::byte* const* dest,
                                            std::byte* const* edges, int tiles_x,
                                            GroupTiles& tiles) {
  static_assert(record_bytes(0) >= 16 * 4, "the first two blocks are whole in every record");
  const __m256i one = _mm256_set1_epi32(1);
  __m256i r[8];
  // Words from 24 first: the varyings' planes from the fourth (a0, dadx, dady each; var[i][k] is
  // plane 3 i + k, word 21 + 3 i + k). The last block of a record may reach past its end, into
  // the next record's first block or its edges, which are stored after it.
  const float* planes = &lanes.var[0][0][h];
  const int count = 3 * num_varyings;
  for (int first = 3, block = 3; first < count; first += 8, ++block) {
    if (first + 8 <= count) {
      for (int i = 0; i < 8; ++i) r[i] = row(planes + (first + i) * TriangleLanes::kMaxLanes);
    } else {
      for (int i = 0; i < 8; ++i) {
        r[i] = first + i < count ? row(planes + (first + i) * TriangleLanes::kMaxLanes)
                                 : _mm256_setzero_si256();
      }
    }
    transpose_store(r, dest, block);
  }
  // Words 16-23: the rest of the fixed fields, the first varying's planes (past the record's end
  // when it has none: the next record's bytes, stored after).
  for (int k = 0; k < 3; ++k) r[k] = row(&lanes.inv_w[k][h]);
  r[3] = _mm256_set1_epi32(num_varyings);
  {  // front_facing (is_front_facing): area < 0 counter-clockwise, area > 0 clockwise.
    const __m256i zero = _mm256_setzero_si256();
    const __m256i a = _mm256_load_si256(reinterpret_cast<const __m256i*>(&lanes.area[h]));
    const __m256i b = _mm256_load_si256(reinterpret_cast<const __m256i*>(&lanes.area[h + 4]));
    const bool ccw = front_face == FrontFace::kCounterClockwise;
    const __m256i fa = ccw ? _mm256_cmpgt_epi64(zero, a) : _mm256_cmpgt_epi64(a, zero);
    const __m256i fb = ccw ? _mm256_cmpgt_epi64(zero, b) : _mm256_cmpgt_epi64(b, zero);
    r[4] = _mm256_and_si256(words_of<0x88>(fa, fb), one);
  }
  for (int i = 0; i < 3; ++i) {
    r[5 + i] = i < count ? row(planes + i * TriangleLanes::kMaxLanes) : _mm256_setzero_si256();
  }
  transpose_store(r, dest, 2);
  // Words 8-15: the interpolants from x_ref.
  r[0] = row(&lanes.x_ref[h]);
  r[1] = row(&lanes.y_ref[h]);
  word_rows(&lanes.z[0][h], r[2], r[3]);
  word_rows(&lanes.z[1][h], r[4], r[5]);
  word_rows(&lanes.z[2][h], r[6], r[7]);
  transpose_store(r, dest, 1);
  // Words 0-7: the bounds, the blocks, small (a bool, then the header's padding).
  for (int i = 0; i < 4; ++i) r[i] = row(&lanes.bounds[i][h]);
  r[4] = row(&lanes.blocks[0][h]);
  r[5] = row(&lanes.blocks[1][h]);
  r[6] = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(int(lanes.small >> h)),
                                            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)),
                          one);
  r[7] = _mm256_setzero_si256();
  {  // The bins (GroupTiles), from the bounds x0, y0, x1, y1 in r[0..4).
    static_assert(kTileSize == 1 << 6);
    const __m256i tx0 = _mm256_srli_epi32(r[0], 6), ty0 = _mm256_srli_epi32(r[1], 6);
    const __m256i tx1 = _mm256_srli_epi32(_mm256_sub_epi32(r[2], one), 6);
    const __m256i ty1 = _mm256_srli_epi32(_mm256_sub_epi32(r[3], one), 6);
    const __m256i one_tile =
        _mm256_and_si256(_mm256_cmpeq_epi32(tx0, tx1), _mm256_cmpeq_epi32(ty0, ty1));
    tiles.spans |= (~uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(one_tile))) & 0xffu) << h;
    _mm256_store_si256(reinterpret_cast<__m256i*>(&tiles.tile[h]),
                       _mm256_add_epi32(_mm256_mullo_epi32(ty0, _mm256_set1_epi32(tiles_x)), tx0));
  }
  transpose_store(r, dest, 0);
  // The edges (RecordEdges, before the header; scratch room for the lanes without): a and b, the
  // low and high words of c, edge by edge, then the padding. Not at all where every lane has
  // blocks (a speck's record goes without): on a dense mesh, most groups of eight. A lane that is
  // not ready (culled, or a speck covering no pixel) has no blocks, so it keeps the stores for its
  // group; leaving such lanes out too (their bits of lanes.ready) measured the same (spheres_1m
  // gouraud and phong, one thread, 36.95 / 36.77 and 47.81 / 47.86 ms).
  const __m256i no_blocks = _mm256_cmpeq_epi32(_mm256_or_si256(r[4], r[5]), _mm256_setzero_si256());
  if (_mm256_testz_si256(no_blocks, no_blocks)) return;
  for (int k = 0; k < 2; ++k) {
    r[4 * k] = row(&lanes.edge_a[k][h]);
    r[4 * k + 1] = row(&lanes.edge_b[k][h]);
    word_rows(&lanes.edge_c[k][h], r[4 * k + 2], r[4 * k + 3]);
  }
  transpose_store(r, edges, 0);
  r[0] = row(&lanes.edge_a[2][h]);
  r[1] = row(&lanes.edge_b[2][h]);
  word_rows(&lanes.edge_c[2][h], r[2], r[3]);
  for (int i = 4; i < 8; ++i) r[i] = _mm256_setzero_si256();
  transpose_store(r, edges, 1);
}

}  // namespace

void write_records(const TriangleLanes& lanes, int count, int num_varyings, FrontFace front_face,
                   std::byte* const* dest, std::byte* const* edges, int tiles_x,
                   GroupTiles& tiles) {
  tiles.spans = 0;
  for (int h = 0; h < count; h += 8) {
    records8(lanes, h, num_varyings, front_face, dest + h, edges + h, tiles_x, tiles);
  }
}

SOFTRAST_TARGET_END

}  // namespace softrast::detail
