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

// One triangle as binned: what the tile kernels read of its coverage (edges, bounds, the 32-bit
// flag), then its Interpolants cut short after the draw's varyings (interpolants_bytes), then,
// only for the scanline rasterizer (RasterAlgorithm::kScanline), its vertices. Records are laid
// out back to back in an arena, record_bytes() apart; never copied as a whole. (The vertices,
// which the tile kernels do not read, were first in the record: 24 bytes of every record's first
// cache line.)
struct TriRecord {
  EdgeFunction edge[3];  // TriangleCoverage::edge
  PixelRect bounds;      // TriangleCoverage::bounds
  // The coverage of a speck (bounds of at most 5x5 pixels), where the SIMD setup computed it on
  // its way to dropping the specks that cover nothing: the masks of the 2x2 blocks from (bounds.x0
  // & ~3, bounds.y0 & ~3), 16 bits each (bit 4 row + column, the tile kernels' masks) in the
  // order top left, top right, bottom left, bottom right. 0: not computed (the scalar setup, a
  // larger triangle); the tile kernels then test the edges.
  uint64_t blocks = 0;
  // The vertices span at most kSmallTriangleFx8 in x and y: the 32-bit coverage path applies.
  bool small = false;

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
  // The record's coverage as the rasterizers take it; precondition: made with the vertices.
  TriangleCoverage coverage(int num_varyings) const {
    TriangleCoverage c;
    const int32_t* v = vertices(num_varyings);
    for (int k = 0; k < 3; ++k) {
      c.vx[k] = v[k];
      c.vy[k] = v[3 + k];
      c.edge[k] = edge[k];
    }
    c.bounds = bounds;
    return c;
  }
};
static_assert(sizeof(TriRecord) % alignof(Interpolants) == 0);
static_assert(interpolants_bytes(0) % alignof(int32_t) == 0);

// Bytes of one record for `num_varyings` varyings, with or without the vertices, a multiple of 8
// so that records stay aligned.
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
