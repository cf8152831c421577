// tests/fill_rule_oracle.hpp: the top-left fill rule written out from CONVENTIONS.md alone, by
// brute force, independently of raster/setup.cpp: the oracle of the rasterization tests and of
// the geometry fuzz target (fuzz/geometry_fuzz.cpp). No GoogleTest here.
#pragma once

#include <array>
#include <cstdint>

namespace softrast::test {

// The fill rule, written from CONVENTIONS.md and nothing else. Coordinates are in 1/256 pixel,
// y down. A sample strictly inside all three edges is covered; a sample exactly on an edge is
// covered only if that edge is a top edge (horizontal, the triangle below it) or a left edge (the
// triangle to its right); at a vertex both edges must qualify. Degenerate triangles cover nothing.

struct Fx8Triangle {
  std::array<int64_t, 3> x{};
  std::array<int64_t, 3> y{};
};

// cross(b - a, p - a) for points given by coordinates.
inline int64_t cross_fx(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// Whether the edge from vertex i to vertex j is a top or left edge, judged by where the third
// vertex k lies: below a horizontal edge, or right of a non-horizontal one at k's height.
inline bool rule_is_top_or_left(const Fx8Triangle& t, int i, int j, int k) {
  int64_t dy = t.y[j] - t.y[i];
  if (dy == 0) return t.y[k] > t.y[i];
  // x_k - x_line(y_k) = ((x_k - x_i) dy - (y_k - y_i) dx) / dy
  int64_t num = (t.x[k] - t.x[i]) * dy - (t.y[k] - t.y[i]) * (t.x[j] - t.x[i]);
  return dy > 0 ? num > 0 : num < 0;
}

inline bool rule_covers(const Fx8Triangle& t, int64_t sx, int64_t sy) {
  for (int i = 0; i < 3; ++i) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    int64_t side_k = cross_fx(t.x[i], t.y[i], t.x[j], t.y[j], t.x[k], t.y[k]);
    if (side_k == 0) return false;  // degenerate
    int64_t side_s = cross_fx(t.x[i], t.y[i], t.x[j], t.y[j], sx, sy);
    if (side_s == 0) {
      if (!rule_is_top_or_left(t, i, j, k)) return false;
    } else if ((side_s > 0) != (side_k > 0)) {
      return false;
    }
  }
  return true;
}

// Whether the sample of pixel (px, py) is covered.
inline bool rule_covers_pixel(const Fx8Triangle& t, int px, int py) {
  return rule_covers(t, int64_t(px) * 256 + 128, int64_t(py) * 256 + 128);
}

// The covered pixels of [x0, x1) x [y0, y1), an area inside the 8x8 pixels from (x0 & ~3, y0 &
// ~3), as the masks of those pixels' four 4x4 blocks: 16 bits each (bit 4 row + column), top
// left, top right, bottom left, bottom right, from the low bits up.
inline uint64_t rule_block_masks(const Fx8Triangle& t, int x0, int y0, int x1, int y1) {
  const int bx = x0 & ~3, by = y0 & ~3;
  uint64_t masks = 0;
  for (int py = y0; py < y1; ++py) {
    for (int px = x0; px < x1; ++px) {
      if (!rule_covers_pixel(t, px, py)) continue;
      const int block = (py - by) / 4 * 2 + (px - bx) / 4, bit = (py - by) % 4 * 4 + (px - bx) % 4;
      masks |= uint64_t(1) << (16 * block + bit);
    }
  }
  return masks;
}

}  // namespace softrast::test
