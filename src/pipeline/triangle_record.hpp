// pipeline/triangle_record.hpp: what the bins hold of a set-up triangle, and the arenas that hold
// the records. The contract between the binning front end and the tile kernels.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/prefetch.hpp"
#include "raster/setup.hpp"
#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// A triangle's edge functions as a record keeps them: a and b (coordinate differences, below
// 2^24 in magnitude: fixed_point.hpp) in 32 bits, c in 64.
struct RecordEdge {
  int32_t a = 0;
  int32_t b = 0;
  int64_t c = 0;
};

// The edges of a record that has them, in the 64 bytes just before the record (the last 16
// bytes padding, for whole 32-byte stores: record_transpose.hpp).
struct RecordEdges {
  RecordEdge edge[3];
  uint32_t padding[4] = {};
};
static_assert(sizeof(RecordEdges) == 64);

// One triangle as binned: what the tile kernels read of its coverage (bounds, the speck's blocks,
// the 32-bit flag), then its Interpolants cut short after the draw's varyings
// (interpolants_bytes), then, only for the scanline rasterizer (RasterAlgorithm::kScanline), its
// vertices. Records are laid out in an arena, addressed by the offset of this header; never
// copied as a whole.
// The edge functions (RecordEdges) sit in the 64 bytes before the header, in every record but
// those of specks whose blocks the SIMD setup computed (`blocks` != 0 from write_records), which
// the tile kernels never test against edges: on a dense mesh that is most records, and the 72
// bytes of edges were more than a third of a three-varying record (spheres_1m gouraud: 274,000
// of about 310,000 records a frame). Records that the scalar paths write carry edges whatever
// their blocks (the scanline rasterizer reads them).
struct TriRecord {
  PixelRect bounds;  // TriangleCoverage::bounds
  // The coverage of a speck (bounds of at most 5x5 pixels), where the SIMD setup computed it on
  // its way to dropping the specks that cover nothing: the masks of the 2x2 blocks from (bounds.x0
  // & ~3, bounds.y0 & ~3), 16 bits each (bit 4 row + column, the tile kernels' masks) in the
  // order top left, top right, bottom left, bottom right. 0: not computed (the scalar setup, a
  // larger triangle); the tile kernels then test the edges.
  uint64_t blocks = 0;
  // The vertices span at most kSmallTriangleFx8 in x and y: the 32-bit coverage path applies.
  bool small = false;

  // Edge k (TriangleCoverage::edge); precondition: the record has its edges (see above).
  EdgeFunction edge(int k) const {
    const RecordEdge& e = edges().edge[k];
    return {e.a, e.b, e.c};
  }
  RecordEdges& edges() {
    return *reinterpret_cast<RecordEdges*>(reinterpret_cast<std::byte*>(this) -
                                           sizeof(RecordEdges));
  }
  const RecordEdges& edges() const { return const_cast<TriRecord*>(this)->edges(); }
  void set_edges(const EdgeFunction (&e)[3]) {
    RecordEdges& out = edges();
    for (int k = 0; k < 3; ++k) out.edge[k] = {int32_t(e[k].a), int32_t(e[k].b), e[k].c};
    for (uint32_t& p : out.padding) p = 0;
  }

  // The interpolants that follow the header (only var[0 .. num_varyings) exist).
  Interpolants& interp() { return *reinterpret_cast<Interpolants*>(this + 1); }
  const Interpolants& interp() const { return *reinterpret_cast<const Interpolants*>(this + 1); }

  // The clockwise vertices' x[0..2] and y[0..2] (TriangleCoverage::vx, vy), after the
  // interpolants of `num_varyings` varyings: in records made with them (record_bytes).
  int32_t* vertices(int num_varyings) {
    return reinterpret_cast<int32_t*>(reinterpret_cast<std::byte*>(this + 1) +
                                      interpolants_bytes(num_varyings));
  }
  const int32_t* vertices(int num_varyings) const {
    return const_cast<TriRecord*>(this)->vertices(num_varyings);
  }
  // The record's coverage as the rasterizers take it; precondition: made with the vertices and
  // the edges.
  TriangleCoverage coverage(int num_varyings) const {
    TriangleCoverage c;
    const int32_t* v = vertices(num_varyings);
    for (int k = 0; k < 3; ++k) {
      c.vx[k] = v[k];
      c.vy[k] = v[3 + k];
      c.edge[k] = edge(k);
    }
    c.bounds = bounds;
    return c;
  }
};
static_assert(sizeof(TriRecord) == 32 && sizeof(TriRecord) % alignof(Interpolants) == 0);
static_assert(interpolants_bytes(0) % alignof(int32_t) == 0);
static_assert(kMaxCoordFx8 <= (int64_t(1) << 30), "edge a and b fit RecordEdge's 32 bits");

// Bytes of one record's header and interpolants for `num_varyings` varyings, with or without the
// vertices, a multiple of 8 so that records stay aligned. A record with edges takes
// sizeof(RecordEdges) more, before its header.
constexpr size_t record_bytes(int num_varyings, bool with_vertices = false) {
  return (sizeof(TriRecord) + interpolants_bytes(num_varyings) +
          (with_vertices ? 6 * sizeof(int32_t) : 0) + 7) &
         ~size_t(7);
}

// Append-only bytes for records, addressed by offset (so growing may move them). Its capacity is
// kept across batches and draws: after the first frame of a scene it no longer allocates.
class RecordArena {
 public:
  void clear() { used_ = 0; }
  // Room for `bytes` more bytes, and `slack` writable bytes after them (which the next
  // allocation takes); returns the offset of the new space.
  uint32_t allocate(size_t bytes, size_t slack = 0) {
    if (used_ + bytes + slack > data_.size()) {
      data_.resize(std::max(2 * data_.size(), used_ + bytes + slack));
    }
    size_t offset = used_;
    used_ += bytes;
    return uint32_t(offset);
  }
  TriRecord* at(uint32_t offset) { return reinterpret_cast<TriRecord*>(data_.data() + offset); }
  // Asks for the lines of [offset, offset + bytes), clipped to the arena's capacity, for writing
  // (prefetch_line_for_write; only where prefetch_for_write_supported()).
  void prefetch_for_write(size_t offset, size_t bytes) const {
    const size_t end = std::min(offset + bytes, data_.size());
    for (size_t at = offset; at < end; at += 64) prefetch_line_for_write(data_.data() + at);
  }
  const std::byte* data() const { return data_.data(); }
  size_t used() const { return used_; }

 private:
  std::vector<std::byte> data_;
  size_t used_ = 0;
};

}  // namespace softrast::detail
