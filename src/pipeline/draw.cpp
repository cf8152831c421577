// pipeline/draw.cpp: one draw call from clip-space vertices to shaded pixels: primitive
// assembly, clipping, divide and viewport (GeometryStage), setup and culling, rasterization and
// the fragment program. Filled triangles take the binned path (binned_draw.cpp), on the calling
// thread alone when threads = 1; lines, points, wireframe and RenderState::reference_path run
// here in submission order: the single-threaded reference the binned path must match bit for bit.
#include "pipeline/draw_internal.hpp"
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
  line(w0, w1);
  line(w1, w2);
  line(w2, w0);
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

void draw_clip_space(Framebuffer& framebuffer, const RenderState& state,
                     const ClipVertices& vertices, const uint32_t* indices, size_t index_count,
                     const FragmentProgram& program) {
  if (vertices.num_varyings < 0 || vertices.num_varyings > kMaxVaryings) return;
  if (vertices.stride < 4 + vertices.num_varyings || program.shade_block == nullptr) return;
  GeometryStage geometry(framebuffer.width(), framebuffer.height(), state, vertices);
  ShadeTarget target{&framebuffer, &state};
  int threads = state.threads > 0 ? state.threads : hardware_threads();
  if (!state.reference_path && state.primitive == Primitive::kTriangles && !state.wireframe) {
    draw_triangles_binned(geometry, state, target, program, indices, index_count, threads);
    return;
  }
  SerialDraw(geometry, state, target, program).draw(indices, index_count);
}

}  // namespace softrast::detail
