// pipeline/tile_visibility.cpp: the tile's depth and id scratch, the depth-resolve kernels (one
// source, compiled for SSE2, AVX2 and AVX-512, picked at run time) and the shading of winners.
#include "pipeline/tile_visibility.hpp"

#include <algorithm>
#include <cstring>

#include "softrast/simd.hpp"
#include "softrast/simd_level.hpp"

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
  int cols = std::min(kBlockSize, region.x1 - x0), rows = std::min(kBlockSize, region.y1 - y0);
  for (int r = 0; r < rows; ++r) {
    std::memcpy(&depth[b][4 * r], framebuffer->depth_row(y0 + r) + x0, sizeof(float) * cols);
  }
}

void TileVisibility::store_depth() const {
  for (int word = 0; word < kBlocks / 64; ++word) {
    for (uint64_t bits = touched[word]; bits != 0; bits &= bits - 1) {
      int b = word * 64 + __builtin_ctzll(bits);
      int x0 = region.x0 + (b % kBlocksPerRow) * kBlockSize;
      int y0 = region.y0 + (b / kBlocksPerRow) * kBlockSize;
      int cols = std::min(kBlockSize, region.x1 - x0), rows = std::min(kBlockSize, region.y1 - y0);
      for (int r = 0; r < rows; ++r) {
        std::memcpy(framebuffer->depth_row(y0 + r) + x0, &depth[b][4 * r], sizeof(float) * cols);
      }
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

// The kernel body, written once on the wide types of softrast/simd.hpp (16 lanes, N per native
// vector; lane l = 4 * row + column) and inlined into one wrapper per instruction set. simd.hpp
// routes AVX-512 comparisons and selects through intrinsics: GCC 12 splits the plain vector-
// extension forms into lanes there, which made this kernel 3x slower than its AVX2 twin.
template <int N, bool kLessEqual>
[[gnu::always_inline]] inline void resolve_block_body(const DepthPlaneRef& p, int x, int y,
                                                      uint32_t mask, int32_t id, float* depth,
                                                      int32_t* ids) {
  using F = simd::Float<N>;
  using I = simd::Int<N>;
  // Exactly the fragment stage's depth: dx = float(px) + 0.5 - x_ref, then
  // z = clamp((a0 + dadx * dx) + dady * dy, 0, 1) with std::clamp's NaN and -0 behaviour.
  F dx = (simd::to_float(I(x) + simd::lane_column<N>()) + F(0.5f)) - F(p.x_ref);
  F dy = (simd::to_float(I(y) + simd::lane_row<N>()) + F(0.5f)) - F(p.y_ref);
  F z = (F(p.z.a0) + F(p.z.dadx) * dx) + F(p.z.dady) * dy;
  z = simd::clamp(z, F(0.0f), F(1.0f));
  F stored = F::load(depth);
  I winner = I::load(ids);
  I pass = (kLessEqual ? (z <= stored) : (z < stored)) & simd::lanes_of<N>(mask);
  simd::select(pass, z, stored).store(depth);
  simd::select(pass, I(id), winner).store(ids);
}

#define SOFTRAST_RESOLVE_KERNEL(name, lanes, target_attr)                                     \
  target_attr [[gnu::flatten]] void name(const DepthPlaneRef& p, int x, int y, uint32_t mask, int32_t id,       \
                        bool less_equal, float* depth, int32_t* ids) {                         \
    if (less_equal) {                                                                          \
      resolve_block_body<lanes, true>(p, x, y, mask, id, depth, ids);                          \
    } else {                                                                                   \
      resolve_block_body<lanes, false>(p, x, y, mask, id, depth, ids);                         \
    }                                                                                          \
  }
SOFTRAST_RESOLVE_KERNEL(resolve_block_sse2, 4, )
SOFTRAST_RESOLVE_KERNEL(resolve_block_avx2, 8, __attribute__((target("avx2"))))
SOFTRAST_RESOLVE_KERNEL(resolve_block_avx512, 16,
                        __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl"))))
#undef SOFTRAST_RESOLVE_KERNEL

}  // namespace

ResolveBlockFn resolve_block_kernel() {
  switch (simd_level()) {
    case SimdLevel::kAvx512:
      return &resolve_block_avx512;
    case SimdLevel::kAvx2:
      return &resolve_block_avx2;
    default:
      return &resolve_block_sse2;
  }
}

void shade_winners(const TileVisibility& vis, const Interpolants* const* interps,
                   const FragmentProgram& program, const ShadeTarget& resolved_target) {
  constexpr int kPerRow = TileVisibility::kBlocksPerRow;
  for (int word = 0; word < TileVisibility::kBlocks / 64; ++word) {
    for (uint64_t bits = vis.touched[word]; bits != 0; bits &= bits - 1) {
      int b = word * 64 + __builtin_ctzll(bits);
      const int32_t* ids = vis.id[b];
      uint32_t left = 0;
      for (int l = 0; l < 16; ++l) left |= uint32_t(ids[l] != TileVisibility::kNoWinner) << l;
      int x = vis.region.x0 + (b % kPerRow) * kBlockSize;
      int y = vis.region.y0 + (b / kPerRow) * kBlockSize;
      // One call per distinct winner of the block, with exactly the pixels it won.
      while (left != 0) {
        int32_t winner = ids[__builtin_ctz(left)];
        uint32_t mask = 0;
        for (int l = 0; l < 16; ++l) mask |= uint32_t(ids[l] == winner) << l;
        left &= ~mask;
        program.shade_block(program.shader, resolved_target, *interps[winner], x, y, mask);
      }
    }
  }
}

}  // namespace softrast::detail
