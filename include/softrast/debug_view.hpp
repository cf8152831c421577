// softrast/debug_view.hpp: pictures of the pipeline's work instead of the shaded image, shared by
// `softrast render --debug VIEW` and the live viewer. Selected by RenderOptions::debug_view.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <glm/vec3.hpp>

namespace softrast {

enum class DebugView {
  kNone,       // the shaded image
  kTiles,      // the shaded image with the binned path's 64x64 tile grid over it
  kOverdraw,   // fragments per pixel (every rasterized fragment, before the depth test)
  kCost,       // time spent per tile as a heat map over the grey image, with the tile grid
  kTriangles,  // every triangle in its own colour (depth-tested)
};
std::optional<DebugView> parse_debug_view(std::string_view name);
const char* debug_view_name(DebugView view);

// The side of the tiles the binned path works in (pixels), as the tiles view draws them.
inline constexpr int kDebugTileSize = 64;

// The heat scale of the overdraw and cost views: t = 0 blue, 0.25 cyan, 0.5 green, 0.75 yellow,
// 1 red, linear in between; t is clamped to [0, 1].
glm::vec3 heat_color(float t);

// The overdraw view's colour for a pixel hit by `fragments` fragments: 0 black, 1..8 along the
// heat scale (1 blue, 8 red), more than 8 white. Packed RGBA8 as Framebuffer stores it.
uint32_t overdraw_color(int fragments);

// The triangles view's colour for the triangle at position `triangle` in Mesh::indices: a hash
// of the index, each channel in 40..255, so that neighbours (consecutive indices) differ.
uint32_t triangle_color(uint32_t triangle);

// The colour of the grid lines of the tiles and cost views (light yellow).
inline constexpr uint32_t kTileGridColor = 0xff40e0ffu;

}  // namespace softrast
