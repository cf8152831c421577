// raster/scanline_raster.cpp: the edge-walking rasterizer. The triangle is split at its middle
// vertex into a flat-bottomed and a flat-topped trapezoid; each is walked one scanline at a time
// along its left edge (a > 0) and right edge (a < 0), computing the exact first and last
// covered sample of the row with integer division. Rows are gathered four at a time into 4x4
// block masks. It shares only the edge functions with the edge-equation rasterizer, so the two
// agreeing pixel for pixel is a real check of both.
#include <algorithm>
#include <climits>

#include "raster/raster.hpp"

namespace softrast::detail {
namespace {

// An edge being walked down the rows: r = b * y + c at the current row's sample y.
struct WalkedEdge {
  const EdgeFunction* e;
  int64_t r;

  void start(int row) { r = e->b * sample_fx8(row) + e->c; }
  void step() { r += e->b * kSubpixelOne; }
  // Narrows [lo, hi) to the pixels whose sample passes a * (256 i + 128) + r >= 0, that is
  // 256 a i >= -(r + 128 a).
  void clip_span(int64_t& lo, int64_t& hi) const {
    int64_t rhs = -(r + e->a * kSubpixelHalf);
    int64_t step = e->a * kSubpixelOne;
    if (step > 0) {
      lo = std::max(lo, ceil_div(rhs, step));
    } else if (step < 0) {
      hi = std::min(hi, floor_div(-rhs, -step) + 1);
    } else if (rhs > 0) {
      hi = lo;  // a horizontal edge this row lies outside of
    }
  }
};

// Collects the spans of four consecutive rows and emits the non-empty 4x4 blocks they touch.
class BandWriter {
 public:
  BandWriter(const BlockSink& sink) : sink_(sink) {}

  void add_span(int row, int64_t lo, int64_t hi) {
    int band = int(floor_div(row, kBlockSize)) * kBlockSize;
    if (band != band_y_) flush(), band_y_ = band;
    int r = row - band_y_;
    lo_[r] = int(lo);
    hi_[r] = int(hi);
  }

  void flush() {
    if (band_y_ == INT_MIN) return;
    int lo = INT_MAX, hi = INT_MIN;
    for (int r = 0; r < 4; ++r) {
      if (lo_[r] < hi_[r]) lo = std::min(lo, lo_[r]), hi = std::max(hi, hi_[r]);
    }
    for (int x = int(floor_div(lo, kBlockSize)) * kBlockSize; x < hi; x += kBlockSize) {
      uint32_t mask = 0;
      for (int r = 0; r < 4; ++r) {
        int c0 = std::clamp(lo_[r] - x, 0, 4), c1 = std::clamp(hi_[r] - x, 0, 4);
        if (c0 < c1) mask |= block_rect_mask(c0, c1, r, r + 1);
      }
      if (mask) sink_(x, band_y_, mask);
    }
    for (int r = 0; r < 4; ++r) lo_[r] = hi_[r] = 0;
    band_y_ = INT_MIN;
  }

 private:
  const BlockSink& sink_;
  int band_y_ = INT_MIN;
  int lo_[4] = {0, 0, 0, 0};
  int hi_[4] = {0, 0, 0, 0};
};

// Walks rows [row0, row1) between two edges.
void walk_trapezoid(const EdgeFunction& e0, const EdgeFunction& e1, int row0, int row1,
                    const PixelRect& area, BandWriter& out) {
  if (row0 >= row1) return;
  WalkedEdge left{&e0, 0}, right{&e1, 0};
  left.start(row0);
  right.start(row0);
  for (int row = row0; row < row1; ++row, left.step(), right.step()) {
    int64_t lo = area.x0, hi = area.x1;
    left.clip_span(lo, hi);
    right.clip_span(lo, hi);
    if (lo < hi) out.add_span(row, lo, hi);
  }
}

// First row whose sample y is >= y_fx8 (clamped to the area).
int first_row_at_or_below(int64_t y_fx8) {
  return int(ceil_div(y_fx8 - kSubpixelHalf, kSubpixelOne));
}

}  // namespace

void rasterize_triangle_scanline(const TriangleCoverage& tri, const PixelRect& region,
                                 const BlockSink& sink) {
  PixelRect area = intersect(tri.bounds, region);
  if (area.empty()) return;
  // Sort the vertices by y: top, middle, bottom.
  int idx[3] = {0, 1, 2};
  std::sort(idx, idx + 3, [&](int a, int b) { return tri.vy[a] < tri.vy[b]; });
  int top = idx[0], mid = idx[1], bottom = idx[2];
  // Edge k joins vertices k and k+1; the edge opposite vertex v is edge (v + 1) % 3.
  auto opposite = [](int v) { return (v + 1) % 3; };
  auto others = [&](int v, const EdgeFunction*& p, const EdgeFunction*& q) {
    p = &tri.edge[(opposite(v) + 1) % 3];
    q = &tri.edge[(opposite(v) + 2) % 3];
  };

  // Rows with a sample in [y_top, y_mid) belong to the upper trapezoid, [y_mid, y_bottom) to the
  // lower one. Within a trapezoid the third edge is strictly positive, so two edges decide.
  // Samples exactly at y_bottom can only touch the bottom vertex or a bottom edge, which the fill
  // rule excludes. On a sample row through the middle vertex the third edge adds nothing either:
  // the middle vertex joins two edges of the same side (both left, both included on the line,
  // or both right, both excluded), and a horizontal third edge there is a top edge (included).
  int row_top = std::max(first_row_at_or_below(tri.vy[top]), area.y0);
  int row_mid = std::clamp(first_row_at_or_below(tri.vy[mid]), row_top, area.y1);
  int row_bottom = std::clamp(first_row_at_or_below(tri.vy[bottom]), row_mid, area.y1);

  BandWriter out(sink);
  const EdgeFunction *p, *q;
  others(top, p, q);
  walk_trapezoid(*p, *q, row_top, row_mid, area, out);
  others(bottom, p, q);
  walk_trapezoid(*p, *q, row_mid, row_bottom, area, out);
  out.flush();
}

}  // namespace softrast::detail
