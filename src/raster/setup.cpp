// raster/setup.cpp: edge functions, fill-rule bias, bounds and plane equations.
#include "raster/setup.hpp"

#include "core/check.hpp"
#include "core/unit_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>

namespace softrast::detail {
namespace {

// Top-left rule in y-down window coordinates for a clockwise triangle: a left edge runs upwards
// (dy < 0); a top edge is horizontal and runs to the right (dy == 0, dx > 0).
bool is_top_left(int64_t dx, int64_t dy) {
  return dy < 0 || (dy == 0 && dx > 0);
}

EdgeFunction make_edge(int32_t xi, int32_t yi, int32_t xj, int32_t yj) {
  // E(p) = (xj - xi)(py - yi) - (yj - yi)(px - xi): positive to the right of i->j in y-down
  // coordinates, i.e. inside a clockwise triangle.
  int64_t dx = int64_t(xj) - xi, dy = int64_t(yj) - yi;
  EdgeFunction e;
  e.a = -dy;
  e.b = dx;
  e.c = dy * xi - dx * yi;
  if (!is_top_left(dx, dy)) e.c -= 1;  // samples exactly on the edge fail the E >= 0 test
  return e;
}

double to_pixels(int32_t fx8) {
  return double(fx8) / kSubpixelOne;
}

// The triangle's shape as the plane equations need it: vertex 1 and 2 minus vertex 0, in pixels,
// and the reciprocal of twice the signed area in square pixels (one division per triangle, not
// two per plane: the gradients are float in the end, and the product differs from the quotient by
// at most an ulp of a double).
struct PlaneBasis {
  double dx1, dx2, dy1, dy2, inv_area2;
};

// The plane through the vertices with values a0, a1, a2 (the basis's vertex 0 at (rx0, ry0) from
// the reference point), in double; the depth plane stays so, the others are rounded by to_float.
DepthPlane make_plane(const PlaneBasis& g, double rx0, double ry0, double a0, double a1,
                      double a2) {
  double da1 = a1 - a0, da2 = a2 - a0;
  DepthPlane p;
  p.dadx = (da1 * g.dy2 - da2 * g.dy1) * g.inv_area2;
  p.dady = (da2 * g.dx1 - da1 * g.dx2) * g.inv_area2;
  p.a0 = (rx0 != 0.0 || ry0 != 0.0) ? a0 - p.dadx * rx0 - p.dady * ry0 : a0;
  return p;
}

Plane to_float(const DepthPlane& p) {
  return {float(p.a0), float(p.dadx), float(p.dady)};
}

// The 1/w of a primitive's vertices for its planes: as they are, unless the largest is outside
// [2^-20, 2^20] (w under about 1e-6 or over about 1e6: a scene in tiny or huge units); then all
// times the power of two that brings the largest to [0.5, 1). Scaling by a power of two is exact,
// so the fragment stage's quotient plane(var) / plane(1/w) is unchanged bit for bit, but var / w
// stays far from float's limits: 1/w reaches 1e30 at the clipper's smallest w, and falls below
// the fragment stage's floor of 1e-30 where w is larger (a model in units of 1e30, whose
// interpolated colours came out 0.37 times too dark), or into float's denormals.
[[gnu::cold, gnu::noinline]] void scale_inv_w(double* inv_w, int count) {
  const double scale = unit_scale(*std::max_element(inv_w, inv_w + count));
  for (int k = 0; k < count; ++k) inv_w[k] *= scale;
}
template <int kCount>
void scaled_inv_w(const float (&in)[kCount], double (&out)[kCount]) {
  float largest = in[0];
  for (int k = 0; k < kCount; ++k) out[k] = in[k], largest = std::max(largest, in[k]);
  if (!(largest <= 0x1p20f && largest >= 0x1p-20f)) [[unlikely]] {
    if (largest > 0.0f && std::isfinite(largest)) scale_inv_w(out, kCount);
  }
}

PixelRect triangle_bounds(const int32_t vx[3], const int32_t vy[3]) {
  int64_t xmin = std::min({vx[0], vx[1], vx[2]}), xmax = std::max({vx[0], vx[1], vx[2]});
  int64_t ymin = std::min({vy[0], vy[1], vy[2]}), ymax = std::max({vy[0], vy[1], vy[2]});
  // Pixel i's sample is at 256 i + 128: the first sample at or right of xmin, the last at or
  // left of xmax.
  PixelRect r;
  r.x0 = int(ceil_div(xmin - kSubpixelHalf, kSubpixelOne));
  r.x1 = int(floor_div(xmax - kSubpixelHalf, kSubpixelOne)) + 1;
  r.y0 = int(ceil_div(ymin - kSubpixelHalf, kSubpixelOne));
  r.y1 = int(floor_div(ymax - kSubpixelHalf, kSubpixelOne)) + 1;
  return r;
}

// Fills the planes for depth, 1/w and varying/w of the (already reordered) triangle.
//
// The planes pass through the vertices where the application put them, not where snapping to
// 1/256 pixel moved them (the residuals of WindowVertex), as Mesa's llvmpipe and the exact
// result do: for a sliver whose height is a few 1/256 of a pixel, the snapped vertices tilt the
// planes enough that a minified texture lookup lands several texels away. The planes stay
// referenced at the snapped vertex 0, which float holds exactly (x_ref, y_ref): a0 is the exact
// plane's value there. When snapping changed the triangle's shape so much that the exact area is
// under a sixteenth of the snapped one (or of the other sign), the exact planes' gradients would
// be unbounded where coverage still finds samples; those keep the snapped shape.
// setup_plane_lanes (pipeline/triangle_kernel.inl) does the same, operation for operation, for 8
// or 16 triangles at once: a change here is a change there (tests/triangle_kernel_test.cpp).
void setup_planes(const WindowVertex* const v[3], int num_varyings, int64_t area_fx16,
                  Interpolants& out) {
  PlaneBasis g;
  g.dx1 = to_pixels(v[1]->x - v[0]->x);  // differences of 16.8 coordinates: exact in int32
  g.dx2 = to_pixels(v[2]->x - v[0]->x);
  g.dy1 = to_pixels(v[1]->y - v[0]->y);
  g.dy2 = to_pixels(v[2]->y - v[0]->y);
  // The exact vertices, relative to the snapped vertex 0 (rx0, ry0: vertex 0's own residual).
  const double rx0 = to_pixels(1) * v[0]->x_residual, ry0 = to_pixels(1) * v[0]->y_residual;
  PlaneBasis e;
  e.dx1 = g.dx1 + (to_pixels(1) * v[1]->x_residual - rx0);
  e.dx2 = g.dx2 + (to_pixels(1) * v[2]->x_residual - rx0);
  e.dy1 = g.dy1 + (to_pixels(1) * v[1]->y_residual - ry0);
  e.dy2 = g.dy2 + (to_pixels(1) * v[2]->y_residual - ry0);
  double exact_area2 = e.dx1 * e.dy2 - e.dx2 * e.dy1;  // positive for the clockwise order
  double snapped_area2 = double(area_fx16) / (double(kSubpixelOne) * kSubpixelOne);
  bool exact = (rx0 != 0.0 || ry0 != 0.0 || e.dx1 != g.dx1 || e.dx2 != g.dx2 || e.dy1 != g.dy1 ||
                e.dy2 != g.dy2) &&
               exact_area2 >= snapped_area2 * (1.0 / 16.0);
  // One division, whichever basis is used (the same quotient either way).
  double inv_area2 =
      exact ? 1.0 / exact_area2 : double(kSubpixelOne) * kSubpixelOne / double(area_fx16);
  g.inv_area2 = e.inv_area2 = inv_area2;
  // The exact planes pass through the exact vertex 0, which is (rx0, ry0) from the snapped one.
  const PlaneBasis& basis = exact ? e : g;
  const double ox = exact ? rx0 : 0.0, oy = exact ? ry0 : 0.0;
  auto plane = [&](double a0, double a1, double a2) {
    return make_plane(basis, ox, oy, a0, a1, a2);
  };
  out.x_ref = float(to_pixels(v[0]->x));
  out.y_ref = float(to_pixels(v[0]->y));
  out.z = plane(v[0]->z, v[1]->z, v[2]->z);
  double iw[3];  // 1/w, times a power of two where w is tiny or huge (scaled_inv_w)
  scaled_inv_w({v[0]->inv_w, v[1]->inv_w, v[2]->inv_w}, iw);
  const double w0 = iw[0], w1 = iw[1], w2 = iw[2];
  out.inv_w = to_float(plane(w0, w1, w2));
  const float *a0 = v[0]->varyings, *a1 = v[1]->varyings, *a2 = v[2]->varyings;
  for (int i = 0; i < num_varyings; ++i) {
    // float * float (times a power of two) is exact in double.
    out.var[i] = to_float(plane(double(a0[i]) * w0, double(a1[i]) * w1, double(a2[i]) * w2));
  }
  out.num_varyings = num_varyings;
}

}  // namespace

bool setup_triangle_coverage(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                             int64_t area, const PixelRect& scissor, TriangleCoverage& out,
                             const WindowVertex* ordered[3]) {
  // Clipping keeps every vertex inside the guard band; the bit budget of the edge functions
  // (fixed_point.hpp) depends on it.
  for (const WindowVertex* v : {&v0, &v1, &v2}) {
    SOFTRAST_CHECK_LT(std::llabs(v->x), kMaxCoordFx8);
    SOFTRAST_CHECK_LT(std::llabs(v->y), kMaxCoordFx8);
  }
  bool ccw = area < 0;  // counter-clockwise as seen in the image (y down)

  // Reorder to clockwise so that every edge function is positive inside.
  ordered[0] = &v0;
  ordered[1] = ccw ? &v2 : &v1;
  ordered[2] = ccw ? &v1 : &v2;
  for (int k = 0; k < 3; ++k) {
    out.vx[k] = ordered[k]->x;
    out.vy[k] = ordered[k]->y;
  }
  out.bounds = intersect(triangle_bounds(out.vx, out.vy), scissor);
  if (out.bounds.empty()) return false;
  for (int k = 0; k < 3; ++k) {
    int j = (k + 1) % 3;
    out.edge[k] = make_edge(out.vx[k], out.vy[k], out.vx[j], out.vy[j]);
  }
  return true;
}

void setup_triangle_interpolants(const WindowVertex* const ordered[3], int num_varyings,
                                 int64_t area, FrontFace front_face, Interpolants& out) {
  setup_planes(ordered, num_varyings, std::abs(area), out);
  out.front_facing = is_front_facing(area, front_face);
}

bool setup_triangle(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                    int num_varyings, CullMode cull, FrontFace front_face, const PixelRect& scissor,
                    TriangleSetup& out) {
  int64_t area = signed_area_fx16(v0, v1, v2);
  if (area == 0) return false;  // zero area: back-facing by convention, and covers nothing
  if (is_culled(area, cull, front_face)) return false;
  const WindowVertex* ordered[3];
  if (!setup_triangle_coverage(v0, v1, v2, area, scissor, out, ordered)) return false;
  setup_triangle_interpolants(ordered, num_varyings, area, front_face, out.interp);
  return true;
}

EdgeFunction triangle_edge(int32_t xi, int32_t yi, int32_t xj, int32_t yj) {
  return make_edge(xi, yi, xj, yj);
}

bool setup_line(const WindowVertex& v0, const WindowVertex& v1, int num_varyings,
                const PixelRect& scissor, LineSetup& out) {
  int64_t dx = int64_t(v1.x) - v0.x, dy = int64_t(v1.y) - v0.y;
  if (dx == 0 && dy == 0) return false;
  out.x0 = v0.x;
  out.y0 = v0.y;
  out.x1 = v1.x;
  out.y1 = v1.y;
  // The pixels containing the endpoints, and one more on every side for ties that the
  // diamond-exit rule resolves towards a neighbour.
  PixelRect box;
  box.x0 = int(floor_div(std::min(v0.x, v1.x), kSubpixelOne)) - 1;
  box.x1 = int(floor_div(std::max(v0.x, v1.x), kSubpixelOne)) + 2;
  box.y0 = int(floor_div(std::min(v0.y, v1.y), kSubpixelOne)) - 1;
  box.y1 = int(floor_div(std::max(v0.y, v1.y), kSubpixelOne)) + 2;
  out.bounds = intersect(box, scissor);
  if (out.bounds.empty()) return false;

  // Attributes vary along the major axis only: a(x, y) = a0 + (x - x0) * (a1 - a0) / dx.
  bool x_major = std::llabs(dx) >= std::llabs(dy);
  double len = double(x_major ? dx : dy) / kSubpixelOne;
  auto line_plane = [&](double a0, double a1) {
    DepthPlane p;
    p.a0 = a0;
    (x_major ? p.dadx : p.dady) = (a1 - a0) / len;
    return p;
  };
  Interpolants& in = out.interp;
  in.x_ref = float(to_pixels(v0.x));
  in.y_ref = float(to_pixels(v0.y));
  in.z = line_plane(v0.z, v1.z);
  double iw[2];  // as setup_planes
  scaled_inv_w({v0.inv_w, v1.inv_w}, iw);
  const double w0 = iw[0], w1 = iw[1];
  in.inv_w = to_float(line_plane(w0, w1));
  for (int i = 0; i < num_varyings; ++i) {
    in.var[i] = to_float(line_plane(double(v0.varyings[i]) * w0, double(v1.varyings[i]) * w1));
  }
  in.num_varyings = num_varyings;
  in.front_facing = true;
  return true;
}

bool setup_point(const WindowVertex& v, int num_varyings, const PixelRect& scissor, int& px,
                 int& py, Interpolants& out) {
  px = int(floor_div(v.x, kSubpixelOne));
  py = int(floor_div(v.y, kSubpixelOne));
  if (px < scissor.x0 || px >= scissor.x1 || py < scissor.y0 || py >= scissor.y1) return false;
  out = Interpolants{};
  out.x_ref = float(to_pixels(v.x));
  out.y_ref = float(to_pixels(v.y));
  out.z.a0 = v.z;
  double iw[1];  // as setup_planes
  scaled_inv_w({v.inv_w}, iw);
  out.inv_w.a0 = float(iw[0]);
  for (int i = 0; i < num_varyings; ++i) out.var[i].a0 = float(double(v.varyings[i]) * iw[0]);
  out.num_varyings = num_varyings;
  out.front_facing = true;
  return true;
}

}  // namespace softrast::detail
