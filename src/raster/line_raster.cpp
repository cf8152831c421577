// raster/line_raster.cpp: Bresenham-equivalent lines in exact integer arithmetic. For an x-major
// segment, every pixel column whose centre x lies in [start, end) gets the one pixel whose row
// contains the segment's y at that centre (a y exactly on a row boundary goes to the row below).
// This is the diamond-exit choice for all but the endpoints' corner cases; the end pixel is
// never drawn, so connected segments (line strips, wireframe edges) do not double-hit a pixel.
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

// Walks the major axis. (u, v) are the major and minor coordinates of the two endpoints.
template <class Plot>
void walk(int64_t u0, int64_t v0, int64_t u1, int64_t v1, Plot plot) {
  int64_t du = u1 - u0, dv = v1 - v0;
  int dir = du > 0 ? 1 : -1;
  // Pixels whose centre 256 i + 128 lies in [u0, u1) (or (u1, u0] going backwards).
  int64_t first = dir > 0 ? ceil_div(u0 - kSubpixelHalf, kSubpixelOne)
                          : floor_div(u0 - kSubpixelHalf, kSubpixelOne);
  int64_t last = dir > 0 ? ceil_div(u1 - kSubpixelHalf, kSubpixelOne) - 1
                         : floor_div(u1 - kSubpixelHalf, kSubpixelOne) + 1;
  if (dir < 0) du = -du, dv = -dv;  // keep the denominator positive
  for (int64_t i = first; dir > 0 ? i <= last : i >= last; i += dir) {
    // v at the centre: v0 + (U - u0) * dv / du, as a row index floor(v / 256).
    int64_t num = v0 * du + (sample_fx8(int(i)) - u0) * dv;
    plot(i, floor_div(num, du * kSubpixelOne));
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
  int64_t dx = int64_t(line.x1) - line.x0, dy = int64_t(line.y1) - line.y0;
  if (std::llabs(dx) >= std::llabs(dy)) {
    walk(line.x0, line.y0, line.x1, line.y1, plot_xy);
  } else {
    walk(line.y0, line.x0, line.y1, line.x1, [&](int64_t y, int64_t x) { plot_xy(x, y); });
  }
}

}  // namespace softrast::detail
