// fuzz/obj_fuzz.cpp: load_obj on arbitrary bytes. The input is up to three files, separated by
// the lines "#--mtl--" and "#--tex--": model.obj, model.mtl and tex.png, written to a private
// temporary folder (load_obj reads files only), so an OBJ saying `mtllib model.mtl` and an MTL
// saying `map_Kd tex.png` reach the material parser and the image decoder through the paths a
// user's files take.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz_entries.hpp"
#include "mesh_checks.hpp"
#include "softrast/mesh.hpp"

namespace softrast::fuzz {
namespace {

namespace fs = std::filesystem;

// One folder per process, made on first use and removed at exit.
struct TempFolder {
  fs::path path;
  TempFolder() {
    const char* base = std::getenv("TMPDIR");
    fs::path root = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::path(base ? base : "/tmp");
    path = root / ("softrast_fuzz_obj." + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

// The part of `rest` before `separator` (all of it when absent); `rest` keeps what follows.
std::string_view take_until(std::string_view& rest, std::string_view separator) {
  size_t at = rest.find(separator);
  std::string_view part = rest.substr(0, at);
  rest = at == std::string_view::npos ? std::string_view() : rest.substr(at + separator.size());
  return part;
}

}  // namespace

int fuzz_obj(const uint8_t* data, size_t size) {
  static TempFolder folder;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::string_view obj = take_until(rest, "\n#--mtl--\n");
  std::string_view mtl = take_until(rest, "\n#--tex--\n");
  write_file(folder.path / "model.obj", obj);
  write_file(folder.path / "model.mtl", mtl);
  write_file(folder.path / "tex.png", rest);
  Result<Mesh> mesh = load_obj((folder.path / "model.obj").string());
  if (!mesh) {
    const std::string& m = mesh.status().message();
    SOFTRAST_FUZZ_REQUIRE(!m.empty(), "load_obj failed without a message");
    // "path: reason" or "path:line: reason", the path as the user or the file gave it (the OBJ,
    // or an MTL or texture path from it, relative to its folder or absolute: "mtllib /").
    size_t colon = m.find(':');
    SOFTRAST_FUZZ_REQUIRE(
        colon != std::string::npos && colon > 0 && m.find(": ") != std::string::npos,
        "error does not start with a file name: " + m);
    return 0;
  }
  check_mesh(*mesh);
  return 0;
}

}  // namespace softrast::fuzz
