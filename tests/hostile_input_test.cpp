// tests/hostile_input_test.cpp: hostile input, as a table, through the built program. Every case
// runs `softrast` in a fresh folder and must end with the expected exit code within its time, its
// peak memory bounded, and either exactly one "softrast: error: " line on stderr (naming what
// was wrong) and no output file, not even a temporary one, or, where the input is valid, a
// correct image. Cases: every byte-offset truncation of a small OBJ (as the model) and of a PNG
// and a TGA (as the texture, and whole as a model); face indices 0, past the end and negative
// past the start; declared sizes of 10^9 pixels and 65535x65535; a texture over each size cap;
// a 1 MiB line; NUL bytes; CRLF and lone CR line ends; NaN, Inf and 1e400; a face of 100,000
// corners; a TGA RLE packet running past the image; an output path that is a folder or cannot
// be written; --size at and past the largest image.
#ifdef SOFTRAST_CLI_PATH
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
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
// kills it after `limit` seconds.
Outcome run_cli(const fs::path& dir, const fs::path& logs, const std::vector<std::string>& args,
                double limit) {
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
    SCOPED_TRACE(c.name);
    fs::path work = root_ / "work";
    fs::remove_all(work);
    fs::create_directories(work);
    for (const auto& [name, bytes] : c.files) {
      fs::create_directories((work / name).parent_path());
      std::ofstream(work / name, std::ios::binary) << bytes;
    }
    Outcome r = run_cli(work, root_ / "logs", c.args, c.max_seconds);
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

}  // namespace
}  // namespace softrast
#endif  // SOFTRAST_CLI_PATH
