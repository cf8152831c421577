// raster/line_raster.cpp: diamond-exit (Bresenham-equivalent) lines in exact integer arithmetic.
// A pixel is drawn when the segment leaves its diamond |x - cx| + |y - cy| < 1/2. For an
// x-major segment that is one pixel per column whose centre line the segment crosses (the row
// containing the segment's y there; a y exactly on a row boundary goes to the row below), plus
// the corrections at both ends in walk(). The end pixel's diamond, if the end lies in it, is not
// left, so connected segments (wireframe edges) do not double-hit their shared vertex.
#include <algorithm>
#include <cstdlib>
#include <utility>

#include "raster/raster.hpp"

namespace softrast::detail {
namespace {

// Gathers single pixels into 4x4 block masks; consecutive pixels of a line mostly share blocks.
class PixelBlocks {
 public:
  explicit PixelBlocks(const BlockSink& sink) : sink_(sink) {}
  ~PixelBlocks() { flush(); }
  void add(int x, int y) {
    int bx = int(floor_div(x, kBlockSize)) * kBlockSize,
        by = int(floor_div(y, kBlockSize)) * kBlockSize;
    if (mask_ && (bx != bx_ || by != by_)) flush();
    bx_ = bx;
    by_ = by;
    mask_ |= 1u << (4 * (y - by) + (x - bx));
  }
  void flush() {
    if (mask_) sink_(bx_, by_, mask_);
    mask_ = 0;
  }

 private:
  const BlockSink& sink_;
  int bx_ = 0, by_ = 0;
  uint32_t mask_ = 0;
};

// Endpoints are perturbed as OpenGL's diamond-exit rule prescribes, by (+e, +e^2) in GL's y-up
// window coordinates, which is (+e, -e^2) here (y down), e vanishingly small: every tie between
// pixels is decided by which side the perturbed point or segment lies on. All tests below are
// exact integer arithmetic on 1/256-pixel coordinates.

// The pixel that contains the perturbed point (x + e, y - e^2).
int64_t pixel_x(int64_t x) {
  return floor_div(x, kSubpixelOne);
}
int64_t pixel_y(int64_t y) {
  return floor_div(y - 1, kSubpixelOne);
}  // y - e^2: boundary goes up

// Whether the perturbed point lies inside the diamond |x - cx| + |y - cy| < 1/2 of pixel
// (px, py). On the diamond's boundary the +e in x decides: inside iff x < cx.
bool in_diamond(int64_t x, int64_t y, int64_t px, int64_t py) {
  int64_t dx = x - sample_fx8(int(px)), dy = y - sample_fx8(int(py));
  int64_t d = std::llabs(dx) + std::llabs(dy);
  return d < kSubpixelHalf || (d == kSubpixelHalf && dx < 0);
}

// One segment by the diamond-exit rule: the pixels whose diamonds it meets, except the one its
// end lies in. A segment with |slope| <= 1 meets a diamond exactly when it crosses the diamond's
// centre line x = cx (or it starts inside past that line), so: the columns whose centre the
// perturbed segment crosses, each with the row containing the segment there, plus the start's
// diamond when the start lies inside one past its centre line, minus the end's diamond when the
// end lies inside one. y-major segments are the same with the axes swapped.
template <class Plot>
void diamond_exit(int64_t x0, int64_t y0, int64_t x1, int64_t y1, Plot plot) {
  bool x_major = std::llabs(x1 - x0) >= std::llabs(y1 - y0);
  int64_t u0 = x_major ? x0 : y0, u1 = x_major ? x1 : y1;  // major axis
  int64_t v0 = x_major ? y0 : x0, v1 = x_major ? y1 : x1;  // minor axis
  // Centres C crossed: the perturbation moves x by +e, so x-major crosses (min, max]; it moves
  // y by -e^2, so y-major crosses [min, max).
  int64_t lo = std::min(u0, u1), hi = std::max(u0, u1);
  auto crossed = [&](int64_t c) { return x_major ? (lo < c && c <= hi) : (lo <= c && c < hi); };
  // The minor-axis pixel at centre C, exactly; on a boundary the perturbed segment decides: for
  // x-major it lies above the boundary when the slope dy/dx >= 0 (y - slope e - e^2), else
  // below; for y-major it always lies right of it (x + e).
  int64_t du = u1 - u0, dv = v1 - v0;
  bool tie_low = x_major && (dv == 0 || (dv > 0) == (du > 0));
  auto minor_at = [&](int64_t c) {
    int64_t num = v0 * du + (c - u0) * dv, den = du * kSubpixelOne;
    if (den < 0) num = -num, den = -den;
    int64_t m = floor_div(num, den);
    if (tie_low && m * den == num) --m;
    return m;
  };
  auto emit = [&](int64_t u, int64_t v) { x_major ? plot(u, v) : plot(v, u); };

  int64_t sx = pixel_x(x0), sy = pixel_y(y0), ex = pixel_x(x1), ey = pixel_y(y1);
  bool start_in = in_diamond(x0, y0, sx, sy), end_in = in_diamond(x1, y1, ex, ey);
  bool same = start_in && end_in && sx == ex && sy == ey;
  int64_t s_major = x_major ? sx : sy, e_major = x_major ? ex : ey;
  int64_t s_minor = x_major ? sy : sx;
  if (start_in && !same && !crossed(sample_fx8(int(s_major)))) emit(s_major, s_minor);

  int dir = u1 > u0 ? 1 : -1;
  int64_t first = dir > 0 ? floor_div(lo - kSubpixelHalf, kSubpixelOne)
                          : ceil_div(hi - kSubpixelHalf, kSubpixelOne);
  for (int64_t i = first;; i += dir) {
    int64_t c = sample_fx8(int(i));
    if (dir > 0 ? c > hi : c < lo) break;
    if (!crossed(c) || (end_in && i == e_major)) continue;
    emit(i, minor_at(c));
  }
}

}  // namespace

void rasterize_line(const LineSetup& line, const PixelRect& region, const BlockSink& sink) {
  PixelRect area = intersect(line.bounds, region);
  if (area.empty()) return;
  PixelBlocks blocks(sink);
  auto plot_xy = [&](int64_t x, int64_t y) {
    if (x >= area.x0 && x < area.x1 && y >= area.y0 && y < area.y1) blocks.add(int(x), int(y));
  };
  diamond_exit(line.x0, line.y0, line.x1, line.y1, plot_xy);
}

}  // namespace softrast::detail
