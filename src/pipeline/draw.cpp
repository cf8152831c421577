// pipeline/draw.cpp: one draw call from clip-space vertices to shaded pixels: primitive
// assembly, clipping, divide and viewport, setup and culling, rasterization. Single-threaded and
// in submission order, so blending is order-correct; the tile loop inside the edge-equation
// rasterizer is where per-tile binning and threads will go.
#include <algorithm>
#include <cstring>

#include "geometry/clip.hpp"
#include "geometry/viewport.hpp"
#include "raster/raster.hpp"
#include "raster/setup.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"

namespace softrast::detail {
namespace {

class DrawContext {
 public:
  DrawContext(Framebuffer& fb, const RenderState& state, const ClipVertices& vertices,
              const FragmentProgram& program)
      : state_(state), vertices_(vertices), program_(program) {
    target_.framebuffer = &fb;
    target_.state = &state;
    viewport_.width = fb.width();
    viewport_.height = fb.height();
    volume_ = viewport_.clip_volume();
    scissor_ = {0, 0, fb.width(), fb.height()};
    num_floats_ = 4 + vertices.num_varyings;
  }

  void draw(const uint32_t* indices, size_t count);

 private:
  const float* vertex(uint32_t index) const {
    return vertices_.data + size_t(index) * size_t(vertices_.stride);
  }
  void load(uint32_t index, ClipVertex& out) const {
    std::memcpy(out.v, vertex(index), sizeof(float) * size_t(num_floats_));
  }
  void triangle(uint32_t i0, uint32_t i1, uint32_t i2);
  void window_triangle(const float* a, const float* b, const float* c);
  void wire_triangle(const WindowVertex& w0, const WindowVertex& w1, const WindowVertex& w2);
  void window_line(const WindowVertex& a, const WindowVertex& b);
  void line(uint32_t i0, uint32_t i1);
  void point(uint32_t i);

  BlockSink sink(const Interpolants& interp) {
    current_ = &interp;
    return BlockSink{&DrawContext::emit, this};
  }
  static void emit(void* self, int x, int y, uint32_t mask) {
    auto* c = static_cast<DrawContext*>(self);
    c->program_.shade_block(c->program_.shader, c->target_, *c->current_, x, y, mask);
  }

  const RenderState& state_;
  const ClipVertices& vertices_;
  const FragmentProgram& program_;
  ShadeTarget target_;
  Viewport viewport_;
  ClipVolume volume_;
  PixelRect scissor_;
  int num_floats_ = 4;
  const Interpolants* current_ = nullptr;
};

void DrawContext::draw(const uint32_t* indices, size_t count) {
  size_t n = vertices_.count;
  auto valid = [n](uint32_t i) { return size_t(i) < n; };
  switch (state_.primitive) {
    case Primitive::kTriangles:
      for (size_t k = 0; k + 2 < count; k += 3) {
        if (valid(indices[k]) && valid(indices[k + 1]) && valid(indices[k + 2]))
          triangle(indices[k], indices[k + 1], indices[k + 2]);
      }
      break;
    case Primitive::kLines:
      for (size_t k = 0; k + 1 < count; k += 2) {
        if (valid(indices[k]) && valid(indices[k + 1])) line(indices[k], indices[k + 1]);
      }
      break;
    case Primitive::kPoints:
      for (size_t k = 0; k < count; ++k) {
        if (valid(indices[k])) point(indices[k]);
      }
      break;
  }
}

void DrawContext::triangle(uint32_t i0, uint32_t i1, uint32_t i2) {
  const float* p[3] = {vertex(i0), vertex(i1), vertex(i2)};
  // NaN or Inf anywhere in a position discards the primitive: nothing sensible can be drawn.
  if (!is_finite_position(p[0]) || !is_finite_position(p[1]) || !is_finite_position(p[2])) return;
  uint32_t o0 = clip_outcode(p[0], volume_), o1 = clip_outcode(p[1], volume_),
           o2 = clip_outcode(p[2], volume_);
  if (o0 & o1 & o2) return;  // all three outside one plane
  if ((o0 | o1 | o2) == 0) return window_triangle(p[0], p[1], p[2]);

  ClipVertex in[3], poly[kMaxClippedVertices];
  load(i0, in[0]);
  load(i1, in[1]);
  load(i2, in[2]);
  const ClipVertex* src[3] = {&in[0], &in[1], &in[2]};
  int n = clip_triangle(src, num_floats_, volume_, poly);
  for (int k = 1; k + 1 < n; ++k) window_triangle(poly[0].v, poly[k].v, poly[k + 1].v);
}

void DrawContext::window_triangle(const float* a, const float* b, const float* c) {
  WindowVertex w0 = viewport_.to_window(a), w1 = viewport_.to_window(b),
               w2 = viewport_.to_window(c);
  if (state_.depth_bias != 0.0f) {
    for (WindowVertex* w : {&w0, &w1, &w2}) w->z = std::clamp(w->z + state_.depth_bias, 0.0f, 1.0f);
  }
  if (state_.wireframe) return wire_triangle(w0, w1, w2);
  TriangleSetup tri;
  if (!setup_triangle(w0, w1, w2, vertices_.num_varyings, state_.cull, state_.front_face, scissor_,
                      tri)) {
    return;
  }
  BlockSink s = sink(tri.interp);
  if (state_.raster == RasterAlgorithm::kScanline) {
    rasterize_triangle_scanline(tri, scissor_, s);
  } else {
    rasterize_triangle_edge_equations(tri, scissor_, s);
  }
}

// Polygon mode "line": the triangle is culled like a filled one, then its edges are drawn.
void DrawContext::wire_triangle(const WindowVertex& w0, const WindowVertex& w1,
                                const WindowVertex& w2) {
  int64_t area = signed_area_fx16(w0, w1, w2);
  if (area == 0 && state_.cull != CullMode::kNone) return;
  bool front = (state_.front_face == FrontFace::kCounterClockwise) == (area < 0);
  if ((state_.cull == CullMode::kBack && !front) || (state_.cull == CullMode::kFront && front)) {
    return;
  }
  window_line(w0, w1);
  window_line(w1, w2);
  window_line(w2, w0);
}

void DrawContext::window_line(const WindowVertex& a, const WindowVertex& b) {
  LineSetup setup;
  if (!setup_line(a, b, vertices_.num_varyings, scissor_, setup)) return;
  rasterize_line(setup, scissor_, sink(setup.interp));
}

void DrawContext::line(uint32_t i0, uint32_t i1) {
  if (!is_finite_position(vertex(i0)) || !is_finite_position(vertex(i1))) return;
  ClipVertex a, b, ca, cb;
  load(i0, a);
  load(i1, b);
  if (!clip_line(a, b, num_floats_, volume_, ca, cb)) return;
  WindowVertex wa = viewport_.to_window(ca.v), wb = viewport_.to_window(cb.v);
  wa.z = std::clamp(wa.z + state_.depth_bias, 0.0f, 1.0f);
  wb.z = std::clamp(wb.z + state_.depth_bias, 0.0f, 1.0f);
  window_line(wa, wb);
}

void DrawContext::point(uint32_t i) {
  const float* p = vertex(i);
  if (clip_outcode(p, volume_) != 0) return;  // includes NaN and Inf
  Interpolants interp;
  int x, y;
  WindowVertex w = viewport_.to_window(p);
  w.z = std::clamp(w.z + state_.depth_bias, 0.0f, 1.0f);
  if (!setup_point(w, vertices_.num_varyings, scissor_, x, y, interp)) return;
  int bx = x & ~(kBlockSize - 1), by = y & ~(kBlockSize - 1);
  sink(interp)(bx, by, 1u << (4 * (y - by) + (x - bx)));
}

}  // namespace

void draw_clip_space(Framebuffer& framebuffer, const RenderState& state,
                     const ClipVertices& vertices, const uint32_t* indices, size_t index_count,
                     const FragmentProgram& program) {
  if (vertices.num_varyings < 0 || vertices.num_varyings > kMaxVaryings) return;
  if (vertices.stride < 4 + vertices.num_varyings || program.shade_block == nullptr) return;
  DrawContext context(framebuffer, state, vertices, program);
  context.draw(indices, index_count);
}

}  // namespace softrast::detail
