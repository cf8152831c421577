// apps/softrast/setup.hpp: from raw flags to a render job that cannot fail for bad input.
// Two steps: interpret() checks every flag value without touching files (usage errors);
// prepare() checks the output path, loads the texture and model and settles the camera
// (runtime errors). Nothing is rendered or written before both have succeeded.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "args.hpp"
#include "framing.hpp"
#include "softrast/camera.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"
#include "softrast/status.hpp"

namespace softrast::cli {

// Every flag checked and typed; files not yet opened.
struct JobSpec {
  std::optional<std::string> model;   // none: the demo scene
  std::optional<std::string> output;  // none: no image (benchmark without -o)
  int width = 800;
  int height = 600;
  CameraFlags camera;
  RenderOptions options;  // all but the texture
  std::optional<std::string> texture;
  // No --light: the light follows the camera (options.light_direction is then taken in the
  // camera's frame: x right, y up, z towards the viewer).
  bool headlight = true;
  int frames = 0;  // 0: one untimed render
  bool quiet = false;
  int jpeg_quality = kDefaultJpegQuality;
};

// The mesh and the camera to see it with.
struct Scene {
  std::string name;    // the model's file name without extension, or "demo"
  std::string source;  // for messages: the model path or "demo scene"
  Mesh mesh;
  Camera camera;  // validated
  double load_ms = 0.0;
};

// What run_job() needs: everything loaded and validated.
struct Job {
  Job(Scene s, Framebuffer target) : scene(std::move(s)), framebuffer(std::move(target)) {}

  Scene scene;
  Framebuffer framebuffer;
  RenderOptions options;
  std::optional<std::string> output;
  int frames = 0;
  bool quiet = false;
  int jpeg_quality = kDefaultJpegQuality;  // for .jpg output
};

Result<JobSpec> interpret(const RawArgs& args);
Result<Job> prepare(const JobSpec& spec);

}  // namespace softrast::cli
