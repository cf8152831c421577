// apps/softrast/setup.hpp: from raw flags to a render job that cannot fail for bad input.
// Two steps: interpret() checks every flag value without touching files (usage errors);
// prepare() checks the output path, loads the texture and model and settles the camera
// (runtime errors). Nothing is rendered or written before both have succeeded.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec4.hpp>

#include "args.hpp"
#include "framing.hpp"
#include "softrast/camera.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"
#include "softrast/status.hpp"
#include "softrast/texture.hpp"

namespace softrast::cli {

// Every flag checked and typed; files not yet opened.
struct JobSpec {
  std::vector<std::string> models;    // files and folders; none: the demo scene
  std::optional<std::string> output;  // none: no image (benchmark without -o)
  int width = 800;
  int height = 600;
  CameraFlags camera;
  RenderOptions options;  // all but the texture
  std::optional<std::string> texture;
  // No --light: the light follows the camera (options.light_direction is then taken in the
  // camera's frame: x right, y up, z towards the viewer).
  bool headlight = true;
  // No --shader: phong, or pbr once the scene turns out to have glTF (PBR) materials.
  bool auto_shader = false;
  glm::vec4 background{0.1f, 0.1f, 0.1f, 1.0f};
  int frames = 0;  // 0: one untimed render
  bool quiet = false;
  int jpeg_quality = kDefaultJpegQuality;
};

// The mesh and the camera to see it with.
struct Scene {
  std::string name;    // the model's file name without extension, or "demo"
  std::string source;  // for messages: the model path(s) or "demo scene"
  Mesh mesh;           // every model file merged, each with its own materials
  Camera camera;       // validated
  double load_ms = 0.0;
  // "softrast: warning: " lines to print before rendering (the message part).
  std::vector<std::string> warnings;
};

// True if any material is a glTF one (Material::pbr): such scenes default to the pbr shader.
bool has_pbr_materials(const Mesh& mesh);

// What run_job() needs: everything loaded and validated.
struct Job {
  Job(Scene s, Framebuffer target) : scene(std::move(s)), framebuffer(std::move(target)) {}

  Scene scene;
  Framebuffer framebuffer;
  RenderOptions options;
  glm::vec4 background{0.1f, 0.1f, 0.1f, 1.0f};
  std::optional<std::string> output;
  int frames = 0;
  bool quiet = false;
  int jpeg_quality = kDefaultJpegQuality;  // for .jpg output
};

// How prepare() reads files; `softrast batch` passes loaders that keep what its jobs share. An
// empty function means the usual reader (load_obj, load_image).
struct Loaders {
  std::function<Result<Mesh>(const std::string& path)> model;
  std::function<Result<std::shared_ptr<const Texture>>(const std::string& path)> texture;
};

Result<JobSpec> interpret(const RawArgs& args);
Result<Job> prepare(const JobSpec& spec, const Loaders& loaders = {});

}  // namespace softrast::cli
