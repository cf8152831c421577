// core/unit_scale.hpp: the power of two that brings a magnitude near 1.
#pragma once

#include <cmath>

namespace softrast::detail {

// The power of two that brings `largest` (finite, > 0) to [0.5, 1). Multiplying by it is exact
// (barring overflow and denormals), so values so scaled keep every bit of their ratios: the
// setup's 1/w, and the shaders' and shadow map's units for scenes of units of 1e30 or 1e-30.
template <class T>
T unit_scale(T largest) {
  int exponent = 0;
  std::frexp(largest, &exponent);
  return std::ldexp(T(1), -exponent);
}

}  // namespace softrast::detail
