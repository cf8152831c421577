// pipeline/shade_call.hpp: one block to the fragment stage, by FragmentProgram::shade_half when
// only two of its rows are covered and the caller may use it, else by shade_block.
#pragma once

#include <cstdint>

#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// `half`: program.shade_half where the target is resolved or the state is common_state, else
// null. The same bits either way (shade_block shades such blocks by the same code).
inline void shade_block_call(const FragmentProgram& program, ShadeBlockFn half,
                             const ShadeTarget& target, const Interpolants& in, int x, int y,
                             uint32_t mask) {
  if (half != nullptr && ((mask & 0xffu) == 0 || (mask >> 8) == 0)) {
    const bool upper = (mask & 0xffu) == 0;  // rows 2 and 3
    half(program.shader, target, in, x, upper ? y + 2 : y, upper ? mask >> 8 : mask);
    return;
  }
  program.shade_block(program.shader, target, in, x, y, mask);
}

}  // namespace softrast::detail
