// pipeline/geometry_stage.hpp: the per-primitive front end shared by the single-threaded and the
// binned draw: NaN/Inf rejection, outcodes, clipping, the divide and viewport, the depth bias.
// It hands window-space primitives to a callback and keeps no state between primitives, so any
// number of threads may use one GeometryStage at once.
#pragma once

#include <algorithm>
#include <cstring>

#include "geometry/clip.hpp"
#include "geometry/viewport.hpp"
#include "pipeline/vertex_kernels.hpp"
#include "raster/setup.hpp"
#include "softrast/render_state.hpp"

namespace softrast::detail {

class GeometryStage {
 public:
  GeometryStage(int width, int height, const RenderState& state, const ClipVertices& vertices)
      : state_(state), vertices_(vertices) {
    viewport_.width = width;
    viewport_.height = height;
    volume_ = viewport_.clip_volume();
    scissor_ = {0, 0, width, height};
    num_floats_ = 4 + vertices.num_varyings;
  }

  const PixelRect& scissor() const { return scissor_; }
  int num_varyings() const { return vertices_.num_varyings; }
  bool valid(uint32_t index) const { return size_t(index) < vertices_.count; }
  size_t vertex_count() const { return vertices_.count; }

  // Calls emit(w0, w1, w2) for every window-space triangle that triangle (i0, i1, i2) clips to,
  // in order (a clipped polygon becomes a fan). Precondition: valid indices.
  template <class Emit>
  void triangle(uint32_t i0, uint32_t i1, uint32_t i2, Emit&& emit) const {
    const float* p[3] = {vertex(i0), vertex(i1), vertex(i2)};
    // NaN or Inf anywhere in a position discards the primitive: nothing sensible can be drawn.
    if (!is_finite_position(p[0]) || !is_finite_position(p[1]) || !is_finite_position(p[2])) {
      return;
    }
    uint32_t o0 = clip_outcode(p[0], volume_), o1 = clip_outcode(p[1], volume_),
             o2 = clip_outcode(p[2], volume_);
    if (o0 & o1 & o2) return;  // all three outside one plane
    if ((o0 | o1 | o2) == 0) {
      emit(window(p[0]), window(p[1]), window(p[2]));
      return;
    }
    ClipVertex in[3], poly[kMaxClippedVertices];
    load(i0, in[0]);
    load(i1, in[1]);
    load(i2, in[2]);
    const ClipVertex* src[3] = {&in[0], &in[1], &in[2]};
    int n = clip_triangle(src, num_floats_, volume_, poly);
    for (int k = 1; k + 1 < n; ++k)
      emit(window(poly[0].v), window(poly[k].v), window(poly[k + 1].v));
  }

  // Calls emit(w0, w1) with the visible part of segment (i0, i1), if any.
  template <class Emit>
  void line(uint32_t i0, uint32_t i1, Emit&& emit) const {
    if (!is_finite_position(vertex(i0)) || !is_finite_position(vertex(i1))) return;
    ClipVertex a, b, ca, cb;
    load(i0, a);
    load(i1, b);
    if (!clip_line(a, b, num_floats_, volume_, ca, cb)) return;
    emit(window(ca.v), window(cb.v));
  }

  // Per-vertex front end, for producers that transform each vertex once (the binned draw):
  // vertex i's outcode (clip_outcode), or kNonFinite when its position has a NaN or an Inf.
  static constexpr uint32_t kNonFinite = 1u << kNumClipPlanes;
  uint32_t vertex_code(uint32_t i) const {
    const float* p = vertex(i);
    return is_finite_position(p) ? clip_outcode(p, volume_) : kNonFinite;
  }
  // Vertex i in window space, exactly as triangle() makes it; precondition: vertex_code(i) == 0.
  WindowVertex window_vertex(uint32_t i) const { return window(vertex(i)); }
  const float* varyings(uint32_t i) const { return vertex(i) + 4; }
  size_t stride() const { return size_t(vertices_.stride); }  // floats from vertex i to i + 1
  // The same for many vertices at once (vertex_kernels.hpp), writing to `codes` and `window`.
  VertexBatch vertex_batch(uint8_t* codes, PackedVertex* window) const {
    VertexBatch b;
    b.data = vertices_.data;
    b.stride = vertices_.stride;
    b.guard_x = volume_.guard_x;
    b.guard_y = volume_.guard_y;
    b.width = viewport_.width;
    b.height = viewport_.height;
    b.depth_bias = state_.depth_bias;
    b.codes = codes;
    b.window = window;
    return b;
  }

  // The window position of point i; false when it lies outside the clip volume.
  bool point(uint32_t i, WindowVertex& out) const {
    const float* p = vertex(i);
    if (clip_outcode(p, volume_) != 0) return false;  // includes NaN and Inf
    out = window(p);
    return true;
  }

 private:
  const float* vertex(uint32_t index) const {
    return vertices_.data + size_t(index) * size_t(vertices_.stride);
  }
  void load(uint32_t index, ClipVertex& out) const {
    std::memcpy(out.v, vertex(index), sizeof(float) * size_t(num_floats_));
  }
  WindowVertex window(const float* clip_vertex) const {
    WindowVertex w = viewport_.to_window(clip_vertex);
    if (state_.depth_bias != 0.0f) w.z = std::clamp(w.z + state_.depth_bias, 0.0f, 1.0f);
    return w;
  }

  const RenderState& state_;
  const ClipVertices& vertices_;
  Viewport viewport_;
  ClipVolume volume_;
  PixelRect scissor_;
  int num_floats_ = 4;
};

}  // namespace softrast::detail
