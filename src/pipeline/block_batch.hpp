// pipeline/block_batch.hpp: the blocks that several triangles cover in an immediate tile, shaded
// several triangles per call. A dense mesh's triangles cover a few pixels each, and the edges of
// larger ones cut blocks that their neighbours complete: a 4x4 block is reached by several
// consecutive triangles, each with a few live lanes of its own call. When the shader reads no
// derivatives (FragmentProgram::shade_mixed) and the state is the one deferred shading needs
// (opaque, depth test less or less-equal with writes), the partly covered blocks are held, one
// slot per block of the tile, and the pixels that later triangles cover without sharing one join
// them; a held block is shaded (ShadeMixedFn, each lane with its own triangle's planes, depth test
// and write) when it is complete, when a triangle covering one of its held pixels or of the other
// facing reaches it, or at the end of the tile.
//
// Why the image is the same bit for bit: every pixel still sees its fragments in submission order
// (a block is shaded before a later triangle covering one of its held pixels is added; different
// blocks are different pixels), and each lane computes what the triangle's own call computes.
#pragma once

#include <cstdint>

#include "raster/raster.hpp"
#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

class BlockBatch {
 public:
  BlockBatch() = default;
  ~BlockBatch() { flush(); }  // in case the owner did not: held pixels are never dropped
  BlockBatch(const BlockBatch&) = delete;
  BlockBatch& operator=(const BlockBatch&) = delete;

  // Starts a tile of a draw (the batch is kept from tile to tile, so that its slots are not
  // built again for each: it holds nothing between tiles).
  void begin(const FragmentProgram& program, const ShadeTarget& target) {
    program_ = &program;
    target_ = &target;
  }
  // The pixels `mask` of the block at (x, y), covered by the triangle of `in`: held for a call
  // with other triangles' pixels of that block, or shaded now if they are the whole block (after
  // the block's held pixels, if any). In the header, for the tile kernels to inline: the usual
  // cases (a whole block where nothing is held, an empty slot taking a block, a held block gaining
  // pixels that leave it incomplete) are a few tests and stores, or one call to the fragment stage
  // (spheres_1m gouraud, one thread: 40.24 -> 39.85 ms, against add and its slot cases as two
  // calls). GCC still keeps it out of line at some call sites, the specks' among them; forcing it
  // inline there measured slower (38.25 -> 38.54 ms).
  void add(const Interpolants& in, int x, int y, uint32_t mask) {
    const int index = slot_index(x, y);
    Slot& slot = slots_[index];
    MixedBlock& held = slot.block;
    if (!holds(index)) {
      if (mask == 0xffffu) {  // a whole block, nothing held where it goes
        program_->shade_block(program_->shader, *target_, in, x, y, mask);
      } else {
        start(slot, in, x, y, mask, index);
      }
      return;
    }
    if (slot.x == x && slot.y == y && (slot.covered & mask) == 0 &&
        held.front_facing == in.front_facing && (slot.covered | mask) != 0xffffu) {
      join(slot, in, mask);  // (a whole block never joins: the slot holds pixels)
      return;
    }
    add_with_shading(in, x, y, mask, index);
  }
  // Shades every held block.
  void flush();

 private:
  // Held blocks, one slot per block of a tile (a block always goes to the same slot, so it is
  // never held twice; blocks of other tiles would share slots, but a batch serves one tile at a
  // time).
  struct Slot {
    int x = 0, y = 0;
    uint32_t covered = 0;  // the union of block.mask
    MixedBlock block;      // count 0: empty
  };
  static constexpr int kSide = kTileSize / kBlockSize;  // a power of two
  static int slot_index(int x, int y) {
    return ((x >> 2) & (kSide - 1)) | ((y >> 2) & (kSide - 1)) * kSide;
  }
  bool holds(int slot) const { return (held_[slot >> 6] >> (slot & 63)) & 1u; }
  // add's other cases, each a call to the fragment stage (a block completed, a whole block
  // where one is held, a held block of another place or facing, or one its pixels overlap): out
  // of line, so that the usual cases save and restore no registers.
  [[gnu::noinline]] void add_with_shading(const Interpolants& in, int x, int y, uint32_t mask,
                                          int index);
  // The slot (empty) takes the pixels `mask` of the block at (x, y).
  void start(Slot& slot, const Interpolants& in, int x, int y, uint32_t mask, int index) {
    slot.x = x;
    slot.y = y;
    slot.covered = mask;
    slot.block.front_facing = in.front_facing;
    slot.block.winner[0] = &in;
    slot.block.mask[0] = mask;
    slot.block.count = 1;
    held_[index >> 6] |= uint64_t(1) << (index & 63);
  }
  // The held block of `slot` gains the pixels `mask` (disjoint from its own) of `in`'s triangle.
  static void join(Slot& slot, const Interpolants& in, uint32_t mask) {
    slot.block.winner[slot.block.count] = &in;
    slot.block.mask[slot.block.count++] = mask;  // at most 16: the masks are disjoint, not empty
    slot.covered |= mask;
  }
  void shade(int slot);

  const FragmentProgram* program_ = nullptr;
  const ShadeTarget* target_ = nullptr;
  // Which slots hold a block (count != 0): a whole block checks this, not its slot's 200 bytes,
  // and flush visits only these.
  uint64_t held_[kSide * kSide / 64] = {};
  Slot slots_[kSide * kSide];
};

}  // namespace softrast::detail
