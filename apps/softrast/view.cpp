// apps/softrast/view.cpp: the live viewer. Each frame is rendered by softrast into a Framebuffer
// the size of the window's drawable area, copied into an SDL streaming texture and presented;
// SDL does no drawing of its own (the texture is copied 1:1, without scaling or blending).
//
// Frames are rendered when something changed (an event that moves the camera or switches a
// setting, a resize, an expose), not continuously, unless --continuous or --frames asks for it.

#include "view.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "debug_flag.hpp"
#include "framing.hpp"
#include "orbit.hpp"
#include "scene_files.hpp"
#include "setup.hpp"
#include "softrast/image.hpp"
#include "softrast/renderer.hpp"

#ifdef SOFTRAST_HAVE_SDL2
#include <dlfcn.h>

#include <SDL.h>
#endif

namespace softrast::cli {
namespace {

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
constexpr const char* kDefaultWindowSize = "1280x720";
constexpr int kMaxFrames = 1000000;

// The scene shown: the models side by side in world space, or the demo scene.
struct ViewScene {
  std::string source;  // for messages
  Mesh mesh;
  Camera camera;
  Bounds bounds;
  bool demo = false;
};

Result<ViewScene> load_view_scene(const std::vector<std::string>& models, float aspect) {
  ViewScene scene;
  if (models.empty()) {
    DemoScene demo = make_demo_scene();
    scene.mesh = std::move(demo.mesh);
    scene.camera = demo.camera;
    scene.bounds = bounds_of(scene.mesh);
    scene.demo = true;
    scene.source = "demo scene";
    return scene;
  }
  Result<LoadedModels> loaded = load_models(models);  // merged as `softrast render` merges them
  if (!loaded) return loaded.status();
  scene.mesh = std::move(loaded->mesh);
  scene.bounds = bounds_of(scene.mesh);
  scene.camera = frame_model(scene.bounds, CameraFlags{}, aspect);
  scene.source = models.size() == 1 ? models.front() : std::to_string(models.size()) + " models";
  return scene;
}

}  // namespace

void define_view_flags(CLI::App& app, ViewArgs& a) {
  RawArgs& r = a.render;
  app.add_option("MODEL", a.models,
                 "Model files (OBJ, glTF 2.0, PLY or STL) or folders of them, shown together as "
                 "one scene; none: the demo scene");
  app.add_option("--size", r.size, "Initial window size (default 1280x720)")->type_name("WxH");
  app.add_option("--shader", r.shader,
                 "flat, gouraud, texture, phong, normals, depth, wireframe or pbr (default phong; "
                 "pbr for glTF models)")
      ->type_name("NAME");
  app.add_flag("--wireframe", r.wireframe, "Start with the wireframe overlay on");
  app.add_option("--cull", r.cull,
                 "Face culling: back, front or none (default none: both faces, lit on both sides)")
      ->type_name("MODE");
  app.add_option("--raster", r.raster, "Rasterizer: edge (tiles) or scanline (default edge)")
      ->type_name("ALGO");
  app.add_option("--threads", r.threads, "Threads to render with: 0 for every core (default 0)")
      ->type_name("N");
  app.add_option("--debug", r.debug, kDebugViewHelp)->type_name("VIEW");
  app.add_flag("--continuous", a.continuous,
               "Render frames continuously instead of only when something changes");
  app.add_option("--frames", a.frames,
                 "Benchmark: show N frames continuously (after 2 warm-ups), print one JSON line "
                 "with the frames per second, and exit")
      ->type_name("N");
  app.add_flag("-q,--quiet", r.quiet, "No messages on stderr");
  app.footer(
      "Mouse: left drag orbits, right or middle drag pans, the wheel zooms.\n"
      "Keys: Tab / Shift+Tab next / previous shader, W wireframe overlay, R rasterizer (edge "
      "equations / edge walking), C culling (on / off), D / Shift+D next / previous debug view, "
      "Home or 0 reset the camera, P or F12 save a screenshot (softrast_view_NNN.png), Enter "
      "print the `softrast render` command for this frame, Q or Escape quit.\n"
      "The window title shows frames per second, ms per frame, triangles and threads.");
}

#ifndef SOFTRAST_HAVE_SDL2

int view_command(const ViewArgs&, void (*report)(std::string message)) {
  report(
      "this softrast was built without SDL2, so it has no viewer (install libsdl2-dev and "
      "build again)");
  return kExitRuntime;
}

#else

// SDL2 is opened when the viewer starts, not linked: linked, it brought 50 shared libraries
// (X11, Wayland, PulseAudio and their codecs) into every run of the command line, and loading
// them was a fifth of the time of a whole `softrast render` process. Only the functions the
// viewer calls are looked up.
namespace {

// The SDL functions the viewer calls, each X(name) for SDL_name: the table's members and the
// names looked up come from this one list.
// clang-format off
#define SOFTRAST_SDL_FUNCTIONS(X)                                                          \
  X(Quit) X(PollEvent) X(Init) X(GetError) X(DestroyTexture) X(Delay)                      \
  X(UnlockTexture) X(SetWindowTitle) X(SetTextureBlendMode) X(RenderPresent) X(RenderCopy) \
  X(RenderClear) X(LockTexture) X(GetWindowSize) X(GetRendererOutputSize) X(DestroyWindow) \
  X(DestroyRenderer) X(CreateWindow) X(CreateTexture) X(CreateRenderer)                   \
  X(GetCurrentVideoDriver)
// clang-format on

struct SdlApi {
#define SOFTRAST_SDL_MEMBER(name) decltype(&SDL_##name) name = nullptr;
  SOFTRAST_SDL_FUNCTIONS(SOFTRAST_SDL_MEMBER)
#undef SOFTRAST_SDL_MEMBER
};

SdlApi g_sdl;

const SdlApi& sdl() {
  return g_sdl;
}

// Opens libSDL2 and fills g_sdl; false with `error` set when the library or a function is missing.
bool open_sdl(std::string& error) {
  static bool opened = false;
  if (opened) return true;
  void* library = dlopen("libSDL2-2.0.so.0", RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    const char* why = dlerror();
    error = std::string("cannot open SDL2 (libSDL2-2.0.so.0, Debian's libsdl2-2.0-0): ") +
            (why ? why : "unknown error");
    return false;
  }
  SdlApi api;
  const char* missing = nullptr;
  auto load = [&](auto& slot, const char* name) {
    using Slot = std::remove_reference_t<decltype(slot)>;
    slot = reinterpret_cast<Slot>(dlsym(library, name));
    if (!slot) missing = name;
    return slot != nullptr;
  };
  bool ok = true;
#define SOFTRAST_SDL_LOAD(name) ok = ok && load(api.name, "SDL_" #name);
  SOFTRAST_SDL_FUNCTIONS(SOFTRAST_SDL_LOAD)
#undef SOFTRAST_SDL_LOAD
  if (!ok) {
    error = std::string("the SDL2 library has no ") + (missing ? missing : "?");
    return false;
  }
  g_sdl = api;
  opened = true;
  return true;
}

}  // namespace

namespace {

constexpr std::array<ShaderKind, 8> kShaderCycle = {
    ShaderKind::kPhong,   ShaderKind::kFlat,  ShaderKind::kGouraud,   ShaderKind::kTexture,
    ShaderKind::kNormals, ShaderKind::kDepth, ShaderKind::kWireframe, ShaderKind::kPbr};
constexpr std::array<DebugView, 5> kDebugCycle = {DebugView::kNone, DebugView::kTiles,
                                                  DebugView::kOverdraw, DebugView::kCost,
                                                  DebugView::kTriangles};
constexpr int kWarmupFrames = 2;
// How often an idle viewer looks for input: often just after input (a drag's events keep coming),
// less often once it has been idle for a second (about 60 wake-ups a second, under 0.5 % of a
// core).
constexpr uint32_t kActivePollMs = 4, kIdlePollMs = 16;
constexpr double kIdleAfterS = 1.0;
constexpr double kTitleIntervalS = 0.25;  // the heads-up line is refreshed at most this often

template <class T, size_t N>
T cycle(const std::array<T, N>& values, T current, int step) {
  size_t i = size_t(std::find(values.begin(), values.end(), current) - values.begin());
  if (i >= N) return values[0];
  return values[size_t(int(i) + int(N) + step) % N];
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string vec_text(glm::vec3 v) {
  char text[128];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g", double(v.x), double(v.y), double(v.z));
  return text;
}

std::string number_text(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", double(v));
  return text;
}

class Viewer {
 public:
  Viewer(const ViewArgs& args, JobSpec spec, ViewScene scene)
      : args_(args),
        spec_(std::move(spec)),
        scene_(std::move(scene)),
        orbit_(scene_.camera, scene_.bounds, scene_.demo),
        options_(spec_.options),
        light_(spec_.options.light_direction) {}

  ~Viewer() {
    if (texture_) sdl().DestroyTexture(texture_);
    if (renderer_) sdl().DestroyRenderer(renderer_);
    if (window_) sdl().DestroyWindow(window_);
  }

  Status open() {
    window_ = sdl().CreateWindow("softrast", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED,
                                 spec_.width, spec_.height,
                                 SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI);
    if (!window_) return sdl_error("cannot open a window");
    renderer_ = sdl().CreateRenderer(window_, -1, 0);
    if (!renderer_) return sdl_error("cannot create an SDL renderer");
    return resize();
  }

  Status run() {
    if (args_.frames) return benchmark(*args_.frames);
    bool dirty = true;
    while (!quit_) {
      if (dirty || args_.continuous) {
        if (Status s = present(); !s.ok()) return s;
        dirty = false;
      }
      SDL_Event event;
      // Idle, the loop polls every few milliseconds rather than blocking in
      // SDL_WaitEventTimeout: SDL 2.26 wakes a blocked thread by sending its window a message
      // over a second X connection, and under Xvfb such a message now and then went to a window
      // already destroyed at quit, where Xlib's default error handler ended the viewer with
      // status 1 (BadWindow on X_SendEvent; the viewer test saw it about once in five runs on a
      // loaded machine).
      bool any = false;
      while (sdl().PollEvent(&event)) {
        dirty |= handle(event);
        any = true;
      }
      if (any) last_input_ = std::chrono::steady_clock::now();
      if (!any && !dirty && !args_.continuous) {
        sdl().Delay(seconds_since(last_input_) < kIdleAfterS ? kActivePollMs : kIdlePollMs);
      }
      if (resized_) {
        if (Status s = resize(); !s.ok()) return s;
      }
    }
    return {};
  }

 private:
  static Status sdl_error(const std::string& what) {
    return Status::error(what + ": " + sdl().GetError());
  }

  // Framebuffer and texture at the drawable size (larger than the window's on HiDPI screens).
  Status resize() {
    resized_ = false;
    int w = 0, h = 0;
    if (sdl().GetRendererOutputSize(renderer_, &w, &h) != 0) return sdl_error("window size");
    w = std::clamp(w, 1, kMaxImageSize);
    h = std::clamp(h, 1, kMaxImageSize);
    if (framebuffer_ && framebuffer_->width() == w && framebuffer_->height() == h) return {};
    Result<Framebuffer> fb = Framebuffer::create(w, h);
    if (!fb) return fb.status();
    framebuffer_ = std::move(*fb);
    if (texture_) sdl().DestroyTexture(texture_);
    texture_ =
        sdl().CreateTexture(renderer_, SDL_PIXELFORMAT_RGBA32, SDL_TEXTUREACCESS_STREAMING, w, h);
    if (!texture_) return sdl_error("cannot create a texture");
    sdl().SetTextureBlendMode(texture_, SDL_BLENDMODE_NONE);
    return {};
  }

  // The frame as `softrast render` draws it: clear, render, with the headlight of run.cpp.
  double render() {
    auto start = std::chrono::steady_clock::now();
    Camera camera = orbit_.camera();
    options_.light_direction = light_;
    if (spec_.headlight) {
      glm::mat3 camera_to_world = glm::transpose(glm::mat3(camera.view()));
      options_.light_direction = camera_to_world * glm::normalize(light_);
    }
    framebuffer_->clear({0.1f, 0.1f, 0.1f, 1.0f}, 1.0f, options_.state.threads);  // as run.cpp
    render_mesh(*framebuffer_, scene_.mesh, camera, options_);
    return seconds_since(start) * 1000.0;
  }

  Status present() {
    auto start = std::chrono::steady_clock::now();
    render_ms_ = render();
    Framebuffer& fb = *framebuffer_;
    void* pixels = nullptr;
    int pitch = 0;
    if (sdl().LockTexture(texture_, nullptr, &pixels, &pitch) != 0) {
      return sdl_error("cannot update the texture");
    }
    fb.copy_rgba8(static_cast<uint8_t*>(pixels), size_t(pitch));
    sdl().UnlockTexture(texture_);
    sdl().RenderClear(renderer_);
    sdl().RenderCopy(renderer_, texture_, nullptr, nullptr);
    sdl().RenderPresent(renderer_);
    frame_ms_ = seconds_since(start) * 1000.0;
    ++frames_in_interval_;
    if (print_command_) print_command();
    update_title();
    return {};
  }

  // The heads-up line, in the window title.
  void update_title() {
    double elapsed = seconds_since(interval_start_);
    if (elapsed < kTitleIntervalS && !force_title_) return;
    // Continuous: frames actually shown per second. On demand: what the last frame allows.
    double fps = args_.continuous || args_.frames ? frames_in_interval_ / elapsed
                                                  : 1000.0 / std::max(frame_ms_, 1e-3);
    int threads = options_.state.threads > 0
                      ? options_.state.threads
                      : int(std::max(1u, std::thread::hardware_concurrency()));
    char title[512];
    std::snprintf(title, sizeof title,
                  "softrast  %.1f fps  %.2f ms/frame (render %.2f)  %zu triangles  %d threads  "
                  "|  %s%s  %s  cull %s  debug %s",
                  fps, frame_ms_, render_ms_, scene_.mesh.triangle_count(), threads,
                  shader_kind_name(options_.shader), options_.wireframe_overlay ? "+wire" : "",
                  raster_name(), cull_name(), debug_view_name(options_.debug_view));
    sdl().SetWindowTitle(window_, title);
    interval_start_ = std::chrono::steady_clock::now();
    frames_in_interval_ = 0;
    force_title_ = false;
  }

  const char* raster_name() const {
    return options_.state.raster == RasterAlgorithm::kScanline ? "scanline" : "edge";
  }
  const char* cull_name() const {
    switch (options_.state.cull) {
      case CullMode::kBack:
        return "back";
      case CullMode::kFront:
        return "front";
      case CullMode::kNone:
        return "none";
    }
    return "?";
  }

  // The command that renders the frame on screen, on stdout (Enter).
  void print_command() {
    print_command_ = false;
    Camera c = orbit_.camera();
    std::string line = "softrast render";
    for (const std::string& m : args_.models) line += " " + m;
    line += " --size " + std::to_string(framebuffer_->width()) + "x" +
            std::to_string(framebuffer_->height());
    line += " --eye " + vec_text(c.eye) + " --target " + vec_text(c.target) + " --up " +
            vec_text(c.up) + " --fov " + number_text(c.fov_y_degrees) + " --near " +
            number_text(c.near_plane) + " --far " + number_text(c.far_plane);
    line += std::string(" --shader ") + shader_kind_name(options_.shader) + " --cull " +
            cull_name() + " --raster " + raster_name();
    if (options_.wireframe_overlay) line += " --wireframe";
    if (options_.debug_view != DebugView::kNone) {
      line += std::string(" --debug ") + debug_view_name(options_.debug_view);
    }
    if (!spec_.headlight) line += " --light " + vec_text(light_);
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }

  void screenshot() {
    namespace fs = std::filesystem;
    std::string path;
    for (int i = 1; i < 1000 && path.empty(); ++i) {
      char name[64];
      std::snprintf(name, sizeof name, "softrast_view_%03d.png", i);
      if (!fs::exists(name)) path = name;
    }
    Status s = path.empty() ? Status::error("softrast_view_001..999.png all exist")
                            : save_image(path, framebuffer_->to_image());
    if (!spec_.quiet || !s.ok()) {
      std::fprintf(stderr, s.ok() ? "saved %s\n" : "softrast: screenshot: %s\n",
                   s.ok() ? path.c_str() : s.message().c_str());
    }
  }

  // Returns whether the frame must be rendered again.
  bool handle(const SDL_Event& e) {
    switch (e.type) {
      case SDL_QUIT:
        quit_ = true;
        return false;
      case SDL_WINDOWEVENT:
        if (e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) resized_ = true;
        return e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED ||
               e.window.event == SDL_WINDOWEVENT_EXPOSED;
      case SDL_MOUSEMOTION:
        if (e.motion.state & SDL_BUTTON_LMASK) {
          orbit_.rotate(float(e.motion.xrel), float(e.motion.yrel));
          return true;
        }
        if (e.motion.state & (SDL_BUTTON_RMASK | SDL_BUTTON_MMASK)) {
          int w = 0, h = 0;
          sdl().GetWindowSize(window_, &w, &h);  // motion is in window (not drawable) pixels
          orbit_.pan(float(e.motion.xrel), float(e.motion.yrel), h);
          return true;
        }
        return false;
      case SDL_MOUSEWHEEL: {
        float steps = float(e.wheel.y);
        if (e.wheel.direction == SDL_MOUSEWHEEL_FLIPPED) steps = -steps;
        orbit_.zoom(steps);
        return true;
      }
      case SDL_KEYDOWN: {
        bool changed = key(e.key.keysym.sym, (e.key.keysym.mod & KMOD_SHIFT) != 0);
        force_title_ |= changed;  // the heads-up line names the settings: show them at once
        return changed;
      }
      default:
        return false;
    }
  }

  bool key(SDL_Keycode k, bool shift) {
    int step = shift ? -1 : 1;
    switch (k) {
      case SDLK_TAB:
        options_.shader = cycle(kShaderCycle, options_.shader, step);
        return true;
      case SDLK_w:
        options_.wireframe_overlay = !options_.wireframe_overlay;
        return true;
      case SDLK_r:
        options_.state.raster = options_.state.raster == RasterAlgorithm::kScanline
                                    ? RasterAlgorithm::kEdgeEquations
                                    : RasterAlgorithm::kScanline;
        return true;
      case SDLK_c:
        if (options_.state.cull != CullMode::kNone) culled_ = options_.state.cull;
        options_.state.cull = options_.state.cull == CullMode::kNone ? culled_ : CullMode::kNone;
        return true;
      case SDLK_d:
        options_.debug_view = cycle(kDebugCycle, options_.debug_view, step);
        return true;
      case SDLK_HOME:
      case SDLK_0:
        orbit_.reset();
        return true;
      case SDLK_p:
      case SDLK_F12:
        screenshot();
        return false;
      case SDLK_RETURN:
      case SDLK_KP_ENTER:
        print_command_ = true;  // after the next frame is on screen
        return true;
      case SDLK_q:
      case SDLK_ESCAPE:
        quit_ = true;
        return false;
      default:
        return false;
    }
  }

  // --frames: warm-ups, then N frames shown back to back; one JSON line.
  Status benchmark(int frames) {
    for (int i = 0; i < kWarmupFrames; ++i) {
      if (Status s = present(); !s.ok()) return s;
    }
    std::vector<double> frame_ms, render_ms;
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < frames && !quit_; ++i) {
      SDL_Event event;
      while (sdl().PollEvent(&event)) handle(event);
      if (Status s = present(); !s.ok()) return s;
      frame_ms.push_back(frame_ms_);
      render_ms.push_back(render_ms_);
    }
    double total = seconds_since(start);
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v.empty() ? 0.0 : v[v.size() / 2];
    };
    // frame: render + texture upload + present; render: softrast alone (clear and draw).
    std::printf(
        "{\"scene\":\"%s\",\"width\":%d,\"height\":%d,\"frames\":%zu,\"threads\":%d,"
        "\"median_frame_ms\":%.3f,\"median_render_ms\":%.3f,\"fps\":%.1f}\n",
        scene_.demo ? "demo" : "models", framebuffer_->width(), framebuffer_->height(),
        frame_ms.size(), options_.state.threads, median(frame_ms), median(render_ms),
        double(frame_ms.size()) / std::max(total, 1e-9));
    std::fflush(stdout);
    return {};
  }

  const ViewArgs& args_;
  JobSpec spec_;
  ViewScene scene_;
  Orbit orbit_;
  RenderOptions options_;
  glm::vec3 light_;
  CullMode culled_ = CullMode::kBack;

  SDL_Window* window_ = nullptr;
  SDL_Renderer* renderer_ = nullptr;
  SDL_Texture* texture_ = nullptr;
  std::optional<Framebuffer> framebuffer_;

  bool quit_ = false;
  bool resized_ = false;
  bool print_command_ = false;
  bool force_title_ = true;
  double render_ms_ = 0.0, frame_ms_ = 0.0;
  int frames_in_interval_ = 0;
  std::chrono::steady_clock::time_point interval_start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_input_ = std::chrono::steady_clock::now();
};

// Whether the environment variable `name` is set to something (an empty value counts as unset).
bool env_set(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0';
}

const char* env_or_empty(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

// SDL's video drivers that draw to no screen: "offscreen" (EGL without a surface) and "dummy".
bool invisible_driver(const char* driver) {
  if (driver == nullptr) return true;
  const std::string_view name(driver);
  return name == "offscreen" || name == "dummy";
}

// SDL_Init and SDL_Quit around the viewer's lifetime.
struct SdlVideo {
  bool ok = sdl().Init(SDL_INIT_VIDEO) == 0;
  ~SdlVideo() {
    if (ok) sdl().Quit();
  }
};

}  // namespace

int view_command(const ViewArgs& args, void (*report)(std::string message)) {
  ViewArgs checked = args;
  if (!checked.render.size) checked.render.size = kDefaultWindowSize;
  checked.render.frames.reset();  // the viewer's --frames is its own
  Result<JobSpec> spec = interpret(checked.render);
  if (!spec) {
    report(spec.status().message());
    return kExitUsage;
  }
  if (args.frames && (*args.frames < 1 || *args.frames > kMaxFrames)) {
    report("--frames: must be in 1.." + std::to_string(kMaxFrames));
    return kExitUsage;
  }
  // Without a display SDL falls back to its offscreen driver, where the viewer would run unseen
  // until killed; SDL_VIDEODRIVER still picks any driver on purpose (kmsdrm on a console). An
  // empty variable counts as unset (`DISPLAY= softrast view`), as X11 and SDL take it.
  const bool driver_chosen = env_set("SDL_VIDEODRIVER");
  if (!env_set("DISPLAY") && !env_set("WAYLAND_DISPLAY") && !driver_chosen) {
    report("no display to open a window on (DISPLAY and WAYLAND_DISPLAY are not set)");
    return kExitRuntime;
  }
  std::string sdl_error;
  if (!open_sdl(sdl_error)) {
    report(sdl_error);
    return kExitRuntime;
  }
  Result<ViewScene> scene = load_view_scene(args.models, float(spec->width) / float(spec->height));
  if (!scene) {
    report(scene.status().message());
    return kExitRuntime;
  }
  if (spec->auto_shader && has_pbr_materials(scene->mesh)) spec->options.shader = ShaderKind::kPbr;
  if (!spec->quiet) {
    std::fprintf(stderr, "loaded %s: %s\n", scene->source.c_str(),
                 element_counts(scene->mesh).c_str());
  }
  SdlVideo video;
  if (!video.ok) {
    report(std::string("cannot start SDL's video (is there a display?): ") + sdl().GetError());
    return kExitRuntime;
  }
  // A display named but not reachable (no X server at DISPLAY, no Wayland socket): SDL moves on
  // to a driver that shows nothing, and the window would never appear.
  if (!driver_chosen && invisible_driver(sdl().GetCurrentVideoDriver())) {
    report(std::string("no display to open a window on (none answers at DISPLAY=") +
           env_or_empty("DISPLAY") + ", WAYLAND_DISPLAY=" + env_or_empty("WAYLAND_DISPLAY") + ")");
    return kExitRuntime;
  }
  Viewer viewer(checked, std::move(*spec), std::move(*scene));
  Status s = viewer.open();
  if (s.ok()) s = viewer.run();
  if (!s.ok()) {
    report(s.message());
    return kExitRuntime;
  }
  return 0;
}

#endif  // SOFTRAST_HAVE_SDL2

}  // namespace softrast::cli
