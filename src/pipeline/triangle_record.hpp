// pipeline/triangle_record.hpp: what the bins hold of a set-up triangle, and the arenas that hold
// the records. The contract between the binning front end and the tile kernels.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "raster/setup.hpp"
#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// One triangle as binned: its coverage (edges, bounds, the vertices for the scanline rasterizer),
// then its Interpolants cut short after the draw's varyings (interpolants_bytes). Records are
// laid out back to back in an arena, record_bytes() apart; never copied as a whole.
struct TriRecord {
  TriangleCoverage coverage;
  // The vertices span at most kSmallTriangleFx8 in x and y: the 32-bit coverage path applies.
  bool small = false;

  // The interpolants that follow the header (only var[0 .. num_varyings) exist).
  Interpolants& interp() { return *reinterpret_cast<Interpolants*>(this + 1); }
  const Interpolants& interp() const { return *reinterpret_cast<const Interpolants*>(this + 1); }
};
static_assert(sizeof(TriRecord) % alignof(Interpolants) == 0);

// Bytes of one record for `num_varyings` varyings, a multiple of 8 so that records stay aligned.
constexpr size_t record_bytes(int num_varyings) {
  return (sizeof(TriRecord) + interpolants_bytes(num_varyings) + 7) & ~size_t(7);
}

// Append-only bytes for records, addressed by offset (so growing may move them). Its capacity is
// kept across batches and draws: after the first frame of a scene it no longer allocates.
class RecordArena {
 public:
  void clear() { used_ = 0; }
  // Room for `bytes` more bytes; returns the offset of the new space.
  uint32_t allocate(size_t bytes) {
    if (used_ + bytes > data_.size()) data_.resize(std::max(2 * data_.size(), used_ + bytes));
    size_t offset = used_;
    used_ += bytes;
    return uint32_t(offset);
  }
  // Gives back the most recent allocation of `bytes` (a triangle that setup rejected).
  void release_last(size_t bytes) { used_ -= bytes; }
  TriRecord* at(uint32_t offset) { return reinterpret_cast<TriRecord*>(data_.data() + offset); }
  const std::byte* data() const { return data_.data(); }
  size_t used() const { return used_; }

 private:
  std::vector<std::byte> data_;
  size_t used_ = 0;
};

}  // namespace softrast::detail
