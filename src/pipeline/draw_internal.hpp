// pipeline/draw_internal.hpp: pieces shared by the single-threaded and the binned draw.
#pragma once

#include "pipeline/geometry_stage.hpp"
#include "raster/raster.hpp"
#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// Routes the rasterizer's 4x4 blocks to the fragment program, with the interpolants of the
// primitive being rasterized. One per thread.
class Shading {
 public:
  Shading(const FragmentProgram& program, const ShadeTarget& target)
      : program_(program), target_(target) {}
  BlockSink sink(const Interpolants& interp) {
    current_ = &interp;
    return BlockSink{&Shading::emit, this};
  }

 private:
  static void emit(void* self, int x, int y, uint32_t mask) {
    auto* s = static_cast<Shading*>(self);
    s->program_.shade_block(s->program_.shader, s->target_, *s->current_, x, y, mask);
  }
  const FragmentProgram& program_;
  ShadeTarget target_;
  const Interpolants* current_ = nullptr;
};

inline void rasterize_triangle(const TriangleCoverage& tri, RasterAlgorithm algorithm,
                               const PixelRect& region, const BlockSink& sink) {
  if (algorithm == RasterAlgorithm::kScanline) {
    rasterize_triangle_scanline(tri, region, sink);
  } else {
    rasterize_triangle_edge_equations(tri, region, sink);
  }
}

// Triangles on all threads: geometry in parallel chunks that bin their setups into 64x64
// tiles, then the tiles in parallel, each walking its bins in submission order.
void draw_triangles_binned(const GeometryStage& geometry, const RenderState& state,
                           const ShadeTarget& target, const FragmentProgram& program,
                           const uint32_t* indices, size_t index_count, int threads);

}  // namespace softrast::detail
