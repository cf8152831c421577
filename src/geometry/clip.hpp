// geometry/clip.hpp: clipping in homogeneous clip space, before the perspective divide.
// Near and far planes always, w > 0 always, x and y against the guard band (not the image).
#pragma once

#include <cstdint>

#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// A clip-space vertex with its varyings: position (x, y, z, w) in v[0..3], varyings after it.
struct ClipVertex {
  float v[4 + kMaxVaryings];
};

// The clip volume: -w <= z <= w, w >= kMinClipW, |x| <= guard_x * w, |y| <= guard_y * w.
// guard_x and guard_y are chosen by the viewport so that every point inside lands within
// kGuardBandPixels of the origin after the viewport transform.
struct ClipVolume {
  double guard_x = 1.0;
  double guard_y = 1.0;
};

// Smallest w that reaches the divide. The near plane already keeps w >= near for perspective
// projections; this plane protects arbitrary user matrices from w <= 0.
inline constexpr float kMinClipW = 1.0e-6f;
inline constexpr int kNumClipPlanes = 7;
// Sutherland-Hodgman adds at most one vertex per plane.
inline constexpr int kMaxClippedVertices = 3 + kNumClipPlanes;

// Bit p is set when the position is outside plane p. NaN or Inf positions are outside all planes.
uint32_t clip_outcode(const float* position, const ClipVolume& volume);
bool is_finite_position(const float* position);

// Clips a triangle to the volume. Writes the polygon (a convex fan, in the input winding) to
// `out` and returns its vertex count: 0 (all clipped) or 3..kMaxClippedVertices.
// Every new vertex is interpolated from the inside endpoint towards the outside one, so an edge
// shared by two triangles yields bit-identical new vertices whichever way each triangle walks it.
int clip_triangle(const ClipVertex* const in[3], int num_floats, const ClipVolume& volume,
                  ClipVertex out[kMaxClippedVertices]);

// Clips a segment to the volume; false when nothing is left. Same interpolation rule.
bool clip_line(const ClipVertex& a, const ClipVertex& b, int num_floats, const ClipVolume& volume,
               ClipVertex& out_a, ClipVertex& out_b);

}  // namespace softrast::detail
