// pipeline/block_batch.cpp: see block_batch.hpp.
#include "pipeline/block_batch.hpp"

namespace softrast::detail {

void BlockBatch::add(const Interpolants& in, int x, int y, uint32_t mask) {
  Slot& slot = slot_of(x, y);
  MixedBlock& held = slot.block;
  bool same_block = held.count != 0 && slot.x == x && slot.y == y;
  if (mask == 0xffffu) {  // a whole block: nothing to share it with
    if (same_block) shade(slot);
    program_->shade_block(program_->shader, *target_, in, x, y, mask);
    return;
  }
  if (same_block && (slot.covered & mask) == 0 && held.front_facing == in.front_facing) {
    held.winner[held.count] = &in;
    held.mask[held.count++] = mask;  // at most 16: the masks are disjoint and not empty
    slot.covered |= mask;
    if (slot.covered == 0xffffu) shade(slot);  // complete: nothing more can join
    return;
  }
  if (held.count != 0) shade(slot);
  slot.x = x;
  slot.y = y;
  slot.covered = mask;
  held.front_facing = in.front_facing;
  held.winner[0] = &in;
  held.mask[0] = mask;
  held.count = 1;
}

void BlockBatch::flush() {
  for (Slot& slot : slots_) {
    if (slot.block.count != 0) shade(slot);
  }
}

void BlockBatch::shade(Slot& slot) {
  const MixedBlock& held = slot.block;
  if (held.count == 1) {
    program_->shade_block(program_->shader, *target_, *held.winner[0], slot.x, slot.y,
                          held.mask[0]);
  } else {
    program_->shade_mixed(program_->shader, *target_, held, slot.x, slot.y);
  }
  slot.block.count = 0;
}

}  // namespace softrast::detail
