// geometry/viewport.cpp
#include "geometry/viewport.hpp"

#include <algorithm>
#include <cmath>

namespace softrast::detail {
namespace {

// Round half to even (the default floating-point rounding mode), clamped into the fixed-point
// range as a last line of defence against values the clipper let through by rounding.
int32_t snap(double window_coord, float& residual) {
  double scaled = window_coord * kSubpixelOne;
  double fx = std::nearbyint(scaled);
  double limit = double(kMaxCoordFx8 - 1);
  residual = 0.0f;
  if (std::isnan(fx)) return 0;  // unreachable after clipping; never convert NaN to int
  if (std::abs(fx) <= limit) residual = float(scaled - fx);  // exact in double
  return int32_t(std::clamp(fx, -limit, limit));
}

}  // namespace

ClipVolume Viewport::clip_volume() const {
  // x_window = (x_ndc + 1) * width / 2 lies in [width - L, L] when |x_ndc| <= 2 L / width - 1.
  ClipVolume vol;
  vol.guard_x = 2.0 * kGuardBandPixels / width - 1.0;
  vol.guard_y = 2.0 * kGuardBandPixels / height - 1.0;
  return vol;
}

WindowVertex Viewport::to_window(const float* v) const {
  double inv_w = 1.0 / double(v[3]);
  double x_ndc = v[0] * inv_w, y_ndc = v[1] * inv_w, z_ndc = v[2] * inv_w;
  WindowVertex out;
  out.x = snap((x_ndc + 1.0) * 0.5 * width, out.x_residual);
  out.y = snap((1.0 - y_ndc) * 0.5 * height, out.y_residual);  // y_ndc = +1 is the top row
  out.z = float(std::clamp((z_ndc + 1.0) * 0.5, 0.0, 1.0));
  out.inv_w = float(inv_w);
  out.varyings = v + 4;
  return out;
}

}  // namespace softrast::detail
