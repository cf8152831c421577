// pipeline/draw_internal.hpp: pieces shared by the single-threaded and the binned draw.
#pragma once

#include <algorithm>
#include <vector>

#include "pipeline/geometry_stage.hpp"
#include "raster/raster.hpp"
#include "softrast/detail/interpolants.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/simd_level.hpp"

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

// Every vertex's outcode and, inside the clip volume, its window position, computed once per
// vertex several at a time (vertex_kernels.hpp) instead of once per triangle corner; kept by the
// caller between draws (the vectors only grow). For the binned and the multisampled draw.
class WindowVertices {
 public:
  // Transforms the geometry's vertices in jobs of kPerJob on `threads` threads.
  void transform(const GeometryStage& geometry, int threads) {
    constexpr size_t kPerJob = 1024;
    const size_t n = geometry.vertex_count();
    window_.resize(n);
    codes_.resize(n);
    VertexBatch batch = geometry.vertex_batch(codes_.data(), window_.data());
    VertexKernelFn kernel = vertex_kernel(simd_level());
    parallel_for((n + kPerJob - 1) / kPerJob, threads, [&](size_t job) {
      kernel(batch, job * kPerJob, std::min(n, (job + 1) * kPerJob));
    });
  }
  // Triangle i[0..2] into `emit` (a WindowVertex triple, as GeometryStage::triangle calls it):
  // straight from the window positions when every vertex is inside the clip volume (trivial
  // accept, no clipping), through the clipper when it crosses a plane, not at all when it lies
  // outside one plane, has a NaN or Inf position or an index out of range.
  template <class Emit>
  void triangle(const GeometryStage& geometry, const uint32_t* i, Emit&& emit) const {
    auto every = [](int64_t) { return true; };
    triangle(geometry, i, every, emit);
  }
  // The same, but a trivially accepted triangle goes to `emit` only if keep(its snapped signed
  // area, signed_area_fx16) is true: a culled triangle stops before its window vertices are made
  // (half of a closed mesh). Clipped pieces go to `emit` regardless.
  template <class Keep, class Emit>
  void triangle(const GeometryStage& geometry, const uint32_t* i, Keep&& keep, Emit&& emit) const {
    if (!geometry.valid(i[0]) || !geometry.valid(i[1]) || !geometry.valid(i[2])) return;
    static_assert(GeometryStage::kNonFinite < 256, "codes are stored in bytes");
    uint32_t c0 = codes_[i[0]], c1 = codes_[i[1]], c2 = codes_[i[2]];
    if ((c0 | c1 | c2) == 0) {
      if (!keep(signed_area_fx16(window_[i[0]], window_[i[1]], window_[i[2]]))) return;
      emit(vertex(geometry, i[0]), vertex(geometry, i[1]), vertex(geometry, i[2]));
    } else if (!((c0 | c1 | c2) & GeometryStage::kNonFinite) && !(c0 & c1 & c2)) {
      geometry.triangle(i[0], i[1], i[2], emit);
    }
  }

  // Vertex i as a WindowVertex; precondition: its code is 0.
  WindowVertex vertex(const GeometryStage& geometry, uint32_t i) const {
    const PackedVertex& p = window_[i];
    return {p.x, p.y, p.z, p.inv_w, geometry.varyings(i), p.x_residual, p.y_residual};
  }
  // Every vertex's PackedVertex (kOutsideVolume in x where its code is not 0), and their number.
  const PackedVertex* window() const { return window_.data(); }
  size_t size() const { return window_.size(); }

 private:
  std::vector<PackedVertex> window_;
  std::vector<uint8_t> codes_;  // GeometryStage::vertex_code
};

// Triangles on all threads: geometry in parallel chunks that bin their setups into 64x64
// tiles, then the tiles in parallel, each walking its bins in submission order.
void draw_triangles_binned(const GeometryStage& geometry, const RenderState& state,
                           const ShadeTarget& target, const FragmentProgram& program,
                           const uint32_t* indices, size_t index_count, int threads);

}  // namespace softrast::detail
