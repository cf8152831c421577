// pipeline/tile_visibility.cpp: the tile's depth and id scratch and the shading of winners (the
// resolve kernels are in tile_kernel.inl).
#include "pipeline/tile_visibility.hpp"

#include <emmintrin.h>

#include <algorithm>
#include <cstring>

namespace softrast::detail {

TileVisibility::TileVisibility() {
  std::fill(&depth[0][0], &depth[0][0] + kBlocks * 16, 1.0f);
  std::fill(&id[0][0], &id[0][0] + kBlocks * 16, kNoWinner);
  std::fill(touched, touched + kBlocks / 64, 0);
}

void TileVisibility::begin(Framebuffer& fb, const PixelRect& tile_region) {
  framebuffer = &fb;
  region = tile_region;
}

void TileVisibility::load_block(int b) {
  touched[b >> 6] |= uint64_t(1) << (b & 63);
  int x0 = region.x0 + (b % kBlocksPerRow) * kBlockSize;
  int y0 = region.y0 + (b / kBlocksPerRow) * kBlockSize;
  std::memcpy(depth[b], framebuffer->depth_block(x0, y0), sizeof(depth[b]));
}

void TileVisibility::store_depth() const {
  for (int word = 0; word < kBlocks / 64; ++word) {
    for (uint64_t bits = touched[word]; bits != 0; bits &= bits - 1) {
      int b = word * 64 + __builtin_ctzll(bits);
      int x0 = region.x0 + (b % kBlocksPerRow) * kBlockSize;
      int y0 = region.y0 + (b / kBlocksPerRow) * kBlockSize;
      std::memcpy(framebuffer->depth_block(x0, y0), depth[b], sizeof(depth[b]));
    }
  }
}

void TileVisibility::reset() {
  for (int word = 0; word < kBlocks / 64; ++word) {
    for (uint64_t bits = touched[word]; bits != 0; bits &= bits - 1) {
      int b = word * 64 + __builtin_ctzll(bits);
      std::fill(id[b], id[b] + 16, kNoWinner);
    }
    touched[word] = 0;
  }
}

namespace {

// Bit l set where ids[l] == value, for the 16 ids of a block (SSE2, the x86-64 baseline).
uint32_t lanes_equal(const int32_t* ids, int32_t value) {
  __m128i v = _mm_set1_epi32(value);
  uint32_t bits = 0;
  for (int q = 0; q < 4; ++q) {
    __m128i four = _mm_load_si128(reinterpret_cast<const __m128i*>(ids + 4 * q));
    bits |= uint32_t(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(four, v)))) << (4 * q);
  }
  return bits;
}

}  // namespace

void shade_winners(const TileVisibility& vis, const Interpolants* const* interps,
                   const FragmentProgram& program, const ShadeTarget& resolved_target) {
  constexpr int kPerRow = TileVisibility::kBlocksPerRow;
  for (int word = 0; word < TileVisibility::kBlocks / 64; ++word) {
    for (uint64_t bits = vis.touched[word]; bits != 0; bits &= bits - 1) {
      int b = word * 64 + __builtin_ctzll(bits);
      const int32_t* ids = vis.id[b];
      uint32_t left = ~lanes_equal(ids, TileVisibility::kNoWinner) & 0xffffu;
      int x = vis.region.x0 + (b % kPerRow) * kBlockSize;
      int y = vis.region.y0 + (b / kPerRow) * kBlockSize;
      if (program.shade_mixed == nullptr || !program.mixed_winners) {
        // One call per distinct winner of the block, with exactly the pixels it won.
        while (left != 0) {
          int32_t winner = ids[__builtin_ctz(left)];
          uint32_t mask = lanes_equal(ids, winner);
          left &= ~mask;
          program.shade_block(program.shader, resolved_target, *interps[winner], x, y, mask);
        }
        continue;
      }
      // The shader reads no derivatives: one call for all the winners of each facing (the
      // shader sees one facing per call).
      MixedBlock facing[2];  // back, front
      while (left != 0) {
        int32_t winner = ids[__builtin_ctz(left)];
        uint32_t mask = lanes_equal(ids, winner);
        left &= ~mask;
        const Interpolants* in = interps[winner];
        MixedBlock& group = facing[in->front_facing ? 1 : 0];
        group.winner[group.count] = in;
        group.mask[group.count++] = mask;
      }
      for (int side = 0; side < 2; ++side) {
        MixedBlock& group = facing[side];
        if (group.count == 1) {
          program.shade_block(program.shader, resolved_target, *group.winner[0], x, y,
                              group.mask[0]);
        } else if (group.count > 1) {
          group.front_facing = side == 1;
          program.shade_mixed(program.shader, resolved_target, group, x, y);
        }
      }
    }
  }
}

}  // namespace softrast::detail
