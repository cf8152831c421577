// shaders/pbr_render.hpp: how render_mesh draws with ShaderKind::kPbr (pbr_render.cpp).
#pragma once

#include <span>

#include <glm/mat4x4.hpp>

#include "softrast/renderer.hpp"

namespace softrast::detail {

// Draws `runs` of `mesh` with the pbr shader: single-sided materials with back faces culled,
// double-sided ones without; opaque and masked runs first, in order, then the triangles of
// blended runs sorted back to front (by their centroid's view depth) with alpha blending and no
// depth writes. Materials without PbrMaterial draw as a dielectric of their diffuse colour
// (roughness 0.5, the diffuse map as the base colour map), double-sided.
void render_pbr(Framebuffer& framebuffer, const Mesh& mesh, const Camera& camera,
                const glm::mat4& mvp, std::span<const SubMesh> runs, const RenderState& state,
                const RenderOptions& options);

}  // namespace softrast::detail
