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
// projections; this plane protects arbitrary user matrices from w <= 0. Small enough for a scene
// in tiny units (a camera 1e-9 from a model has w near 1e-9: 1e-6 clipped it all away), large
// enough that 1 / w stays a normal float; setup scales each triangle's 1/w by a power of two so
// that its planes stay in range (setup.cpp).
inline constexpr float kMinClipW = 1.0e-30f;
inline constexpr int kNumClipPlanes = 7;
// Sutherland-Hodgman adds at most one vertex per plane to a convex polygon, but rounding can make
// the polygon slightly non-convex near plane corners, and then a pass can add more: a pass over n
// vertices writes at most floor(3n / 2) (every inside vertex plus one per in/out crossing). Over
// seven passes from 3 vertices: 4, 6, 9, 13, 19, 28, 42.
constexpr int max_clipped_vertices() {
  int n = 3;
  for (int p = 0; p < kNumClipPlanes; ++p) n = n * 3 / 2;
  return n;
}
inline constexpr int kMaxClippedVertices = max_clipped_vertices();
static_assert(kMaxClippedVertices == 42);

// Bit p is set when the position is outside plane p. NaN or Inf positions are outside all planes.
uint32_t clip_outcode(const float* position, const ClipVolume& volume);
bool is_finite_position(const float* position);

// Clips a triangle to the volume. Writes the polygon (a convex fan, in the input winding) to
// `out` and returns its vertex count: 0 (all clipped) or 3..kMaxClippedVertices.
// A new vertex depends only on the (inside, outside) pair of endpoints, never on the direction a
// triangle walks the edge, so two triangles sharing an edge get bit-identical new vertices.
int clip_triangle(const ClipVertex* const in[3], int num_floats, const ClipVolume& volume,
                  ClipVertex out[kMaxClippedVertices]);

// Clips a segment to the volume; false when nothing is left. Same interpolation rule.
bool clip_line(const ClipVertex& a, const ClipVertex& b, int num_floats, const ClipVolume& volume,
               ClipVertex& out_a, ClipVertex& out_b);

}  // namespace softrast::detail
