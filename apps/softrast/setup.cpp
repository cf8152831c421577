// apps/softrast/setup.cpp: checking the flags, then the files, then the camera, in that order,
// so that a mistake costs no loading or rendering time and never leaves an output file.

#include "setup.hpp"

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <utility>

#include "debug_flag.hpp"
#include "scene_files.hpp"
#include "softrast/image.hpp"
#include "softrast/texture.hpp"
#include "values.hpp"

namespace softrast::cli {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxFrames = 1000000;

// Keeps the first error of a sequence of checks, so each check is one line.
class FirstError {
 public:
  template <class T, class U>
  void take(Result<T> result, U& out) {
    if (!status_.ok()) return;
    if (result) {
      out = std::move(*result);
    } else {
      status_ = result.status();
    }
  }
  void fail_if(bool bad, const std::string& message) {
    if (bad && status_.ok()) status_ = Status::error(message);
  }
  const Status& status() const { return status_; }

 private:
  Status status_;
};

struct DepthSetting {
  bool test;
  DepthFunc func;
};

constexpr std::array<Named<CullMode>, 3> kCullModes = {
    {{"back", CullMode::kBack}, {"front", CullMode::kFront}, {"none", CullMode::kNone}}};
constexpr std::array<Named<FrontFace>, 2> kFrontFaces = {
    {{"ccw", FrontFace::kCounterClockwise}, {"cw", FrontFace::kClockwise}}};
constexpr std::array<Named<DepthSetting>, 9> kDepthSettings = {{
    {"less", {true, DepthFunc::kLess}},
    {"lequal", {true, DepthFunc::kLessEqual}},
    {"equal", {true, DepthFunc::kEqual}},
    {"greater", {true, DepthFunc::kGreater}},
    {"gequal", {true, DepthFunc::kGreaterEqual}},
    {"notequal", {true, DepthFunc::kNotEqual}},
    {"always", {true, DepthFunc::kAlways}},
    {"never", {true, DepthFunc::kNever}},
    {"off", {false, DepthFunc::kLess}},
}};
constexpr std::array<Named<BlendMode>, 3> kBlendModes = {
    {{"opaque", BlendMode::kOpaque}, {"alpha", BlendMode::kAlpha}, {"add", BlendMode::kAdditive}}};
constexpr std::array<Named<RasterAlgorithm>, 2> kRasterAlgorithms = {
    {{"edge", RasterAlgorithm::kEdgeEquations}, {"scanline", RasterAlgorithm::kScanline}}};
constexpr std::array<Named<Filter>, 3> kFilters = {{{"nearest", Filter::kNearest},
                                                    {"bilinear", Filter::kBilinear},
                                                    {"trilinear", Filter::kTrilinear}}};
constexpr std::array<Named<Wrap>, 3> kWraps = {
    {{"repeat", Wrap::kRepeat}, {"clamp", Wrap::kClampToEdge}, {"mirror", Wrap::kMirroredRepeat}}};
constexpr std::array<Named<RenderOptions::Maps>, 3> kMapChoices = {
    {{"all", RenderOptions::Maps::kAll},
     {"diffuse", RenderOptions::Maps::kDiffuse},
     {"none", RenderOptions::Maps::kNone}}};
constexpr std::array<ShaderKind, 8> kShaderKinds = {
    ShaderKind::kFlat,    ShaderKind::kGouraud, ShaderKind::kTexture,   ShaderKind::kPhong,
    ShaderKind::kNormals, ShaderKind::kDepth,   ShaderKind::kWireframe, ShaderKind::kPbr};

Result<ShaderKind> shader_named(const std::string& name) {
  if (std::optional<ShaderKind> kind = parse_shader_kind(name)) return *kind;
  std::vector<std::string_view> names;
  for (ShaderKind kind : kShaderKinds) names.push_back(shader_kind_name(kind));
  return Status::error("--shader: unknown shader '" + name + "' (expected " + name_list(names) +
                       ")");
}

bool in_unit_range(float x) {
  return x >= 0.0f && x <= 1.0f;
}

constexpr int kMaxThreads = 1024;
constexpr float kMaxLightIntensity = 100.0f;

const std::array<Named<glm::vec3>, 6> kUpAxes = {{{"+x", {1.0f, 0.0f, 0.0f}},
                                                  {"-x", {-1.0f, 0.0f, 0.0f}},
                                                  {"+y", {0.0f, 1.0f, 0.0f}},
                                                  {"-y", {0.0f, -1.0f, 0.0f}},
                                                  {"+z", {0.0f, 0.0f, 1.0f}},
                                                  {"-z", {0.0f, 0.0f, -1.0f}}}};

void interpret_state(const RawArgs& a, RenderState& state, FirstError& e) {
  e.take(lookup<CullMode>("--cull", kCullModes, a.cull), state.cull);
  e.take(lookup<FrontFace>("--front-face", kFrontFaces, a.front_face), state.front_face);
  DepthSetting depth{true, DepthFunc::kLess};
  e.take(lookup<DepthSetting>("--depth", kDepthSettings, a.depth), depth);
  state.depth_test = depth.test;
  state.depth_func = depth.func;
  e.take(lookup<BlendMode>("--blend", kBlendModes, a.blend), state.blend);
  e.take(lookup<RasterAlgorithm>("--raster", kRasterAlgorithms, a.raster), state.raster);
  e.fail_if(a.threads < 0 || a.threads > kMaxThreads,
            "--threads: must be in 0.." + std::to_string(kMaxThreads));
  state.threads = a.threads;
  state.reference_path = a.reference_path;
  e.fail_if(a.msaa != 1 && a.msaa != 2 && a.msaa != 4 && a.msaa != 8,
            "--msaa: must be 1, 2, 4 or 8, got " + std::to_string(a.msaa));
  state.samples = a.msaa;
}

void interpret_shading(const RawArgs& a, RenderOptions& options, FirstError& e) {
  e.take(shader_named(a.shader.empty() ? "phong" : a.shader), options.shader);
  if (a.exposure) {
    e.fail_if(!(*a.exposure >= -20.0f && *a.exposure <= 20.0f),
              "--exposure: must be in [-20, 20] stops");
    options.exposure = *a.exposure;
  }
  options.wireframe_overlay = a.wireframe;
  if (a.color) {
    glm::vec4 color(0.0f);
    e.take(parse_color("--color", *a.color, false), color);
    options.color = glm::vec3(color);
  }
  if (a.light) {
    e.take(parse_vec3("--light", *a.light), options.light_direction);
    e.fail_if(!(glm::length(options.light_direction) > 1.0e-6f),
              "--light: the direction must not be zero, got '" + *a.light + "'");
  }
  if (a.light_pos) {
    glm::vec3 position(0.0f);
    e.take(parse_vec3("--light-pos", *a.light_pos), position);
    e.fail_if(a.light.has_value(),
              "--light-pos: a point light has no direction; give --light or --light-pos, not both");
    options.light_position = position;
  }
  e.take(lookup<RenderOptions::Maps>("--maps", kMapChoices, a.maps), options.maps);
  options.srgb = a.srgb;
  if (a.ambient) {
    e.fail_if(!in_unit_range(*a.ambient), "--ambient: must be in [0, 1]");
    options.ambient = *a.ambient;
  }
  if (a.light_intensity) {
    e.fail_if(!(*a.light_intensity >= 0.0f && *a.light_intensity <= kMaxLightIntensity),
              "--light-intensity: must be in [0, 100]");
    options.light_intensity = *a.light_intensity;
  }
  if (a.edge_color) {
    glm::vec4 edge(0.0f);
    e.take(parse_color("--edge-color", *a.edge_color, false), edge);
    options.wire_color = glm::vec3(edge);
  }
  e.fail_if(!in_unit_range(a.alpha), "--alpha: must be in [0, 1]");
  options.alpha = a.alpha;
  options.shadows = a.shadows;
  // The demo scene's floor reaches the horizon, where bilinear filtering draws moire: without
  // --filter it is drawn mipmapped. Models keep bilinear, the benchmark pipeline's (SCENES.md).
  const std::string filter = a.filter.value_or(a.models.empty() ? "trilinear" : "bilinear");
  e.take(lookup<Filter>("--filter", kFilters, filter), options.sampler.filter);
  e.take(lookup<Wrap>("--wrap", kWraps, a.wrap), options.sampler.wrap_u);
  e.take(debug_view_named("--debug", a.debug), options.debug_view);
  options.sampler.wrap_v = options.sampler.wrap_u;
}

// What can be said about the camera before the scene is known; the complete check is
// Camera::validate() once the scene's defaults are filled in.
void check_camera_flags(const CameraFlags& c, FirstError& e) {
  if (c.fov) e.fail_if(!(*c.fov > 0.0f && *c.fov < 180.0f), "--fov: must be in (0, 180) degrees");
  if (c.near_plane) e.fail_if(!std::isfinite(*c.near_plane), "--near: must be a finite number");
  if (c.far_plane) e.fail_if(!std::isfinite(*c.far_plane), "--far: must be a finite number");
  if (c.near_plane && !c.ortho) {
    e.fail_if(!(*c.near_plane > 0.0f), "--near: must be > 0 with a perspective projection");
  }
  if (c.near_plane && c.far_plane) {
    e.fail_if(!(*c.near_plane < *c.far_plane), "--near must be less than --far");
  }
  if (c.eye && c.target) e.fail_if(*c.eye == *c.target, "--eye and --target must differ");
  if (c.ortho) {
    glm::vec4 box = *c.ortho;
    e.fail_if(box.x == box.y || box.z == box.w, "--ortho: the box is empty");
  }
}

// --up-axis, and the flags that place the camera instead of --eye.
void interpret_placement(const RawArgs& a, CameraFlags& c, FirstError& e) {
  e.take(lookup<glm::vec3>("--up-axis", kUpAxes, a.up_axis), c.up_axis);
  if (a.view) {
    std::optional<Orientation> o = view_named(*a.view);
    e.fail_if(!o, "--view: unknown view '" + *a.view + "' (expected " + view_names() + ")");
    if (o) c.azimuth = o->azimuth, c.elevation = o->elevation;
  }
  if (a.azimuth) {
    e.fail_if(!std::isfinite(*a.azimuth), "--azimuth: must be a finite number of degrees");
    c.azimuth = a.azimuth;
  }
  if (a.elevation) {
    e.fail_if(!(*a.elevation >= -90.0f && *a.elevation <= 90.0f),
              "--elevation: must be in [-90, 90] degrees");
    c.elevation = a.elevation;
  }
  if (a.zoom) {
    e.fail_if(!(*a.zoom > 0.0f && *a.zoom <= 1000.0f), "--zoom: must be in (0, 1000]");
    c.zoom = *a.zoom;
    e.fail_if(a.ortho.has_value(), "--zoom: not with --ortho (its box sets the size)");
  }
  bool placed = a.view || a.azimuth || a.elevation || a.zoom;
  e.fail_if(a.eye && placed,
            "--eye places the camera itself; it cannot be combined with --view, --azimuth, "
            "--elevation or --zoom");
}

void interpret_camera(const RawArgs& a, CameraFlags& c, FirstError& e) {
  if (a.eye) e.take(parse_vec3("--eye", *a.eye), c.eye);
  if (a.target) e.take(parse_vec3("--target", *a.target), c.target);
  if (a.up) e.take(parse_vec3("--up", *a.up), c.up);
  if (a.ortho) e.take(parse_vec4("--ortho", *a.ortho), c.ortho);
  c.fov = a.fov;
  c.near_plane = a.near_plane;
  c.far_plane = a.far_plane;
  check_camera_flags(c, e);
  interpret_placement(a, c, e);
}

// The output's format: .png, .jpg/.jpeg, .tga, or "-" (PNG on the standard output); --quality.
void interpret_image_output(const RawArgs& a, JobSpec& spec, FirstError& e) {
  bool to_stdout = spec.output && *spec.output == "-";
  std::optional<ImageFormat> format;
  if (spec.output && !to_stdout) {
    format = image_format_of(*spec.output);
    e.fail_if(!format, *spec.output +
                           ": unknown image format (the output must end in .png, .jpg or .tga, "
                           "or be - for the standard output)");
  }
  e.fail_if(to_stdout && spec.frames > 0,
            "-o -: cannot be combined with --frames (both write to the standard output)");
  if (a.quality) {
    e.fail_if(*a.quality < 1 || *a.quality > 100, "--quality: must be in 1..100");
    e.fail_if(format != ImageFormat::kJpeg, "--quality: only for .jpg output");
    spec.jpeg_quality = *a.quality;
  }
}

void interpret_output(const RawArgs& a, JobSpec& spec, FirstError& e) {
  if (a.size) {
    glm::ivec2 size(0);
    e.take(parse_size("--size", *a.size), size);
    spec.width = size.x;
    spec.height = size.y;
  }
  if (a.frames) {
    e.fail_if(*a.frames < 1 || *a.frames > kMaxFrames,
              "--frames: must be in 1.." + std::to_string(kMaxFrames));
    spec.frames = *a.frames;
  }
  if (a.background) e.take(parse_color("--background", *a.background, true), spec.background);
  spec.output = a.output;
  if (!spec.output && spec.frames == 0) spec.output = "softrast.png";
  interpret_image_output(a, spec, e);
}

// The folder must exist and be writable now, not after a long render.
Status check_output_path(const std::string& path) {
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return Status::error(path + ": '" + dir.string() + "' is not an existing folder");
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    return Status::error(path + ": cannot write in folder '" + dir.string() +
                         "': " + std::strerror(errno));
  }
  if (fs::is_directory(path, ec)) return Status::error(path + ": is a folder");
  return {};
}

Result<std::shared_ptr<const Texture>> load_texture(const std::string& path) {
  Result<Image> image = load_image(path);
  if (!image) return image.status();
  // A colour texture: sRGB data (decoded only with --srgb).
  return std::shared_ptr<const Texture>(
      std::make_shared<Texture>(Texture::from_image(*image, ColorSpace::kSrgb)));
}

}  // namespace

bool has_pbr_materials(const Mesh& mesh) {
  return std::any_of(mesh.materials.begin(), mesh.materials.end(),
                     [](const Material& m) { return m.pbr.has_value(); });
}

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The scene's name for the benchmark line: each model file's name without extension (a folder's
// name), joined by "+"; "demo" without models.
std::string scene_name(const std::vector<std::string>& args) {
  if (args.empty()) return "demo";
  std::string name;
  for (const std::string& arg : args) {
    fs::path path = fs::path(arg).lexically_normal();
    if (path.filename().empty()) path = path.parent_path();  // "folder/"
    name += (name.empty() ? "" : "+") +
            (path.has_extension() ? path.stem().string() : path.filename().string());
  }
  return name;
}

std::string joined(const std::vector<std::string>& args) {
  std::string text;
  for (const std::string& a : args) text += (text.empty() ? "" : " ") + a;
  return text;
}

// The model files framed automatically as one scene, or the demo scene with its own camera; the
// flags override either.
Result<Scene> load_scene(const JobSpec& spec, const Loaders& loaders) {
  auto start = std::chrono::steady_clock::now();
  Scene scene;
  if (spec.models.empty()) {
    DemoScene demo = make_demo_scene();
    scene.mesh = std::move(demo.mesh);
    scene.camera = demo.camera;
    apply_flags(scene.camera, spec.camera);
  } else {
    Result<std::vector<std::string>> paths = expand_model_paths(spec.models);
    if (!paths) return paths.status();
    Result<LoadedModels> loaded = load_models(*paths, loaders.model);
    if (!loaded) return loaded.status();
    scene.mesh = std::move(loaded->mesh);
    scene.warnings = std::move(loaded->warnings);
    std::vector<std::string> more =
        texture_warnings(loaded->parts, spec.options, spec.texture.has_value());
    scene.warnings.insert(scene.warnings.end(), more.begin(), more.end());
    float aspect = float(spec.width) / float(spec.height);
    scene.camera = frame_model(scene.mesh, spec.camera, aspect);
  }
  scene.load_ms = milliseconds_since(start);
  scene.name = scene_name(spec.models);
  scene.source = spec.models.empty() ? "demo scene" : joined(spec.models);
  if (spec.camera.eye && !spec.camera.target && scene.camera.eye == scene.camera.target) {
    return Status::error(
        "--eye is at the default --target, the centre of the scene; give --target, or another "
        "--eye");
  }
  if (Status s = scene.camera.validate(); !s.ok()) return s;
  return scene;
}

}  // namespace

Result<JobSpec> interpret(const RawArgs& args) {
  JobSpec spec;
  FirstError e;
  interpret_output(args, spec, e);
  interpret_camera(args, spec.camera, e);
  interpret_shading(args, spec.options, e);
  interpret_state(args, spec.options.state, e);
  if (!e.status().ok()) return e.status();
  spec.models = args.models;
  spec.texture = args.texture;
  spec.headlight = !args.light && !args.light_pos;
  spec.auto_shader = args.shader.empty();
  if (args.models.empty()) {
    e.fail_if(args.up_axis != "+y" || args.view || args.azimuth || args.elevation || args.zoom,
              "--up-axis, --view, --azimuth, --elevation and --zoom frame a model; the demo "
              "scene has its own camera");
    if (!e.status().ok()) return e.status();
  }
  spec.quiet = args.quiet;
  return spec;
}

Result<Job> prepare(const JobSpec& spec, const Loaders& loaders) {
  if (spec.output && *spec.output == "-" && ::isatty(STDOUT_FILENO)) {
    return Status::error("-o -: the standard output is a terminal; redirect it to a file or pipe");
  }
  if (spec.output && *spec.output != "-") {
    if (Status s = check_output_path(*spec.output); !s.ok()) return s;
  }
  RenderOptions options = spec.options;
  if (spec.texture) {
    Result<std::shared_ptr<const Texture>> texture =
        loaders.texture ? loaders.texture(*spec.texture) : load_texture(*spec.texture);
    if (!texture) return texture.status();
    options.texture = std::move(*texture);
  }
  Result<Scene> scene = load_scene(spec, loaders);
  if (!scene) return scene.status();
  // Allocated last: up to 2 GiB for the largest size, not worth spending on a bad model.
  Result<Framebuffer> framebuffer = Framebuffer::create(spec.width, spec.height);
  if (!framebuffer) return framebuffer.status();
  if (spec.headlight) {
    // From the camera's frame to the world: the transpose of the view matrix's rotation.
    glm::mat3 camera_to_world = glm::transpose(glm::mat3(scene->camera.view()));
    options.light_direction = camera_to_world * glm::normalize(options.light_direction);
  }
  if (spec.auto_shader && has_pbr_materials(scene->mesh)) options.shader = ShaderKind::kPbr;
  Job job(std::move(*scene), std::move(*framebuffer));
  job.options = std::move(options);
  job.background = spec.background;
  job.output = spec.output;
  job.frames = spec.frames;
  job.quiet = spec.quiet;
  job.jpeg_quality = spec.jpeg_quality;
  return job;
}

}  // namespace softrast::cli
