// texture/srgb_encode.hpp: the sRGB encoding of one channel to a byte, as the mip chain of an
// sRGB texture stores it.
#pragma once

#include <cstdint>

namespace softrast {

// uint8_t(linear_to_srgb(c) * 255 + 0.5): the formula (a pow per call) ...
uint8_t linear_to_srgb_byte_exact(float c);
// ... and the same byte, exactly, from a table of the 255 thresholds between bytes (no pow).
uint8_t linear_to_srgb_byte(float c);

}  // namespace softrast
