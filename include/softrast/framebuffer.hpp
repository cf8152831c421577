// softrast/framebuffer.hpp: the render target: RGBA8 colour and float32 depth.
// Row 0 is the top row (window y grows downwards), the same as Image.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

#include <glm/vec4.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "softrast/image.hpp"
#include "softrast/status.hpp"

namespace softrast {

// Storage is tiled, as the rasterizer walks it: the image is cut into 64x64-pixel tiles (the
// binning tiles), each tile into 16x16 blocks of 4x4 pixels, and a block's 16 pixels are stored
// together (pixel (x, y) of the block is element 4 * y + x), so a block's colour is one 64-byte
// line and its depth another, and a tile's 32 KiB are contiguous. The storage is padded to whole
// tiles; padding pixels are never drawn. Read pixels with color_at / depth_at or copy the image
// out with to_image / depth_values.
//
// Clears are lazy: clear() records the values and marks every tile; a tile is filled when it is
// first written (a draw fills it just before it draws into it, while the tile is in cache) or
// read, so a frame's clear costs no pass over memory of its own.
class Framebuffer {
 public:
  static constexpr int kTileSize = 64;  // pixels per tile side
  static constexpr int kBlockSize = 4;  // pixels per block side

  // Precondition: 1 <= width, height <= kMaxImageSize (see create() for checked construction).
  // Starts cleared to the defaults of clear().
  Framebuffer(int width, int height);
  // Checked construction: an error for sizes outside [1, kMaxImageSize].
  static Result<Framebuffer> create(int width, int height);
  Framebuffer(const Framebuffer& other);
  Framebuffer& operator=(const Framebuffer& other);
  Framebuffer(Framebuffer&&) noexcept = default;
  Framebuffer& operator=(Framebuffer&&) noexcept = default;

  int width() const { return width_; }
  int height() const { return height_; }

  // Clears colour (floats clamped to [0, 1]) and depth; the defaults are CONVENTIONS.md's.
  // clear_color and clear_depth write every pixel at once.
  void clear_color(glm::vec4 color = {0.1f, 0.1f, 0.1f, 1.0f});
  void clear_depth(float depth = 1.0f);
  // Both, lazily (see above): the frame clear.
  void clear(glm::vec4 color = {0.1f, 0.1f, 0.1f, 1.0f}, float depth = 1.0f);
  // The same; `threads` is kept for source compatibility (the tiles are filled by the draws).
  void clear(glm::vec4 color, float depth, int /*threads*/) { clear(color, depth); }

  // Packed RGBA8 pixel: byte 0 is red (little-endian uint32 = 0xAABBGGRR).
  // Precondition for the pixel accessors: 0 <= x < width, 0 <= y < height.
  uint32_t color_at(int x, int y) const {
    return pending(tile_of(x, y)) ? pending_color_ : color_[index(x, y)];
  }
  float depth_at(int x, int y) const {
    return pending(tile_of(x, y)) ? pending_depth_ : depth_[index(x, y)];
  }
  void set_color(int x, int y, uint32_t rgba) {
    prepare(tile_of(x, y));
    color_[index(x, y)] = rgba;
  }
  void set_depth(int x, int y, float depth) {
    prepare(tile_of(x, y));
    depth_[index(x, y)] = depth;
  }

  // For the pipeline: direct access to the storage of a tile that has no clear pending (after
  // prepare_tile or write_pending_clears). Pixel (x, y), and the 16 pixels of the 4x4 block
  // whose top-left pixel is (x, y) (multiples of 4), 64-byte aligned, pixel (x + i, y + j) at
  // element 4 * j + i. Blocks cut by the image's right or bottom edge exist whole (the padding).
  uint32_t* color_pixel(int x, int y) { return &color_[index(x, y)]; }
  float* depth_pixel(int x, int y) { return &depth_[index(x, y)]; }
  uint32_t* color_block(int x, int y) { return &color_[index(x, y)]; }
  float* depth_block(int x, int y) { return &depth_[index(x, y)]; }
  // Fills tile (tx, ty) (tile units) with the pending clear, if it has one. Distinct tiles may be
  // prepared on different threads at once.
  void prepare_tile(int tx, int ty) { prepare(size_t(ty) * size_t(tiles_x_) + size_t(tx)); }
  // Whether tile (tx, ty) still has a clear pending (color_at and depth_at then give the clear).
  bool tile_pending(int tx, int ty) const {
    return pending(size_t(ty) * size_t(tiles_x_) + size_t(tx));
  }
  // Fills every tile that still has a clear pending, on `threads` threads (0: every core).
  void write_pending_clears(int threads);

  // Where pixel (x, y) is stored (elements from the first).
  size_t index(int x, int y) const {
    size_t tile = size_t(y >> 6) * size_t(tiles_x_) + size_t(x >> 6);
    size_t block = size_t(((y >> 2) & 15) * 16 + ((x >> 2) & 15));
    return tile * 4096 + block * 16 + size_t((y & 3) * 4 + (x & 3));
  }

  Image to_image() const;
  // The colour as RGBA8 rows, top row first, `pitch` bytes apart (for a window's texture).
  void copy_rgba8(uint8_t* out, size_t pitch) const;
  // The depth of every pixel, row by row, top row first.
  std::vector<float> depth_values() const;

  // Colour and depth per sample for multisampled draws (RenderState::samples > 1), `count`
  // samples per pixel, each pixel's together (the order is below). Kept between
  // multisampled draws with the same count, so that triangles of different draws sharing an edge
  // blend per sample; every draw leaves the pixels resolved (colour the rounded average of the
  // samples, depth their minimum). `valid` is false until a multisampled draw fills the samples
  // from the pixels; clear_color, clear_depth and single-sampled draws reset it, and
  // clear(colour, depth, threads) clears the samples with the pixels. Code that writes pixels
  // directly after a multisampled draw sets it to false too.
  // The samples are stored tile by tile (64x64 pixels, each pixel's samples together), and a
  // tile's are filled from its pixels when a draw first touches it (`stale`, one flag per tile).
  struct Multisample {
    int count = 0;
    bool valid = false;
    std::vector<uint32_t> color;
    std::vector<float> depth;
    std::vector<uint8_t> stale;
  };
  Multisample& multisample() { return multisample_; }
  const Multisample& multisample() const { return multisample_; }

 private:
  template <class T>
  struct AlignedDelete {
    void operator()(T* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  template <class T>
  using Buffer = std::unique_ptr<T[], AlignedDelete<T>>;
  template <class T>
  static Buffer<T> allocate(size_t n) {
    return Buffer<T>(static_cast<T*>(::operator new[](n * sizeof(T), std::align_val_t(64))));
  }

  size_t tile_of(int x, int y) const { return size_t(y >> 6) * size_t(tiles_x_) + size_t(x >> 6); }
  bool pending(size_t tile) const { return any_pending_ && pending_[tile] != 0; }
  void prepare(size_t tile) {
    if (pending(tile)) fill_tile(tile);
  }
  void fill_tile(size_t tile);

  int width_;
  int height_;
  int tiles_x_;
  size_t size_;  // pixels stored, with the padding
  Buffer<uint32_t> color_;
  Buffer<float> depth_;
  // The lazy clear: the values, and per tile whether it still has to be filled with them.
  std::vector<uint8_t> pending_;
  bool any_pending_ = false;
  uint32_t pending_color_ = 0;
  float pending_depth_ = 1.0f;
  Multisample multisample_;
};

// Float colour to RGBA8 by the conventions: clamp to [0, 1], then x * 255 + 0.5 truncated.
inline uint8_t to_unorm8(float x) {
  // max(0, NaN) is 0 (the comparison is false), so NaN maps to 0; no branches.
  float clamped = std::min(1.0f, std::max(0.0f, x));
  return static_cast<uint8_t>(clamped * 255.0f + 0.5f);
}
inline uint32_t pack_rgba8(glm::vec4 c) {
#if defined(__SSE2__)  // every x86-64 has SSE2: the four channels at once, same results
  __m128 v = _mm_setr_ps(c.r, c.g, c.b, c.a);
  v = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(1.0f));  // max(NaN, 0) is 0
  __m128i i = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(v, _mm_set1_ps(255.0f)), _mm_set1_ps(0.5f)));
  i = _mm_packs_epi32(i, i);
  return uint32_t(_mm_cvtsi128_si32(_mm_packus_epi16(i, i)));
#else
  return uint32_t(to_unorm8(c.r)) | uint32_t(to_unorm8(c.g)) << 8 | uint32_t(to_unorm8(c.b)) << 16 |
         uint32_t(to_unorm8(c.a)) << 24;
#endif
}
inline glm::vec4 unpack_rgba8(uint32_t p) {
  constexpr float k = 1.0f / 255.0f;
  return {float(p & 0xff) * k, float((p >> 8) & 0xff) * k, float((p >> 16) & 0xff) * k,
          float(p >> 24) * k};
}

}  // namespace softrast
