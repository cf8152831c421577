// pipeline/multisample_draw.hpp: filled triangles with several samples per pixel
// (RenderState::samples > 1): coverage and depth per sample, one shading per pixel and triangle,
// the pixels resolved at the end of the draw.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/geometry_stage.hpp"
#include "softrast/detail/interpolants.hpp"

namespace softrast::detail {

// Draws the triangles of `indices` into the framebuffer's samples (Framebuffer::multisample,
// filled from the pixels first when not valid for this sample count), then resolves every 64x64
// tile a triangle touched. Triangles are set up in submission order on the calling thread; the
// tiles are rasterized and shaded on up to `threads` threads, each pixel seeing its triangles in
// order. Precondition: standard_sample_pattern(state.samples) exists and is not 1.
void draw_triangles_multisample(Framebuffer& framebuffer, const GeometryStage& geometry,
                                const RenderState& state, const FragmentProgram& program,
                                const uint32_t* indices, size_t index_count, int threads);

}  // namespace softrast::detail
