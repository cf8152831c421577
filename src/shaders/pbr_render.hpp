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

// The power of two that the lit shaders' world positions, eye and point light (phong) or view
// rays (pbr) are scaled by: 1 while the scene's distances stay within 2^-32 .. 2^32 (the image
// is then what it always was); otherwise the one that brings the largest of them (the eye, the
// far plane, a point light) to [0.5, 1). Lighting reads only directions, which the scale leaves
// alone, but a squared length overflows float beyond about 2^64 (units of 1e30: the highlight
// was lost) and underflows below 2^-63.
float shading_scale(const Camera& camera, const RenderOptions& options);

}  // namespace softrast::detail
