// tests/hostile_input_test.cpp: hostile input, as a table, through the built program. Every case
// runs `softrast` in a fresh folder and must end with the expected exit code within its time, its
// peak memory bounded, and either exactly one "softrast: error: " line on stderr (naming what
// was wrong) and no output file, not even a temporary one, or, where the input is valid, a
// correct image. Cases: every byte-offset truncation of a small OBJ (as the model) and of a PNG
// and a TGA (as the texture, and whole as a model); face indices 0, past the end and negative
// past the start; declared sizes of 10^9 pixels and 65535x65535; a texture over each size cap;
// a 1 MiB line; NUL bytes; CRLF and lone CR line ends; NaN, Inf and 1e400; a face of 100,000
// corners; a TGA RLE packet running past the image; an output path that is a folder or cannot
// be written; --size at and past the largest image; SIGINT and SIGTERM during a long render,
// while writing the image and during a batch.
#ifdef SOFTRAST_CLI_PATH
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using Bytes = std::string;

constexpr int kExitOk = 0, kExitRuntime = 1, kExitUsage = 2;

// One row of the table.
struct Case {
  std::string name;
  std::map<std::string, Bytes> files;  // written to the work folder first
  std::vector<std::string> args;       // after the program name
  int exit_code = kExitRuntime;
  std::string message;  // a part of the one error line (or "" for a success)
  double max_seconds = 10.0;
};

struct Outcome {
  int exit_code = -1;
  bool timed_out = false;
  double seconds = 0.0;
  long max_rss_kb = 0;
  std::string err;
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs the program in `dir` (fork and exec, no shell) with stdout and stderr in files beside it;
// kills it after `limit` seconds. `file_bytes`: a limit on the size of the files it writes (as
// `ulimit -f` sets), none when 0.
Outcome run_cli(const fs::path& dir, const fs::path& logs, const std::vector<std::string>& args,
                double limit, rlim_t file_bytes = 0) {
  std::vector<std::string> argv_text = {SOFTRAST_CLI_PATH};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::string out = (logs / "stdout").string(), err = (logs / "stderr").string();
  auto start = std::chrono::steady_clock::now();
  pid_t pid = ::fork();
  if (pid == 0) {
    int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || e < 0 || ::chdir(dir.c_str()) != 0) ::_exit(126);
    ::dup2(o, 1);
    ::dup2(e, 2);
    if (file_bytes != 0) {
      rlimit size{file_bytes, file_bytes};
      if (::setrlimit(RLIMIT_FSIZE, &size) != 0) ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  Outcome r;
  int status = 0;
  rusage usage{};
  for (;;) {
    pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (done == pid) break;
    if (r.seconds > limit && !r.timed_out) {
      r.timed_out = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.max_rss_kb = usage.ru_maxrss;
  r.err = read_file(err);
  return r;
}

// ---------------------------------------------------------------------------------------------
// Files.

// A triangle facing +z with uvs; framed automatically it fills much of a square image.
const Bytes kTriangleObj =
    "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nf 1/1 2/2 3/3\n";

Bytes be32(uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

Bytes png_chunk(const std::string& type, const Bytes& data) {
  Bytes body = type + data;
  uint32_t crc =
      uint32_t(::crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size())));
  return be32(uint32_t(data.size())) + body + be32(crc);
}

// An RGBA8 PNG of `width` x `height` whose IDAT holds `pixels` raw rows (filter byte 0 each),
// deflated; with no pixels given, an IDAT of a few bytes whatever the declared size (a header
// that must be refused before anything is inflated).
Bytes make_png(uint32_t width, uint32_t height, const Bytes* pixels) {
  Bytes ihdr = be32(width) + be32(height) + Bytes("\x08\x06\x00\x00\x00", 5);
  Bytes raw;
  if (pixels) {
    for (uint32_t y = 0; y < height; ++y) {
      raw += '\0';
      raw += pixels->substr(size_t(y) * width * 4, size_t(width) * 4);
    }
  } else {
    raw = Bytes(16, '\0');
  }
  uLongf size = compressBound(uLong(raw.size()));
  Bytes z(size, '\0');
  ::compress(reinterpret_cast<Bytef*>(z.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
             uLong(raw.size()));
  z.resize(size);
  return Bytes("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + png_chunk("IDAT", z) +
         png_chunk("IEND", "");
}

// 2x2 texture: red, green / blue, white (rows top first).
const Bytes kPixels2x2 =
    Bytes("\xff\x00\x00\xff\x00\xff\x00\xff\x00\x00\xff\xff\xff\xff\xff\xff", 16);

// TGA header: type 2 (raw true colour) or 10 (RLE), 32 bits per pixel, top-down rows.
Bytes tga_header(int type, uint16_t width, uint16_t height) {
  Bytes h(18, '\0');
  h[2] = char(type);
  h[12] = char(width & 255), h[13] = char(width >> 8);
  h[14] = char(height & 255), h[15] = char(height >> 8);
  h[16] = 32;
  h[17] = char(0x28);  // 8 alpha bits, top-down
  return h;
}

Bytes make_tga_2x2() {
  Bytes body;
  for (int p = 0; p < 4; ++p) {  // RGBA -> BGRA
    const char* c = kPixels2x2.data() + 4 * p;
    body += {c[2], c[1], c[0], c[3]};
  }
  return tga_header(2, 2, 2) + body;
}

std::vector<std::string> base_args(const std::string& model) {
  return {model, "-q", "--size", "16x16", "--threads", "1", "-o", "out.png"};
}

std::vector<std::string> texture_args(const std::string& texture) {
  std::vector<std::string> a = base_args("tri.obj");
  a.insert(a.end(), {"--shader", "texture", "--filter", "nearest", "--texture", texture});
  return a;
}

// A regular polygon of n corners (radius 1, facing +z) as one face.
Bytes polygon_obj(int n) {
  Bytes obj;
  char line[64];
  for (int i = 0; i < n; ++i) {
    double a = 2.0 * 3.14159265358979 * i / n;
    std::snprintf(line, sizeof line, "v %.6f %.6f 0\n", std::cos(a), std::sin(a));
    obj += line;
  }
  obj += "f";
  for (int i = 1; i <= n; ++i) {
    obj += ' ';
    obj += std::to_string(i);
  }
  return obj + "\n";
}

Case error_case(std::string name, std::map<std::string, Bytes> files, std::vector<std::string> args,
                std::string message, int code = kExitRuntime) {
  return {std::move(name), std::move(files), std::move(args), code, std::move(message)};
}

Case ok_case(std::string name, std::map<std::string, Bytes> files, std::vector<std::string> args) {
  return {std::move(name), std::move(files), std::move(args), kExitOk, ""};
}

// Every prefix of `file`, shorter than it, used where `args` name "cut".
void add_truncations(std::vector<Case>& cases, const std::string& kind, const Bytes& file,
                     const std::vector<std::string>& args, const std::string& message,
                     const std::set<size_t>& valid_lengths = {}) {
  for (size_t n = 0; n < file.size(); ++n) {
    std::string name = kind + " cut to " + std::to_string(n) + " bytes";
    std::map<std::string, Bytes> files = {{"tri.obj", kTriangleObj}, {"cut", file.substr(0, n)}};
    if (valid_lengths.count(n)) {
      cases.push_back(ok_case(name, files, args));
    } else {
      cases.push_back(error_case(name, files, args, message));
    }
  }
}

std::vector<Case> hostile_cases() {
  std::vector<Case> c;
  const Bytes png = make_png(2, 2, &kPixels2x2), tga = make_tga_2x2();
  // Truncations. The OBJ is valid cut after its face's "3" and its "3/3" (the final newline is
  // optional); "3/" is a malformed corner, and every shorter prefix lacks a complete face.
  // Images: every cut is an error.
  add_truncations(c, "OBJ", kTriangleObj, base_args("cut"), "cut",
                  {kTriangleObj.size() - 3, kTriangleObj.size() - 1});
  add_truncations(c, "PNG texture", png, texture_args("cut"), "cut");
  add_truncations(c, "TGA texture", tga, texture_args("cut"), "cut");
  c.push_back(ok_case("whole PNG texture", {{"tri.obj", kTriangleObj}, {"t.png", png}},
                      texture_args("t.png")));
  c.push_back(ok_case("whole TGA texture", {{"tri.obj", kTriangleObj}, {"t.tga", tga}},
                      texture_args("t.tga")));
  c.push_back(error_case("PNG as the model", {{"m.obj", png}}, base_args("m.obj"), "m.obj"));
  c.push_back(error_case("TGA as the model", {{"m.obj", tga}}, base_args("m.obj"), "m.obj"));

  const Bytes verts = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  c.push_back(
      error_case("face index 0", {{"m.obj", verts + "f 0 1 2\n"}}, base_args("m.obj"), "m.obj:4"));
  c.push_back(error_case("face index past the end", {{"m.obj", verts + "f 1 2 4\n"}},
                         base_args("m.obj"), "m.obj:4"));
  c.push_back(error_case("negative face index past the start", {{"m.obj", verts + "f -4 -1 -2\n"}},
                         base_args("m.obj"), "m.obj:4"));
  c.push_back(error_case("face index past 2^32", {{"m.obj", verts + "f 1 2 4294967299\n"}},
                         base_args("m.obj"), "m.obj:4"));
  c.push_back(error_case("NUL byte", {{"m.obj", verts + Bytes("f 1 2 3\0\n", 9)}},
                         base_args("m.obj"), "m.obj"));
  c.push_back(error_case("1 MiB line",
                         {{"m.obj", verts + "#" + Bytes(1 << 20, 'x') + "\nf 1 2 3\n"}},
                         base_args("m.obj"), "m.obj:4"));
  for (const char* number : {"nan", "inf", "-inf", "1e400"}) {
    c.push_back(
        error_case(std::string("vertex coordinate ") + number,
                   {{"m.obj", std::string("v 0 0 ") + number + "\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"}},
                   base_args("m.obj"), "m.obj:1"));
  }
  c.push_back(ok_case("CRLF line ends",
                      {{"m.obj", "v -1 -1 0\r\nv 1 -1 0\r\nv 0 1 0\r\nf 1 2 3\r\n"}},
                      base_args("m.obj")));
  c.push_back(error_case("lone CR line ends (one line, trailing garbage after a vertex)",
                         {{"m.obj", "v -1 -1 0\rv 1 -1 0\rv 0 1 0\rf 1 2 3\r"}}, base_args("m.obj"),
                         "m.obj"));
  Case big_face =
      ok_case("face of 100,000 corners", {{"m.obj", polygon_obj(100000)}}, base_args("m.obj"));
  big_face.max_seconds = 20.0;
  c.push_back(big_face);

  // Declared sizes far beyond the data: refused from the header, before allocating.
  c.push_back(error_case("TGA declaring 40000x25000 (10^9 pixels)",
                         {{"tri.obj", kTriangleObj}, {"t.tga", tga_header(2, 40000, 25000) + "ab"}},
                         texture_args("t.tga"), "t.tga"));
  c.push_back(error_case("PNG declaring 65535x65535",
                         {{"tri.obj", kTriangleObj}, {"t.png", make_png(65535, 65535, nullptr)}},
                         texture_args("t.png"), "t.png"));
  c.push_back(error_case("PNG texture 16385 wide (over kMaxImageSize)",
                         {{"tri.obj", kTriangleObj}, {"t.png", make_png(16385, 1, nullptr)}},
                         texture_args("t.png"), "t.png"));
  c.push_back(error_case("PNG texture 16384x4097 (over kMaxImagePixels)",
                         {{"tri.obj", kTriangleObj}, {"t.png", make_png(16384, 4097, nullptr)}},
                         texture_args("t.png"), "t.png"));
  // RLE: a run packet of 128 pixels in a 2x2 image.
  c.push_back(error_case("TGA RLE packet past the image",
                         {{"tri.obj", kTriangleObj},
                          {"t.tga", tga_header(10, 2, 2) + Bytes("\xff\x01\x02\x03\x04", 5)}},
                         texture_args("t.tga"), "t.tga"));

  // Outputs.
  std::vector<std::string> to_folder = base_args("tri.obj");
  to_folder.back() = "folder.png";
  c.push_back(error_case("output is a folder", {{"tri.obj", kTriangleObj}, {"folder.png/x", "x"}},
                         to_folder, "folder.png"));
  std::vector<std::string> to_file_folder = base_args("tri.obj");
  to_file_folder.back() = "file/out.png";
  c.push_back(error_case("output inside a file", {{"tri.obj", kTriangleObj}, {"file", "x"}},
                         to_file_folder, "file/out.png"));
  std::vector<std::string> unwritable = base_args("tri.obj");
  unwritable.back() = "/proc/softrast_out.png";  // not writable even for root
  c.push_back(error_case("unwritable output folder", {{"tri.obj", kTriangleObj}}, unwritable,
                         "/proc/softrast_out.png"));
  std::vector<std::string> huge = {"tri.obj", "-q", "--size", "16385x16385", "-o", "out.png"};
  c.push_back(
      error_case("--size 16385x16385", {{"tri.obj", kTriangleObj}}, huge, "--size", kExitUsage));
  // The largest size is accepted, but the output folder is checked before 2 GiB are allocated.
  std::vector<std::string> largest = {"tri.obj", "-q", "--size", "16384x16384", "-o", "folder.png"};
  c.push_back(error_case("--size 16384x16384 with a bad output",
                         {{"tri.obj", kTriangleObj}, {"folder.png/x", "x"}}, largest,
                         "folder.png"));
  return c;
}

class HostileInput : public testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_hostile_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    fs::create_directories(root_ / "logs");
  }
  void TearDown() override { fs::remove_all(root_); }

  // Runs one case in a fresh work folder; returns the output image's path if one was written.
  void run(const Case& c, Image* image = nullptr) {
    run_case(c, image);
    report_row(c.name, last_exit_, last_err_);
  }

  // With SOFTRAST_HOSTILE_REPORT=FILE, each case becomes a row of a Markdown table in FILE
  // (docs/hostile_inputs.md is made so): the input, the exit code, the line on stderr.
  static void report_row(const std::string& name, int exit_code, const std::string& err) {
    const char* path = std::getenv("SOFTRAST_HOSTILE_REPORT");
    if (!path) return;
    static bool started = false;
    std::ofstream out(path, started ? std::ios::app : std::ios::trunc);
    if (!started) {
      out << "| input | exit code | stderr |\n|---|---|---|\n";
      started = true;
    }
    auto cell = [](std::string text) {
      while (!text.empty() && text.back() == '\n') text.pop_back();
      std::string escaped;
      for (char ch : text) escaped += ch == '|' ? std::string("\\|") : std::string(1, ch);
      return escaped.empty() ? std::string("(none)") : "`" + escaped + "`";
    };
    out << "| " << cell(name) << " | " << exit_code << " | " << cell(err) << " |\n";
  }

  void run_case(const Case& c, Image* image) {
    SCOPED_TRACE(c.name);
    fs::path work = root_ / "work";
    fs::remove_all(work);
    fs::create_directories(work);
    for (const auto& [name, bytes] : c.files) {
      fs::create_directories((work / name).parent_path());
      std::ofstream(work / name, std::ios::binary) << bytes;
    }
    Outcome r = run_cli(work, root_ / "logs", c.args, c.max_seconds);
    last_exit_ = r.exit_code;
    last_err_ = r.err;
    EXPECT_FALSE(r.timed_out) << "took over " << c.max_seconds << " s";
    EXPECT_EQ(r.exit_code, c.exit_code) << "stderr: " << r.err;
    // Peak memory: the error cases read at most a few MiB (a sanitized build adds its shadow).
    EXPECT_LT(r.max_rss_kb, 400 * 1024) << "peak memory " << r.max_rss_kb << " KiB";
    bool written = fs::exists(work / "out.png");
    for (const auto& entry : fs::directory_iterator(work)) {
      std::string name = entry.path().filename().string();
      EXPECT_EQ(name.find(".tmp."), std::string::npos) << "temporary file left: " << name;
    }
    if (c.exit_code == kExitOk) {
      EXPECT_EQ(r.err, "");
      ASSERT_TRUE(written) << "no image written";
      Result<Image> out = load_image((work / "out.png").string());
      ASSERT_TRUE(out.ok()) << out.status().message();
      EXPECT_EQ(out->width, 16);
      EXPECT_EQ(out->height, 16);
      if (image) *image = *out;
    } else {
      EXPECT_FALSE(written) << "an output file was written";
      ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr: " << r.err;
      EXPECT_EQ(r.err.rfind("softrast: error: ", 0), 0u) << r.err;
      EXPECT_NE(r.err.find(c.message), std::string::npos)
          << "the error does not name '" << c.message << "': " << r.err;
    }
  }

  fs::path root_;
  int last_exit_ = 0;
  std::string last_err_;
};

TEST_F(HostileInput, EveryCaseFailsCleanlyOrRendersCorrectly) {
  std::vector<Case> cases = hostile_cases();
  ASSERT_GT(cases.size(), 150u);
  for (const Case& c : cases) run(c);
  RecordProperty("cases", int(cases.size()));
  std::printf("hostile inputs: %zu cases\n", cases.size());
}

// The valid inputs render what they describe: the CRLF OBJ gives the LF OBJ's image byte for
// byte; the 100,000-corner disc covers the image's centre and leaves its corners to the clear
// colour; the textured triangle shows the 2x2 texture's texels, the same from PNG and TGA.
TEST_F(HostileInput, ValidInputsRenderTheirContent) {
  std::vector<std::string> args = base_args("m.obj");
  args.insert(args.end(), {"--shader", "flat", "--color", "1,0,0"});
  Image lf, crlf, disc;
  run(ok_case("LF", {{"m.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n"}}, args), &lf);
  run(ok_case("CRLF", {{"m.obj", "v -1 -1 0\r\nv 1 -1 0\r\nv 0 1 0\r\nf 1 2 3\r\n"}}, args), &crlf);
  EXPECT_EQ(lf.rgba, crlf.rgba);
  Case big = ok_case("disc", {{"m.obj", polygon_obj(100000)}}, args);
  big.max_seconds = 20.0;
  run(big, &disc);
  ASSERT_EQ(disc.width, 16);
  auto disc_red = [&](int x, int y) {
    const uint8_t* p = disc.pixel(x, y);
    return p[0] == 255 && p[1] == 0 && p[2] == 0;
  };
  EXPECT_TRUE(disc_red(8, 8));
  EXPECT_FALSE(disc_red(0, 0));
  EXPECT_FALSE(disc_red(15, 15));

  Image from_png, from_tga;
  run(ok_case("PNG", {{"tri.obj", kTriangleObj}, {"t.png", make_png(2, 2, &kPixels2x2)}},
              texture_args("t.png")),
      &from_png);
  run(ok_case("TGA", {{"tri.obj", kTriangleObj}, {"t.tga", make_tga_2x2()}}, texture_args("t.tga")),
      &from_tga);
  EXPECT_EQ(from_png.rgba, from_tga.rgba);
  // Nearest filtering: the triangle shows the texture's pure texels, blue and white at its base
  // (v = 0 is the file's last row), red and green towards its apex.
  int red = 0, green = 0, blue = 0;
  for (int i = 0; i < 16 * 16; ++i) {
    const uint8_t* p = &from_png.rgba[size_t(i) * 4];
    red += p[0] == 255 && p[1] == 0 && p[2] == 0;
    green += p[0] == 0 && p[1] == 255 && p[2] == 0;
    blue += p[0] == 0 && p[1] == 0 && p[2] == 255;
  }
  EXPECT_GT(blue, 5);
  EXPECT_GT(red + green, 2);
}

// ---------------------------------------------------------------------------------------------
// SIGINT and SIGTERM while the program works: during a long render, while the image is being
// written (the test hook SOFTRAST_TEST_SLOW_WRITE_MS slows the write down) and during a batch.
// Each must end the program within kSignalSeconds of the signal, by the signal (a shell sees 130
// or 143), with one error line naming it, and leave no temporary file and no partial output: an
// output that exists is a complete image.

constexpr double kSignalSeconds = 5.0;

// Whether process `pid` has installed a handler for `signal` (bit signal - 1 of SigCgt).
bool catches(pid_t pid, int signal) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigCgt:", 0) == 0) {
      uint64_t mask = std::stoull(line.substr(7), nullptr, 16);
      return (mask >> (signal - 1)) & 1;
    }
  }
  return false;
}

bool has_temporary_file(const fs::path& dir) {
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

struct SignalCase {
  std::string name;
  std::map<std::string, Bytes> files;
  std::vector<std::string> args;
  std::vector<std::string> env;               // NAME=VALUE added to the environment
  std::function<bool(const fs::path&)> busy;  // true once the program is where the case wants it
};

struct SignalOutcome {
  Outcome outcome;
  bool signalled = false;
  double seconds_after_signal = 0.0;
};

// Runs the program, sends `signal` once it catches it and `busy` holds, waits for its end (killed
// after kSignalSeconds, or after 120 s if it never got busy).
SignalOutcome run_and_signal(const fs::path& dir, const fs::path& logs, const SignalCase& c,
                             int signal) {
  std::vector<std::string> argv_text = {SOFTRAST_CLI_PATH};
  argv_text.insert(argv_text.end(), c.args.begin(), c.args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e; ++e) env_text.push_back(*e);
  env_text.insert(env_text.end(), c.env.begin(), c.env.end());
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::string out = (logs / "stdout").string(), err = (logs / "stderr").string();
  auto start = std::chrono::steady_clock::now();
  pid_t pid = ::fork();
  if (pid == 0) {
    int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || e < 0 || ::chdir(dir.c_str()) != 0) ::_exit(126);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  SignalOutcome r;
  std::chrono::steady_clock::time_point sent;
  int status = 0;
  rusage usage{};
  for (;;) {
    pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    auto now = std::chrono::steady_clock::now();
    r.outcome.seconds = std::chrono::duration<double>(now - start).count();
    if (done == pid) break;
    if (!r.signalled && catches(pid, signal) && c.busy(dir)) {
      ::kill(pid, signal);
      r.signalled = true;
      sent = now;
    }
    double waited = r.signalled ? std::chrono::duration<double>(now - sent).count() : 0.0;
    if (!r.outcome.timed_out &&
        (waited > kSignalSeconds || (!r.signalled && r.outcome.seconds > 120.0))) {
      r.outcome.timed_out = true;
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  if (r.signalled) {
    r.seconds_after_signal =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  }
  r.outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.outcome.max_rss_kb = usage.ru_maxrss;
  r.outcome.err = read_file(err);
  return r;
}

std::vector<SignalCase> signal_cases() {
  std::vector<SignalCase> c;
  auto running = [](const fs::path&) { return true; };
  // A long render: 100,000 timed frames of 1024x1024, then out.png.
  c.push_back({"long render",
               {{"tri.obj", kTriangleObj}},
               {"tri.obj", "-q", "--size", "1024x1024", "--frames", "100000", "-o", "out.png"},
               {},
               running});
  // The image being written: a second after each 64 KiB of the TGA (RLE, about 180 KiB).
  c.push_back({"writing the image",
               {{"tri.obj", kTriangleObj}},
               {"tri.obj", "-q", "--size", "1024x1024", "-o", "out.tga"},
               {"SOFTRAST_TEST_SLOW_WRITE_MS=1000"},
               [](const fs::path& dir) { return has_temporary_file(dir); }});
  // A batch of 400 renders of 512x512, interrupted once the first image exists.
  std::string jobs;
  for (int i = 0; i < 400; ++i) {
    jobs += "{\"model\": \"tri.obj\", \"output\": \"out/" + std::to_string(i) +
            ".png\", \"size\": \"512x512\", \"threads\": 1}\n";
  }
  c.push_back({"a batch",
               {{"tri.obj", kTriangleObj}, {"jobs.jsonl", jobs}},
               {"batch", "jobs.jsonl", "-q"},
               {},
               [](const fs::path& dir) { return fs::exists(dir / "out" / "0.png"); }});
  return c;
}

const char* signal_name(int signal) {
  return signal == SIGINT ? "SIGINT" : signal == SIGHUP ? "SIGHUP" : "SIGTERM";
}

TEST_F(HostileInput, SignalsEndTheProgramCleanly) {
  for (const SignalCase& c : signal_cases()) {
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
      std::string name = std::string(signal_name(signal)) + " during " + c.name;
      SCOPED_TRACE(name);
      fs::path work = root_ / "work";
      fs::remove_all(work);
      fs::create_directories(work);
      for (const auto& [file, bytes] : c.files)
        std::ofstream(work / file, std::ios::binary) << bytes;
      SignalOutcome r = run_and_signal(work, root_ / "logs", c, signal);
      ASSERT_TRUE(r.signalled) << "the program ended before it was busy: " << r.outcome.err;
      EXPECT_FALSE(r.outcome.timed_out)
          << "still running " << kSignalSeconds << " s after the signal";
      EXPECT_LT(r.seconds_after_signal, kSignalSeconds);
      EXPECT_EQ(r.outcome.exit_code, 128 + signal) << "stderr: " << r.outcome.err;
      ASSERT_EQ(std::count(r.outcome.err.begin(), r.outcome.err.end(), '\n'), 1)
          << "stderr: " << r.outcome.err;
      EXPECT_EQ(r.outcome.err.rfind("softrast: error: ", 0), 0u) << r.outcome.err;
      EXPECT_NE(r.outcome.err.find(signal_name(signal)), std::string::npos) << r.outcome.err;
      EXPECT_FALSE(has_temporary_file(work)) << "a temporary file is left";
      EXPECT_FALSE(fs::exists(work / "out.png"));
      EXPECT_FALSE(fs::exists(work / "out.tga"));
      // Batch outputs that exist are whole images.
      if (fs::exists(work / "out")) {
        int complete = 0;
        for (const auto& entry : fs::directory_iterator(work / "out")) {
          Result<Image> image = load_image(entry.path().string());
          EXPECT_TRUE(image.ok() && image->width == 512)
              << entry.path() << " is not a complete image";
          complete += image.ok();
        }
        EXPECT_GE(complete, 1);
        EXPECT_LT(complete, 400) << "the batch was not interrupted";
      }
      report_row(name, r.outcome.exit_code, r.outcome.err);
      std::printf("hostile signal: %s: exit %d after %.2f s, %s", name.c_str(), r.outcome.exit_code,
                  r.seconds_after_signal, r.outcome.err.c_str());
    }
  }
}

// Past a file-size limit (ulimit -f, a quota) the image's write fails as on a full disk: exit 1,
// one error line that says why, no temporary file and no output. (By default the limit's signal,
// SIGXFSZ, killed the program and left the temporary file.)
TEST_F(HostileInput, AFileSizeLimitFailsTheWriteCleanly) {
  constexpr rlim_t kLimit = 16 * 1024;
  for (const std::string name : {"out.png", "out.tga", "out.jpg"}) {
    SCOPED_TRACE(name);
    fs::path work = root_ / "work";
    fs::remove_all(work);
    fs::create_directories(work);
    // The demo scene at 1024x1024: every format's file is far above the limit.
    Outcome r =
        run_cli(work, root_ / "logs", {"-q", "--size", "1024x1024", "-o", name}, 60.0, kLimit);
    EXPECT_FALSE(r.timed_out);
    EXPECT_EQ(r.exit_code, 1) << "stderr: " << r.err;
    ASSERT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr: " << r.err;
    EXPECT_EQ(r.err.rfind("softrast: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(std::strerror(EFBIG)), std::string::npos) << r.err;
    EXPECT_FALSE(has_temporary_file(work)) << "a temporary file is left";
    EXPECT_FALSE(fs::exists(work / name));
    // Without the limit the same image is written (the case is about the limit alone).
    Outcome whole = run_cli(work, root_ / "logs", {"-q", "--size", "1024x1024", "-o", name}, 60.0);
    EXPECT_EQ(whole.exit_code, 0) << whole.err;
    EXPECT_GT(fs::file_size(work / name), 4 * kLimit);
  }
}

}  // namespace
}  // namespace softrast
#endif  // SOFTRAST_CLI_PATH
