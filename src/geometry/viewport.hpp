// geometry/viewport.hpp: the perspective divide, the viewport transform and snapping.
// Direct3D-style window space: origin top-left, y down, depth (z/w + 1) / 2 in [0, 1].
#pragma once

#include "geometry/clip.hpp"
#include "raster/setup.hpp"

namespace softrast::detail {

struct Viewport {
  int width = 1;
  int height = 1;

  // The guard band in clip space: |x| <= guard_x * w maps to |x_window| <= kGuardBandPixels.
  ClipVolume clip_volume() const;
  // Divides by w (> 0 after clipping), maps to window coordinates and snaps to 1/256 pixel with
  // round-half-to-even. The vertex (position, then varyings) must be inside clip_volume().
  WindowVertex to_window(const float* clip_vertex) const;
};

}  // namespace softrast::detail
