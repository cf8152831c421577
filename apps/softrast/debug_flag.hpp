// apps/softrast/debug_flag.hpp: the --debug flag shared by `render` and `view`: its help text and
// its value, with the same one-line error as every other enum flag.
#pragma once

#include <array>
#include <string_view>

#include "softrast/debug_view.hpp"
#include "softrast/status.hpp"
#include "values.hpp"

namespace softrast::cli {

inline constexpr const char* kDebugViewHelp =
    "Debug view instead of the shaded image (default none): tiles (the 64x64 tile grid over "
    "the image), overdraw (fragments per pixel before the depth test: black 0, blue 1, then "
    "through cyan, green and yellow to red 8, white above 8), cost (time per tile, blue fastest to "
    "red slowest, "
    "over the image in grey), triangles (each triangle in its own colour)";

inline constexpr std::array<Named<DebugView>, 5> kDebugViews = {
    {{"none", DebugView::kNone},
     {"tiles", DebugView::kTiles},
     {"overdraw", DebugView::kOverdraw},
     {"cost", DebugView::kCost},
     {"triangles", DebugView::kTriangles}}};

inline Result<DebugView> debug_view_named(std::string_view flag, std::string_view text) {
  return lookup<DebugView>(flag, kDebugViews, text);
}

}  // namespace softrast::cli
