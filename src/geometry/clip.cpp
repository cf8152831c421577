// geometry/clip.cpp: Sutherland-Hodgman against the seven planes of the clip volume.
#include "geometry/clip.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace softrast::detail {
namespace {

// Signed distance-like value of a position to plane p: >= 0 inside. Computed in double so that
// huge coordinates (1e30) neither overflow nor lose the sign.
double plane_distance(int plane, const float* p, const ClipVolume& vol) {
  double x = p[0], y = p[1], z = p[2], w = p[3];
  switch (plane) {
    case 0:
      return w - double(kMinClipW);
    case 1:
      return z + w;  // near
    case 2:
      return w - z;  // far
    case 3:
      return x + vol.guard_x * w;
    case 4:
      return vol.guard_x * w - x;
    case 5:
      return y + vol.guard_y * w;
    default:
      return vol.guard_y * w - y;
  }
}

// The point where the segment from `in` (inside) to `out` (outside) crosses plane p.
// Interpolating from the nearer endpoint keeps the error proportional to the part of the segment
// that is interpolated over; with endpoints at 1e30 and the crossing near the origin, starting
// from the far one would leave an error of 1e14. The coordinate the plane constrains is then set
// exactly onto the plane, so the next passes see the vertex inside it and never with w <= 0.
void intersect(int plane, const ClipVertex& in, const ClipVertex& out, double d_in, double d_out,
               int num_floats, const ClipVolume& vol, ClipVertex& result) {
  double t = d_in / (d_in - d_out);  // from `in`, in [0, 1]
  const ClipVertex& from = t <= 0.5 ? in : out;
  const ClipVertex& to = t <= 0.5 ? out : in;
  double s = t <= 0.5 ? t : d_out / (d_out - d_in);
  for (int i = 0; i < num_floats; ++i) {
    double a = from.v[i], b = to.v[i];
    result.v[i] = float(a + s * (b - a));
  }
  float* p = result.v;
  switch (plane) {
    case 0:
      p[3] = kMinClipW;
      break;
    case 1:
      p[2] = -p[3];
      break;
    case 2:
      p[2] = p[3];
      break;
    case 3:
      p[0] = float(-vol.guard_x * p[3]);
      break;
    case 4:
      p[0] = float(vol.guard_x * p[3]);
      break;
    case 5:
      p[1] = float(-vol.guard_y * p[3]);
      break;
    default:
      p[1] = float(vol.guard_y * p[3]);
      break;
  }
}

// One Sutherland-Hodgman pass: keeps the part of polygon `src` inside plane p.
int clip_polygon_against(int plane, const ClipVertex* src, int n, int num_floats,
                         const ClipVolume& vol, ClipVertex* dst) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& cur = src[i];
    const ClipVertex& next = src[(i + 1) % n];
    double d_cur = plane_distance(plane, cur.v, vol);
    double d_next = plane_distance(plane, next.v, vol);
    bool cur_in = d_cur >= 0.0, next_in = d_next >= 0.0;
    if (cur_in) dst[m++] = cur;
    if (cur_in && !next_in) intersect(plane, cur, next, d_cur, d_next, num_floats, vol, dst[m++]);
    if (!cur_in && next_in) intersect(plane, next, cur, d_next, d_cur, num_floats, vol, dst[m++]);
  }
  return m;
}

}  // namespace

bool is_finite_position(const float* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && std::isfinite(p[3]);
}

uint32_t clip_outcode(const float* position, const ClipVolume& volume) {
  if (!is_finite_position(position)) return (1u << kNumClipPlanes) - 1;
  uint32_t code = 0;
  for (int p = 0; p < kNumClipPlanes; ++p) {
    if (!(plane_distance(p, position, volume) >= 0.0)) code |= 1u << p;
  }
  return code;
}

int clip_triangle(const ClipVertex* const in[3], int num_floats, const ClipVolume& volume,
                  ClipVertex out[kMaxClippedVertices]) {
  ClipVertex scratch[kMaxClippedVertices];
  for (int i = 0; i < 3; ++i) out[i] = *in[i];
  int n = 3;
  uint32_t any_out = 0;
  for (int i = 0; i < 3; ++i) any_out |= clip_outcode(in[i]->v, volume);
  for (int p = 0; p < kNumClipPlanes && n >= 3; ++p) {
    if (!(any_out & (1u << p))) continue;  // nobody is outside this plane
    n = clip_polygon_against(p, out, n, num_floats, volume, scratch);
    for (int i = 0; i < n; ++i) out[i] = scratch[i];
  }
  return n >= 3 ? n : 0;
}

bool clip_line(const ClipVertex& a, const ClipVertex& b, int num_floats, const ClipVolume& volume,
               ClipVertex& out_a, ClipVertex& out_b) {
  out_a = a;
  out_b = b;
  for (int p = 0; p < kNumClipPlanes; ++p) {
    double da = plane_distance(p, out_a.v, volume);
    double db = plane_distance(p, out_b.v, volume);
    bool a_in = da >= 0.0, b_in = db >= 0.0;
    if (!a_in && !b_in) return false;  // also catches NaN
    if (a_in && b_in) continue;
    ClipVertex cut;
    if (a_in) {
      intersect(p, out_a, out_b, da, db, num_floats, volume, cut);
      out_b = cut;
    } else {
      intersect(p, out_b, out_a, db, da, num_floats, volume, cut);
      out_a = cut;
    }
  }
  return true;
}

}  // namespace softrast::detail
