// raster/setup.hpp: the contract between geometry and the rasterizers. Triangle setup turns
// three snapped window-space vertices into edge functions with the fill rule folded in, a pixel
// bounding box and the plane equations of the fragment stage. All per-triangle work is here.
#pragma once

#include <algorithm>
#include <cstdint>

#include "raster/fixed_point.hpp"
#include "softrast/detail/interpolants.hpp"
#include "softrast/render_state.hpp"

namespace softrast::detail {

// A vertex after the divide, the viewport transform and snapping.
struct WindowVertex {
  int32_t x = 0;                    // 1/256 pixel (16.8 fixed point), window x (right)
  int32_t y = 0;                    // 1/256 pixel, window y (down)
  float z = 0.0f;                   // window depth in [0, 1]
  float inv_w = 1.0f;               // 1 / clip w
  const float* varyings = nullptr;  // num_varyings floats, not yet divided by w
  // What snapping moved: the exact window position minus (x, y), in 1/256 pixel (|r| <= 1/2; 0
  // where the position was clamped). Coverage uses the snapped position; the attribute planes use
  // the exact one, as the application gave it (see setup_planes).
  float x_residual = 0.0f;
  float y_residual = 0.0f;
};

// E(x, y) = a * x + b * y + c with x, y in 1/256 pixel. The sample (x, y) is covered by the
// edge iff E >= 0: the top-left rule is already in c (c is one less for edges that are neither
// top nor left, so a sample exactly on such an edge fails).
struct EdgeFunction {
  int64_t a = 0;
  int64_t b = 0;
  int64_t c = 0;
  int64_t at(int64_t x, int64_t y) const { return a * x + b * y + c; }
};

// A rectangle of pixels [x0, x1) x [y0, y1).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
};
inline PixelRect intersect(const PixelRect& a, const PixelRect& b) {
  return {std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

// Window x or y of the sample point of pixel i, in 1/256 pixel.
inline int64_t sample_fx8(int i) {
  return int64_t(i) * kSubpixelOne + kSubpixelHalf;
}

// What the rasterizers read of a triangle.
struct TriangleCoverage {
  // Vertices in clockwise order as seen in the image (y down), so E > 0 inside every edge.
  int32_t vx[3] = {0, 0, 0};
  int32_t vy[3] = {0, 0, 0};
  EdgeFunction edge[3];  // edge k runs from vertex k to vertex (k + 1) % 3
  PixelRect bounds;      // pixels whose samples can be covered, already inside the scissor
};

struct TriangleSetup : TriangleCoverage {
  Interpolants interp;
};

// Twice the signed area of the snapped triangle, (x1-x0)(y2-y0) - (x2-x0)(y1-y0), exact.
// In y-down window coordinates it is negative for counter-clockwise triangles. V: any vertex with
// WindowVertex's int32 x and y (16.8 fixed point).
template <class V>
int64_t signed_area_fx16(const V& v0, const V& v1, const V& v2) {
  return (int64_t(v1.x) - v0.x) * (int64_t(v2.y) - v0.y) -
         (int64_t(v2.x) - v0.x) * (int64_t(v1.y) - v0.y);
}

// Facing and culling from the sign of the snapped area (signed_area_fx16); zero area counts as
// back-facing.
inline bool is_front_facing(int64_t area, FrontFace front_face) {
  return area != 0 && (front_face == FrontFace::kCounterClockwise) == (area < 0);
}
inline bool is_culled(int64_t area, CullMode cull, FrontFace front_face) {
  bool front = is_front_facing(area, front_face);
  return (cull == CullMode::kBack && !front) || (cull == CullMode::kFront && front);
}

// Culling and setup of one triangle. Returns false when the triangle is culled (zero area
// counts as back-facing and is never drawn), or covers no pixel of `scissor`.
bool setup_triangle(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                    int num_varyings, CullMode cull, FrontFace front_face, const PixelRect& scissor,
                    TriangleSetup& out);

// setup_triangle in two steps, for producers that store the interpolants elsewhere (the bins'
// compact records) and cull before anything else. The first takes the snapped signed area
// (signed_area_fx16, non-zero, of a triangle that is_culled kept), reorders the vertices
// clockwise into `ordered` and fills the coverage; false when it covers no pixel of `scissor`.
// The second fills the interpolants. setup_triangle is the area, the cull and these two calls, so
// every path sets triangles up identically.
bool setup_triangle_coverage(const WindowVertex& v0, const WindowVertex& v1, const WindowVertex& v2,
                             int64_t area, const PixelRect& scissor, TriangleCoverage& out,
                             const WindowVertex* ordered[3]);
void setup_triangle_interpolants(const WindowVertex* const ordered[3], int num_varyings,
                                 int64_t area, FrontFace front_face, Interpolants& out);

// The edge function of the edge from (xi, yi) to (xj, yj) of a clockwise triangle (1/256 pixel),
// with the top-left rule in c: the edges setup_triangle makes, for rasterizers that test other
// sample positions than the pixel centres (multisampling).
EdgeFunction triangle_edge(int32_t xi, int32_t yi, int32_t xj, int32_t yj);

// A line segment after snapping, with its interpolants (gradients along the major axis only).
struct LineSetup {
  int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // 1/256 pixel
  PixelRect bounds;
  Interpolants interp;
};
bool setup_line(const WindowVertex& v0, const WindowVertex& v1, int num_varyings,
                const PixelRect& scissor, LineSetup& out);

// A point: the pixel that contains it, with constant interpolants.
bool setup_point(const WindowVertex& v, int num_varyings, const PixelRect& scissor, int& px,
                 int& py, Interpolants& out);

}  // namespace softrast::detail
