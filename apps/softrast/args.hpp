// apps/softrast/args.hpp: the flags of `softrast render` as CLI11 sees them: raw text and
// numbers, each optional so that "not given" (use the scene's default) is visible.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace softrast::cli {

struct RawArgs {
  std::vector<std::string> models;  // files and folders; none: the built-in demo scene
  std::optional<std::string> output;
  std::optional<std::string> size;
  std::optional<std::string> eye, target, up, ortho;
  std::optional<float> fov, near_plane, far_plane;
  std::string up_axis = "+y";
  std::optional<std::string> view;
  std::optional<float> azimuth, elevation, zoom;
  std::string shader;  // empty: phong, or pbr for glTF models (JobSpec::auto_shader)
  bool wireframe = false;
  std::optional<std::string> texture;
  std::optional<std::string> color;
  std::optional<std::string> light;
  std::optional<std::string> light_pos;  // a point light's position
  std::string maps = "all";              // which material maps phong uses
  bool srgb = false;                     // the linear workflow (sRGB textures and output)
  std::optional<float> ambient, light_intensity;
  std::optional<float> exposure;
  std::optional<std::string> edge_color;
  std::optional<std::string> background;
  std::string cull = "none";
  std::string front_face = "ccw";
  std::string depth = "less";
  std::string blend = "opaque";
  float alpha = 1.0f;
  std::string raster = "edge";
  int threads = 0;
  bool reference_path = false;
  int msaa = 1;                       // samples per pixel (RenderState::samples)
  bool shadows = false;               // shadow map of the light (RenderOptions::shadows)
  std::optional<std::string> filter;  // default: bilinear, trilinear for the demo scene
  std::string wrap = "repeat";
  std::optional<int> frames;
  bool quiet = false;
  std::string debug = "none";  // a debug view (softrast/debug_view.hpp)
  // Set by define_sequence_flags (sequence.hpp) for `softrast render` only, never in batch jobs.
  std::optional<int> turntable;
  bool json = false;
  std::optional<int> quality;  // JPEG output quality, 1..100
};

// Adds every flag of the render command to `app`, storing into `args`.
void define_render_flags(CLI::App& app, RawArgs& args);

}  // namespace softrast::cli
