// core/store_mode.hpp: how the AVX2 depth resolve writes a group's winners (tile_kernel.inl).
#pragma once

namespace softrast::detail {

// True: by masked stores (VMASKMOVPS, VPMASKMOVD), which leave the other lanes untouched. False:
// by blending into the loaded depth and ids and storing both whole (the block is the tile
// worker's own, so no other thread writes those lanes). Masked stores unless blends are at least
// a fifth faster on this CPU, timed once (AMD's Zen 3 microcodes masked stores: they were half of
// the AVX2 depth resolve's time there). SOFTRAST_MASKED_STORES=1 or 0 forces the choice.
bool avx2_masked_stores();
// Forces it (tests compare both ways).
void set_avx2_masked_stores(bool masked);

}  // namespace softrast::detail
