// tests/viewer_test.cpp: `softrast view` under a virtual X server (Xvfb). The test starts the
// viewer on a small model in a fixed-size window, drives it with real X input events (xdotool:
// a left drag, wheel notches, a right drag, keys for the shader, wireframe overlay, culling and
// rasterizer), asks it for the `softrast render` command of the frame it shows (Enter), captures
// the window from the X server (xwd), and compares the capture with that command's image.
// Then it resizes the window and compares again, saves a screenshot (P) and quits (Q).
//
// Tolerance: none. The window shows softrast's framebuffer copied 1:1 into a 24-bit X visual, so
// every pixel's red, green and blue must equal the render's (alpha is not shown and not
// compared). On failure the capture and a diff image are written next to the test binary.
//
// Skips, with the reason, where the viewer was not built (no SDL2) or Xvfb, xdotool or xwd is
// missing (apt-get install xvfb xdotool x11-apps; scripts/install-deps.sh installs them).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "softrast/debug_view.hpp"
#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr auto kStartTimeout = std::chrono::seconds(20);

std::optional<std::string> find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    fs::path candidate = fs::path(dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::nullopt;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A child process, ended (SIGTERM, then SIGKILL) and reaped when this goes out of scope.
class Child {
 public:
  // Runs `argv` with `env` added to the environment, stdout to `out` (if given), in `cwd`.
  // `keep_fd` stays open in the child (Xvfb's -displayfd).
  Child(std::vector<std::string> argv, std::vector<std::string> env, const fs::path& out,
        const fs::path& cwd, int keep_fd = -1) {
    // Everything the child needs is built here: after fork() in a process with threads, the
    // child only calls async-signal-safe functions.
    for (char** e = environ; *e; ++e) env.push_back(*e);  // the additions come first and win
    std::vector<char*> args, envp;
    for (std::string& a : argv) args.push_back(a.data());
    for (std::string& e : env) envp.push_back(e.data());
    args.push_back(nullptr);
    envp.push_back(nullptr);
    std::string out_path = out.empty() ? "/dev/null" : out.string();
    std::string dir = cwd.string();
    pid_ = ::fork();
    if (pid_ != 0) return;
    int out_fd = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(out_fd, 1);
    ::dup2(null, 2);
    for (int fd = 3; fd < 1024; ++fd) {
      if (fd != keep_fd) ::close(fd);
    }
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    ::execve(args[0], args.data(), envp.data());
    ::_exit(127);
  }
  ~Child() {
    if (pid_ <= 0 || exited_) return;
    ::kill(pid_, SIGTERM);
    if (!wait_for(std::chrono::seconds(2))) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status_, 0);
    }
  }
  pid_t pid() const { return pid_; }
  // True once the child has ended within `timeout`; its status is then exit_status().
  bool wait_for(std::chrono::milliseconds timeout) {
    auto end = Clock::now() + timeout;
    while (!exited_) {
      if (::waitpid(pid_, &status_, WNOHANG) == pid_) {
        exited_ = true;
        break;
      }
      if (Clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
  }
  int exit_status() const { return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1; }

 private:
  pid_t pid_ = -1;
  int status_ = 0;
  bool exited_ = false;
};

// Runs a shell command, returning its stdout (and whether it exited 0).
std::string run(const std::string& command, bool* ok = nullptr) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  int status = ::pclose(pipe);
  if (ok) *ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  return out;
}

// An XWD file (the X Window Dump format xwd writes) of a 24-bit TrueColor window, decoded
// through its channel masks: 100-byte header of big-endian CARD32 fields, the window name, a
// colour map of 12-byte entries, then rows of 32-bit pixels in the file's byte order.
std::optional<Image> decode_xwd(const std::string& data, std::string& error) {
  auto field = [&](int i) -> uint32_t {
    const auto* p = reinterpret_cast<const unsigned char*>(data.data()) + 4 * i;
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
  };
  if (data.size() < 100) return error = "XWD shorter than its header", std::nullopt;
  uint32_t header = field(0), width = field(4), height = field(5), byte_order = field(7);
  uint32_t bits = field(11), stride = field(12), ncolors = field(19);
  uint32_t masks[3] = {field(14), field(15), field(16)};
  if (bits != 32 || width == 0 || height == 0 || width > 4096 || height > 4096) {
    return error = "unexpected XWD: " + std::to_string(bits) + " bits per pixel", std::nullopt;
  }
  size_t offset = size_t(header) + size_t(ncolors) * 12;
  if (data.size() < offset + size_t(stride) * height) return error = "XWD cut short", std::nullopt;
  Image image{int(width), int(height)};
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const auto* p =
          reinterpret_cast<const unsigned char*>(data.data()) + offset + size_t(y) * stride + 4 * x;
      uint32_t v =
          byte_order == 0
              ? uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24
              : uint32_t(p[3]) | uint32_t(p[2]) << 8 | uint32_t(p[1]) << 16 | uint32_t(p[0]) << 24;
      uint8_t* out = image.pixel(int(x), int(y));
      for (int c = 0; c < 3; ++c) {
        out[c] = uint8_t((v & masks[c]) >> __builtin_ctz(masks[c]));
      }
      out[3] = 255;
    }
  }
  return image;
}

// Pixels whose red, green or blue differ; a diff image (red where they do) at `diff_path`
// unless it is empty.
int count_differences(const Image& got, const Image& want, const fs::path& diff_path) {
  Image diff(want.width, want.height);
  int bad = 0;
  for (int y = 0; y < want.height; ++y) {
    for (int x = 0; x < want.width; ++x) {
      const uint8_t* g = got.pixel(x, y);
      const uint8_t* w = want.pixel(x, y);
      bool differs = g[0] != w[0] || g[1] != w[1] || g[2] != w[2];
      bad += differs;
      uint8_t* d = diff.pixel(x, y);
      for (int c = 0; c < 3; ++c) d[c] = differs ? (c == 0 ? 255 : 0) : uint8_t(w[c] / 3);
      d[3] = 255;
    }
  }
  if (bad && !diff_path.empty()) {  // with the capture beside it
    EXPECT_TRUE(save_image(diff_path.string(), diff).ok());
    fs::path capture = diff_path;
    EXPECT_TRUE(save_image(capture.replace_extension(".capture.png").string(), got).ok());
  }
  return bad;
}

// The camera of a printed `softrast render` command.
struct CameraLine {
  glm::vec3 eye{0.0f}, target{0.0f};
  float distance() const { return glm::distance(eye, target); }
};

glm::vec3 vec3_after(const std::string& line, const std::string& flag) {
  size_t at = line.find(flag + " ");
  EXPECT_NE(at, std::string::npos) << flag << " not in: " << line;
  if (at == std::string::npos) return glm::vec3(0.0f);
  glm::vec3 v(0.0f);
  const char* p = line.c_str() + at + flag.size() + 1;
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    v[i] = std::strtof(p, &end);
    p = end + 1;  // past the comma
  }
  return v;
}

CameraLine camera_of(const std::string& line) {
  return {vec3_after(line, "--eye"), vec3_after(line, "--target")};
}

// A box beside a pyramid on a ground square: asymmetric, so a turned or moved camera shows.
constexpr const char* kModelObj =
    "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"                           // box bottom
    "v -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n"                           // box top
    "v 1.5 0 -0.5\nv 2.5 0 -0.5\nv 2.5 0 0.5\nv 1.5 0 0.5\nv 2 1.6 0\n"  // pyramid
    "v -3 -0.01 -3\nv 4 -0.01 -3\nv 4 -0.01 3\nv -3 -0.01 3\n"           // ground
    "f 1 2 3 4\nf 8 7 6 5\nf 4 3 7 8\nf 2 1 5 6\nf 3 2 6 7\nf 1 4 8 5\n"
    "f 9 10 13\nf 10 11 13\nf 11 12 13\nf 12 9 13\nf 12 11 10 9\n"
    "f 17 16 15 14\n";

class ViewerUnderXvfb : public testing::Test {
 protected:
  void SetUp() override {
#if !defined(SOFTRAST_CLI_PATH) || !defined(SOFTRAST_HAVE_VIEWER)
    GTEST_SKIP() << "softrast was built without the viewer (SDL2, libsdl2-dev, not found)";
#else
    for (const char* tool : {"Xvfb", "xdotool", "xwd"}) {
      if (!find_program(tool)) {
        GTEST_SKIP() << tool << " is not installed (apt-get install xvfb xdotool x11-apps)";
      }
    }
    dir_ = fs::temp_directory_path() / ("softrast_viewer_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "model.obj") << kModelObj;
    start_xvfb();
#endif
  }
  void TearDown() override {
    viewer_.reset();
    xvfb_.reset();
    if (!dir_.empty() && !HasFailure() && !std::getenv("SOFTRAST_KEEP_TEST_FILES")) {
      fs::remove_all(dir_);
    }
  }

  void start_xvfb() {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    xvfb_.emplace(
        std::vector<std::string>{*find_program("Xvfb"), "-displayfd", std::to_string(fds[1]),
                                 "-screen", "0", "640x480x24", "-nolisten", "tcp"},
        std::vector<std::string>{}, fs::path(), dir_, fds[1]);
    ::close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    while (number.find('\n') == std::string::npos &&
           ::poll(&p, 1, int(std::chrono::milliseconds(kStartTimeout).count())) > 0) {
      char c;
      if (::read(fds[0], &c, 1) != 1) break;
      number += c;
    }
    ::close(fds[0]);
    ASSERT_NE(number.find('\n'), std::string::npos) << "Xvfb did not start";
    display_ = ":" + number.substr(0, number.find('\n'));
  }

  std::string x(const std::string& command, bool* ok = nullptr) {
    return run("DISPLAY=" + display_ + " timeout 20 " + command + " 2>&1", ok);
  }

  // The lines the viewer has printed so far.
  std::vector<std::string> printed() {
    std::vector<std::string> lines;
    std::stringstream in(read_file(dir_ / "viewer.out"));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }

  // Presses Enter and returns the `softrast render` command the viewer prints for its frame,
  // which it does once that frame is on screen.
  std::string command_of_frame() {
    size_t before = printed().size();
    x("xdotool key --clearmodifiers Return");
    auto end = Clock::now() + kStartTimeout;
    while (printed().size() == before && Clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::vector<std::string> lines = printed();
    return lines.size() > before ? lines.back() : std::string();
  }

  // Renders `command` (as printed by the viewer) with the CLI; returns the image.
  Image render(const std::string& command, const std::string& name) {
    const std::string prefix = "softrast render ";
    EXPECT_EQ(command.rfind(prefix, 0), 0u) << command;
    fs::path out = dir_ / (name + ".png");
    bool ok = false;
    std::string log = run(std::string(SOFTRAST_CLI_PATH) + " render -q -o " + out.string() + " " +
                              command.substr(prefix.size()) + " 2>&1",
                          &ok);
    EXPECT_TRUE(ok) << log;
    Result<Image> image = load_image(out.string());
    EXPECT_TRUE(image.ok()) << image.status().message();
    return image.ok() ? *image : Image(1, 1);
  }

  // The window as the X server shows it, equal to `want` within a few tries (the server may
  // still be drawing the frame whose command was just printed).
  void expect_window_shows(const Image& want, const std::string& name) {
    std::string error;
    std::optional<Image> got;
    for (int attempt = 0; attempt < 20; ++attempt) {
      got = decode_xwd(x("xwd -silent -id " + window_), error);
      ASSERT_TRUE(got) << error;
      if (got->width == want.width && got->height == want.height &&
          count_differences(*got, want, fs::path()) == 0) {
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_EQ(got->width, want.width);
    ASSERT_EQ(got->height, want.height);
    fs::path diff = fs::current_path() / (name + "_diff.png");
    EXPECT_EQ(count_differences(*got, want, diff), 0) << "diff image: " << diff;
  }

  fs::path dir_;
  std::string display_;
  std::string window_;
  std::optional<Child> xvfb_;
  std::optional<Child> viewer_;
};

TEST_F(ViewerUnderXvfb, WindowShowsTheFrameSoftrastRenderDrawsAfterMouseAndKeys) {
  fs::path model = dir_ / "model.obj";
  // The software SDL renderer: Xvfb has no GPU, and this keeps the copy to the window exact.
  std::vector<std::string> env{"DISPLAY=" + display_, "SDL_VIDEODRIVER=x11",
                               "SDL_RENDER_DRIVER=software"};
#if defined(__SANITIZE_ADDRESS__)
  // SDL unloads the X11 libraries it loaded when it quits, leaving 112 bytes that LeakSanitizer
  // cannot attribute (their module is gone by then, so no suppression matches): leak checking is
  // off for the viewer process alone; AddressSanitizer's other checks stay on.
  env.push_back("ASAN_OPTIONS=detect_leaks=0");
#endif
  viewer_.emplace(std::vector<std::string>{SOFTRAST_CLI_PATH, "view", model.string(), "--size",
                                           "200x150", "--threads", "2", "-q"},
                  env, dir_ / "viewer.out", dir_);
  bool ok = false;
  window_ = x("xdotool search --sync --onlyvisible --pid " + std::to_string(viewer_->pid()), &ok);
  ASSERT_TRUE(ok) << "no viewer window appeared: " << window_;
  window_ = window_.substr(0, window_.find('\n'));
  x("xdotool windowfocus --sync " + window_);
  std::string initial = command_of_frame();
  ASSERT_FALSE(initial.empty()) << "the viewer printed nothing for Enter";

  // Each mouse action changes what it should and keeps the rest: a left drag orbits (the
  // target and the distance stay), two wheel notches up come 0.9^2 as close, a right drag pans
  // (the target moves, the distance stays).
  std::string w = " --window " + window_ + " ";
  x("xdotool mousemove" + w + "100 75 mousedown 1 mousemove" + w + "140 95 mouseup 1");
  CameraLine start = camera_of(initial), orbited = camera_of(command_of_frame());
  EXPECT_GT(glm::distance(orbited.eye, start.eye), 0.1f * start.distance());
  EXPECT_EQ(orbited.target, start.target);
  EXPECT_NEAR(orbited.distance(), start.distance(), 1e-4f * start.distance());
  x("xdotool mousemove" + w + "100 75 click 4 click 4");
  CameraLine zoomed = camera_of(command_of_frame());
  EXPECT_EQ(zoomed.target, start.target);
  EXPECT_NEAR(zoomed.distance(), 0.81f * start.distance(), 1e-4f * start.distance());
  x("xdotool mousemove" + w + "100 75 mousedown 3 mousemove" + w + "90 70 mouseup 3");
  CameraLine panned = camera_of(command_of_frame());
  EXPECT_GT(glm::distance(panned.target, start.target), 0.01f * start.distance());
  EXPECT_NEAR(panned.distance(), zoomed.distance(), 1e-4f * start.distance());

  // Then the shader (Tab: phong -> flat), the wireframe overlay (W), culling on (C: back, the
  // default being none) and edge
  // walking (R): the window shows what `softrast render` draws with the printed command.
  x("xdotool key --clearmodifiers Tab w c r");
  std::string moved = command_of_frame();
  ASSERT_FALSE(moved.empty());
  for (const char* expected :
       {"--size 200x150 ", "--shader flat ", "--cull back ", "--raster scanline", "--wireframe"}) {
    EXPECT_NE(moved.find(expected), std::string::npos) << expected << " not in: " << moved;
  }
  expect_window_shows(render(moved, "moved"), "viewer_moved");

  // D twice: the overdraw debug view, also drawn the same by `softrast render --debug`.
  x("xdotool key --clearmodifiers d d");
  std::string overdraw = command_of_frame();
  EXPECT_NE(overdraw.find("--debug overdraw"), std::string::npos) << overdraw;
  expect_window_shows(render(overdraw, "overdraw"), "viewer_overdraw");
  x("xdotool key --clearmodifiers d d d");  // tiles, cost, triangles ... back to none

  // A resized window gets a framebuffer of its new size.
  x("xdotool windowsize --sync " + window_ + " 240 160");
  std::string resized = command_of_frame();
  EXPECT_NE(resized.find("--size 240x160 "), std::string::npos) << resized;
  Image want = render(resized, "resized");
  expect_window_shows(want, "viewer_resized");

  // P saves the frame shown (through save_image).
  x("xdotool key --clearmodifiers p");

  // Home puts the camera back where it started.
  x("xdotool key --clearmodifiers Home");
  CameraLine reset = camera_of(command_of_frame());
  EXPECT_EQ(reset.target, start.target);
  EXPECT_LT(glm::distance(reset.eye, start.eye), 1e-5f * start.distance());

  // Q quits with status 0; the screenshot is the resized frame.
  x("xdotool key --clearmodifiers q");
  ASSERT_TRUE(viewer_->wait_for(std::chrono::seconds(10))) << "Q did not end the viewer";
  EXPECT_EQ(viewer_->exit_status(), 0);
  Result<Image> shot = load_image((dir_ / "softrast_view_001.png").string());
  ASSERT_TRUE(shot.ok()) << shot.status().message();
  EXPECT_EQ(shot->rgba, want.rgba);
}

#ifdef SOFTRAST_CLI_PATH
// The command line's side of the debug views and the viewer's errors: one line, no window.
TEST(ViewerCli, DebugFlagAndErrors) {
  fs::path dir = fs::temp_directory_path() / ("softrast_viewer_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string cli = SOFTRAST_CLI_PATH;
  bool ok = false;
  fs::path tiles = dir / "tiles.png";
  std::string out =
      run(cli + " render -q --debug tiles --size 130x70 -o " + tiles.string() + " 2>&1", &ok);
  ASSERT_TRUE(ok) << out;
  Result<Image> image = load_image(tiles.string());
  ASSERT_TRUE(image.ok());
  const uint8_t* grid = image->pixel(64, 10);
  const uint8_t* beside = image->pixel(65, 10);
  uint32_t want = kTileGridColor;
  EXPECT_EQ(grid[0] | grid[1] << 8 | grid[2] << 16 | uint32_t(grid[3]) << 24, want);
  EXPECT_NE(beside[0] | beside[1] << 8 | beside[2] << 16 | uint32_t(beside[3]) << 24, want);

  struct Case {
    std::string args;
    int status;
    std::string message;
    std::string display = "-u DISPLAY";  // how the case sets DISPLAY for `env`
  };
  for (const Case& c : {
           Case{"render --debug heat", 2, "--debug: unknown value 'heat'"},
           Case{"view --debug heat", 2, "--debug: unknown value 'heat'"},
           Case{"view --size 0x5", 2, "--size"},
           Case{"view --frames 0", 2, "--frames: must be in"},
           Case{"view", 1, "no display to open a window on"},
           // Set but empty, and naming a display no X server serves: SDL fell back to its
           // offscreen driver, and the viewer ran unseen until killed (status 124 here).
           Case{"view", 1, "no display to open a window on", "DISPLAY="},
           Case{"view", 1, "no display to open a window on", "DISPLAY=:4093"},
       }) {
    std::string command = "cd " + dir.string() + " && env -u WAYLAND_DISPLAY -u SDL_VIDEODRIVER " +
                          c.display + " timeout 20 " + cli + " " + c.args +
                          " 2>&1 >/dev/null; echo \"status $?\"";
    std::string err = run(command);
    EXPECT_NE(err.find("softrast: error: "), std::string::npos) << c.args << ": " << err;
    EXPECT_NE(err.find(c.message), std::string::npos) << c.args << ": " << err;
    if (c.display == "DISPLAY=:4093") {
      // SDL's probe of Wayland may print a line of its own before softrast's one.
      EXPECT_EQ(err.find("softrast: error: "), err.rfind("softrast: error: ")) << err;
    } else {
      EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 2) << c.args << ": " << err;
    }
    EXPECT_NE(err.find("status " + std::to_string(c.status)), std::string::npos) << err;
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}
#endif

}  // namespace
}  // namespace softrast
