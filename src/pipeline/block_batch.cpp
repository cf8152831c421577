// pipeline/block_batch.cpp: see block_batch.hpp.
#include "pipeline/block_batch.hpp"

namespace softrast::detail {

void BlockBatch::add(const Interpolants& in, int x, int y, uint32_t mask) {
  const int index = slot_index(x, y);
  if (mask == 0xffffu && !holds(index)) {  // a whole block, nothing held where it goes
    program_->shade_block(program_->shader, *target_, in, x, y, mask);
    return;
  }
  add_to_slot(in, x, y, mask, index);
}

inline void BlockBatch::start(Slot& slot, const Interpolants& in, int x, int y, uint32_t mask,
                              int index) {
  slot.x = x;
  slot.y = y;
  slot.covered = mask;
  slot.block.front_facing = in.front_facing;
  slot.block.winner[0] = &in;
  slot.block.mask[0] = mask;
  slot.block.count = 1;
  held_[index >> 6] |= uint64_t(1) << (index & 63);
}

// The two usual cases need no call, so they save no registers: a block the slot already holds
// gains pixels that leave it incomplete, or an empty slot takes a block. The rest (a call to the
// fragment stage) goes on in add_with_shading.
void BlockBatch::add_to_slot(const Interpolants& in, int x, int y, uint32_t mask, int index) {
  Slot& slot = slots_[index];
  MixedBlock& held = slot.block;
  if (!holds(index)) {
    if (mask != 0xffffu) {
      start(slot, in, x, y, mask, index);
      return;
    }
  } else if (slot.x == x && slot.y == y && (slot.covered & mask) == 0 &&
             held.front_facing == in.front_facing && (slot.covered | mask) != 0xffffu) {
    // (A whole block never joins: the slot holds pixels.)
    held.winner[held.count] = &in;
    held.mask[held.count++] = mask;  // at most 15 here: the masks are disjoint and not empty
    slot.covered |= mask;
    return;
  }
  add_with_shading(in, x, y, mask, index);
}

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
    held.winner[held.count] = &in;  // it completes the block: nothing more can join
    held.mask[held.count++] = mask;
    slot.covered |= mask;
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
