// pipeline/block_batch.cpp: see block_batch.hpp.
#include "pipeline/block_batch.hpp"

namespace softrast::detail {

void BlockBatch::add_with_shading(const Interpolants& in, int x, int y, uint32_t mask, int index) {
  Slot& slot = slots_[index];
  MixedBlock& held = slot.block;
  bool same_block = holds(index) && slot.x == x && slot.y == y;
  if (mask == 0xffffu) {  // a whole block: nothing to share it with
    if (same_block) shade(index);
    program_->shade_block(program_->shader, *target_, in, x, y, mask);
    return;
  }
  if (same_block && (slot.covered & mask) == 0 && held.front_facing == in.front_facing) {
    join(slot, in, mask);  // it completes the block: nothing more can join
    shade(index);
    return;
  }
  if (holds(index)) shade(index);
  start(slot, in, x, y, mask, index);
}

void BlockBatch::flush() {
  for (int word = 0; word < kSide * kSide / 64; ++word) {
    while (held_[word] != 0) shade(word * 64 + __builtin_ctzll(held_[word]));
  }
}

void BlockBatch::shade(int index) {
  Slot& slot = slots_[index];
  const MixedBlock& held = slot.block;
  if (held.count == 1) {
    program_->shade_block(program_->shader, *target_, *held.winner[0], slot.x, slot.y,
                          held.mask[0]);
  } else {
    program_->shade_mixed(program_->shader, *target_, held, slot.x, slot.y);
  }
  slot.block.count = 0;
  held_[index >> 6] &= ~(uint64_t(1) << (index & 63));
}

}  // namespace softrast::detail
