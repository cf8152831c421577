// pipeline/draw.cpp: one draw call from clip-space vertices to shaded pixels: primitive
// assembly, clipping, divide and viewport (GeometryStage), setup and culling, rasterization and
// the fragment program. Filled triangles take the binned path (binned_draw.cpp), on the calling
// thread alone when threads = 1; lines, points, wireframe and RenderState::reference_path run
// here in submission order: the single-threaded reference the binned path must match bit for bit.
#include <algorithm>
#include <cmath>

#include "pipeline/draw_internal.hpp"
#include "pipeline/multisample_draw.hpp"
#include "raster/sample_coverage.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/framebuffer.hpp"

namespace softrast::detail {
namespace {

class SerialDraw {
 public:
  SerialDraw(const GeometryStage& geometry, const RenderState& state, const ShadeTarget& target,
             const FragmentProgram& program)
      : geometry_(geometry), state_(state), shading_(program, target) {}

  void draw(const uint32_t* indices, size_t count);

 private:
  void filled_triangle(const WindowVertex& w0, const WindowVertex& w1, const WindowVertex& w2);
  void wire_triangle(const WindowVertex& w0, const WindowVertex& w1, const WindowVertex& w2);
  float polygon_offset(const WindowVertex (&v)[3], int64_t area_fx16) const;
  void line(const WindowVertex& a, const WindowVertex& b);
  void point(const WindowVertex& w);

  const GeometryStage& geometry_;
  const RenderState& state_;
  Shading shading_;
};

void SerialDraw::draw(const uint32_t* indices, size_t count) {
  auto valid = [this](uint32_t i) { return geometry_.valid(i); };
  auto on_triangle = [this](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
    state_.wireframe ? wire_triangle(a, b, c) : filled_triangle(a, b, c);
  };
  auto on_line = [this](const WindowVertex& a, const WindowVertex& b) { line(a, b); };
  switch (state_.primitive) {
    case Primitive::kTriangles:
      for (size_t k = 0; k + 2 < count; k += 3) {
        if (valid(indices[k]) && valid(indices[k + 1]) && valid(indices[k + 2])) {
          geometry_.triangle(indices[k], indices[k + 1], indices[k + 2], on_triangle);
        }
      }
      break;
    case Primitive::kLines:
      for (size_t k = 0; k + 1 < count; k += 2) {
        if (valid(indices[k]) && valid(indices[k + 1])) {
          geometry_.line(indices[k], indices[k + 1], on_line);
        }
      }
      break;
    case Primitive::kPoints:
      for (size_t k = 0; k < count; ++k) {
        WindowVertex w;
        if (valid(indices[k]) && geometry_.point(indices[k], w)) point(w);
      }
      break;
  }
}

void SerialDraw::filled_triangle(const WindowVertex& w0, const WindowVertex& w1,
                                 const WindowVertex& w2) {
  TriangleSetup tri;
  if (!setup_triangle(w0, w1, w2, geometry_.num_varyings(), state_.cull, state_.front_face,
                      geometry_.scissor(), tri)) {
    return;
  }
  rasterize_triangle(tri, state_.raster, geometry_.scissor(), shading_.sink(tri.interp));
}

// Polygon mode "line": the triangle is culled like a filled one, then its edges are drawn.
void SerialDraw::wire_triangle(const WindowVertex& w0, const WindowVertex& w1,
                               const WindowVertex& w2) {
  int64_t area = signed_area_fx16(w0, w1, w2);
  if (area == 0 && state_.cull != CullMode::kNone) return;
  if (is_culled(area, state_.cull, state_.front_face)) return;
  if (state_.polygon_offset_factor == 0.0f && state_.polygon_offset_units == 0.0f) {
    line(w0, w1);
    line(w1, w2);
    line(w2, w0);
    return;
  }
  WindowVertex v[3] = {w0, w1, w2};
  float offset = polygon_offset(v, area);
  for (WindowVertex& w : v) w.z = std::clamp(w.z + offset, 0.0f, 1.0f);
  line(v[0], v[1]);
  line(v[1], v[2]);
  line(v[2], v[0]);
}

// glPolygonOffset's offset for the triangle: factor * max(|dz/dx|, |dz/dy|) + units * r, with
// the slopes of the triangle's depth plane in depth per pixel and r = 2^-24 (a 24-bit buffer's
// step, as the reference renderer has). A degenerate triangle has no slope.
float SerialDraw::polygon_offset(const WindowVertex (&v)[3], int64_t area_fx16) const {
  float slope = 0.0f;
  if (area_fx16 != 0) {
    double x1 = double(v[1].x - v[0].x) / kSubpixelOne, y1 = double(v[1].y - v[0].y) / kSubpixelOne;
    double x2 = double(v[2].x - v[0].x) / kSubpixelOne, y2 = double(v[2].y - v[0].y) / kSubpixelOne;
    double z1 = double(v[1].z) - v[0].z, z2 = double(v[2].z) - v[0].z;
    double area2 = double(area_fx16) / (double(kSubpixelOne) * kSubpixelOne);
    double dzdx = (z1 * y2 - z2 * y1) / area2, dzdy = (z2 * x1 - z1 * x2) / area2;
    slope = float(std::max(std::abs(dzdx), std::abs(dzdy)));
  }
  return state_.polygon_offset_factor * slope + state_.polygon_offset_units * 0x1p-24f;
}

void SerialDraw::line(const WindowVertex& a, const WindowVertex& b) {
  LineSetup setup;
  if (!setup_line(a, b, geometry_.num_varyings(), geometry_.scissor(), setup)) return;
  rasterize_line(setup, geometry_.scissor(), shading_.sink(setup.interp));
}

void SerialDraw::point(const WindowVertex& w) {
  Interpolants interp;
  int x, y;
  if (!setup_point(w, geometry_.num_varyings(), geometry_.scissor(), x, y, interp)) return;
  int bx = x & ~(kBlockSize - 1), by = y & ~(kBlockSize - 1);
  shading_.sink(interp)(bx, by, 1u << (4 * (y - by) + (x - bx)));
}

}  // namespace

void compact_draw(std::span<const uint32_t> indices, uint32_t vertex_count,
                  std::vector<uint32_t>& names, std::vector<uint32_t>& renumbered) {
  // Each vertex's place in `names` plus one (0: not named yet), all zeros between calls; one
  // array per thread whatever the shader type (it grows to the largest vertex count drawn).
  thread_local std::vector<uint32_t> place;
  // Everything allocated first: `place` must be all zeros again when this returns.
  names.clear();
  names.reserve(indices.size());
  renumbered.resize(indices.size());
  if (place.size() < vertex_count) place.resize(vertex_count, 0u);
  for (size_t k = 0; k < indices.size(); ++k) {
    const uint32_t i = indices[k];
    if (i >= vertex_count) {
      renumbered[k] = 0xffffffffu;
      continue;
    }
    uint32_t& p = place[i];
    if (p == 0) {
      names.push_back(i);
      p = uint32_t(names.size());
    }
    renumbered[k] = p - 1;
  }
  for (uint32_t i : names) place[i] = 0;
}

void draw_clip_space(Framebuffer& framebuffer, const RenderState& state,
                     const ClipVertices& vertices, const uint32_t* indices, size_t index_count,
                     const FragmentProgram& program) {
  if (vertices.num_varyings < 0 || vertices.num_varyings > kMaxVaryings) return;
  if (vertices.stride < 4 + vertices.num_varyings || program.shade_block == nullptr) return;
  GeometryStage geometry(framebuffer.width(), framebuffer.height(), state, vertices);
  ShadeTarget target{&framebuffer, &state};
  int threads = state.threads > 0 ? state.threads : hardware_threads();
  bool filled = state.primitive == Primitive::kTriangles && !state.wireframe;
  if (state.samples > 1 && standard_sample_pattern(state.samples) && filled) {
    draw_triangles_multisample(framebuffer, geometry, state, program, indices, index_count,
                               threads);
    return;
  }
  framebuffer.multisample().valid = false;  // the pixels change under the samples
  if (!state.reference_path && state.primitive == Primitive::kTriangles && !state.wireframe) {
    draw_triangles_binned(geometry, state, target, program, indices, index_count, threads);
    return;
  }
  framebuffer.write_pending_clears(threads);  // SerialDraw writes anywhere
  SerialDraw(geometry, state, target, program).draw(indices, index_count);
}

}  // namespace softrast::detail
