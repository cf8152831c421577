// debug/debug_render.hpp: drawing the debug views of softrast/debug_view.hpp; render_mesh hands
// every draw whose options name a debug view to render_debug_view.
#pragma once

#include "softrast/camera.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"

namespace softrast::detail {

// Precondition: options.debug_view != DebugView::kNone.
void render_debug_view(Framebuffer& framebuffer, const Mesh& mesh, const Camera& camera,
                       const RenderOptions& options);

}  // namespace softrast::detail
