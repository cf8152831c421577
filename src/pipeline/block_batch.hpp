// pipeline/block_batch.hpp: immediate tiles' blocks of small triangles, shaded several triangles
// per call. A dense mesh's triangles cover a few pixels each, so a 4x4 block is reached by several
// consecutive triangles, each with a few live lanes of its own call. When the shader reads no
// derivatives (FragmentProgram::shade_mixed) and the state is the one deferred shading needs
// (opaque, depth test less or less-equal with writes), the blocks that consecutive triangles
// cover without sharing a pixel are held and shaded together, each lane with its own triangle's
// planes, depth test and write (ShadeMixedFn).
//
// Why the image is the same bit for bit: every pixel still sees its fragments in submission order
// (a block is shaded before a later triangle covering one of its held pixels is added; different
// blocks are different pixels), and each lane computes what the triangle's own call computes.
#pragma once

#include <cstdint>

#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

class BlockBatch {
 public:
  BlockBatch(const FragmentProgram& program, const ShadeTarget& target)
      : program_(program), target_(target) {}
  ~BlockBatch() { flush(); }  // in case the owner did not: held pixels are never dropped
  BlockBatch(const BlockBatch&) = delete;
  BlockBatch& operator=(const BlockBatch&) = delete;

  // The pixels `mask` of the block at (x, y), covered by the triangle of `in`, held for a call
  // with other triangles' pixels of that block.
  void add(const Interpolants& in, int x, int y, uint32_t mask);
  // The same, shaded now (a larger triangle's block, which has few pixels to share): after the
  // block's held pixels, if any.
  void shade_now(const Interpolants& in, int x, int y, uint32_t mask) {
    Slot& slot = slot_of(x, y);
    if (slot.block.count != 0 && slot.x == x && slot.y == y) shade(slot);
    program_.shade_block(program_.shader, target_, in, x, y, mask);
  }
  // Shades every held block.
  void flush();

 private:
  // Held blocks, one per position of a 4x4 neighbourhood of blocks (a block always goes to the
  // same slot, so it is never held twice).
  struct Slot {
    int x = 0, y = 0;
    uint32_t covered = 0;  // the union of block.mask
    MixedBlock block;      // count 0: empty
  };
  Slot& slot_of(int x, int y) { return slots_[((x >> 2) & 3) | ((y >> 2) & 3) << 2]; }
  void shade(Slot& slot);

  const FragmentProgram& program_;
  const ShadeTarget& target_;
  Slot slots_[16];
};

}  // namespace softrast::detail
