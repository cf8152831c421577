// apps/softrast/args.hpp: the flags of `softrast render` as CLI11 sees them: raw text and
// numbers, each optional so that "not given" (use the scene's default) is visible.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace softrast::cli {

struct RawArgs {
  std::optional<std::string> model;  // none: the built-in demo scene
  std::optional<std::string> output;
  std::optional<std::string> size;
  std::optional<std::string> eye, target, up, ortho;
  std::optional<float> fov, near_plane, far_plane;
  std::string shader = "phong";
  bool wireframe = false;
  std::optional<std::string> texture;
  std::optional<std::string> color;
  std::optional<std::string> light;
  std::string cull = "back";
  std::string front_face = "ccw";
  std::string depth = "less";
  std::string blend = "opaque";
  float alpha = 1.0f;
  std::string raster = "edge";
  int threads = 0;
  bool reference_path = false;
  std::string filter = "bilinear";
  std::string wrap = "repeat";
  std::optional<int> frames;
  bool quiet = false;
  std::optional<int> quality;  // JPEG output quality, 1..100
};

// Adds every flag of the render command to `app`, storing into `args`.
void define_render_flags(CLI::App& app, RawArgs& args);

}  // namespace softrast::cli
