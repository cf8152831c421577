// io/model_loader.cpp: load_model, which tells OBJ, PLY, STL and glTF apart by their contents and
// says what a file that is none of them looks like; load_ply and load_stl.

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/image_decode.hpp"
#include "io/model_formats.hpp"
#include "io/text_lines.hpp"
#include "softrast/mesh.hpp"

namespace softrast {
namespace {

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

// Bytes looked at to tell the format: every signature below, and a header's first words.
constexpr size_t kSniffBytes = 512;

struct Signature {
  std::string_view bytes;
  const char* what;
};

// Files people give as a model by mistake, by their first bytes.
constexpr std::array<Signature, 9> kNotModels = {{
    {"\x89PNG\r\n\x1a\n", "a PNG image"},
    {"\xff\xd8\xff", "a JPEG image"},
    {"GIF8", "a GIF image"},
    {"PK\x03\x04", "a ZIP archive"},
    {"%PDF", "a PDF document"},
    {"\x1f\x8b", "a gzip-compressed file"},
    {"\x7f"
     "ELF",
     "a program (ELF)"},
    {"Kaydara FBX Binary", "an FBX scene"},
    {"BM", "a BMP image"},
}};

bool starts_with(std::string_view data, std::string_view prefix) {
  return data.size() >= prefix.size() && data.substr(0, prefix.size()) == prefix;
}

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// A glTF (JSON) file starts with '{' and names its "asset" near the top.
bool looks_like_gltf(std::string_view head) {
  size_t first = head.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && head[first] == '{' &&
         head.find("\"asset\"") != std::string_view::npos;
}

// What the first bytes say the file is, if it is something other than a model. A BMP's "BM" is
// also how an OBJ could start in theory, so it needs the rest of its 14-byte header to agree.
const char* not_a_model(std::string_view head) {
  for (const Signature& s : kNotModels) {
    if (!starts_with(head, s.bytes)) continue;
    if (s.bytes == "BM" && (head.size() < 14 || head[6] || head[7] || head[8] || head[9])) continue;
    return s.what;
  }
  // TGA has no signature; its strict header test never passes on text (the second byte, the
  // colour map type, must be 0 or 1).
  if (detail::is_tga(reinterpret_cast<const uint8_t*>(head.data()), head.size())) {
    return "a TGA image";
  }
  return nullptr;
}

// Other 3D formats, by their usual extension: a file of one of them (read as OBJ, the fallback)
// failed with "no faces" or "NUL byte: not a text file", which did not say what was wrong.
struct OtherFormat {
  std::string_view extension;
  const char* what;
};
constexpr std::array<OtherFormat, 37> kOtherFormats = {{
    {".dae", "a COLLADA scene"},
    {".fbx", "an FBX scene"},
    {".3ds", "a 3D Studio scene"},
    {".max", "a 3ds Max scene"},
    {".blend", "a Blender scene"},
    {".ma", "a Maya scene"},
    {".mb", "a Maya scene"},
    {".c4d", "a Cinema 4D scene"},
    {".lwo", "a LightWave object"},
    {".lws", "a LightWave scene"},
    {".lxo", "a modo scene"},
    {".x", "a DirectX model"},
    {".ase", "a 3ds Max ASCII scene"},
    {".ac", "an AC3D model"},
    {".ms3d", "a MilkShape model"},
    {".md2", "a Quake II model"},
    {".md3", "a Quake III model"},
    {".md5mesh", "a Doom 3 model"},
    {".mdl", "a Quake or Half-Life model"},
    {".off", "an OFF mesh"},
    {".3mf", "a 3MF package"},
    {".amf", "an AMF model"},
    {".usd", "a USD scene"},
    {".usda", "a USD scene"},
    {".usdc", "a USD scene"},
    {".usdz", "a USD package"},
    {".x3d", "an X3D scene"},
    {".wrl", "a VRML scene"},
    {".ifc", "an IFC building model"},
    {".dxf", "a DXF drawing"},
    {".step", "a STEP CAD model"},
    {".stp", "a STEP CAD model"},
    {".iges", "an IGES CAD model"},
    {".igs", "an IGES CAD model"},
    {".skp", "a SketchUp model"},
    {".abc", "an Alembic cache"},
    {".bvh", "a motion capture (BVH) file"},
}};

const char* other_format(const std::string& extension) {
  for (const OtherFormat& f : kOtherFormats) {
    if (f.extension == extension) return f.what;
  }
  return nullptr;
}

enum class Kind { kObj, kPly, kBinaryStl, kAsciiStl };

bool starts_solid(std::string_view head) {
  size_t first = head.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return false;
  std::string_view rest = head.substr(first);
  if (rest.size() < 5) return false;
  std::string first_word(rest.substr(0, 5));
  for (char& c : first_word) c = char(std::tolower((unsigned char)c));  // "SOLID" too
  return first_word == "solid" && (rest.size() == 5 || std::isspace((unsigned char)rest[5]));
}

// The first kSniffBytes of the file and its size; for a pipe or device (no size, -1) nothing
// is read.
Status sniff(const std::string& path, std::string& head, int64_t& size) {
  // A pipe or device is not opened here at all: opening a FIFO pairs with its writer, and what
  // the writer sent would be lost to the loader's own open (which would then wait forever).
  struct stat named {};
  if (::stat(path.c_str(), &named) == 0 && !S_ISREG(named.st_mode) && !S_ISDIR(named.st_mode)) {
    size = -1;
    return {};
  }
  detail::FilePtr f;
  if (Status s = detail::open_text_file(path, {kMaxObjFileBytes, "model files"}, f); !s.ok()) {
    return s;
  }
  struct stat info {};
  size = fstat(fileno(f.get()), &info) == 0 && S_ISREG(info.st_mode) ? int64_t(info.st_size) : -1;
  if (size < 0) return {};  // a pipe or device: what is read here would be lost to the loader
  head.resize(kSniffBytes);
  head.resize(std::fread(head.data(), 1, head.size(), f.get()));
  if (std::ferror(f.get())) return fail(path, std::string("cannot read: ") + std::strerror(errno));
  return {};
}

Result<Mesh> load_whole(const std::string& path, Kind kind) {
  std::vector<char> bytes;
  const char* limit_kind = kind == Kind::kPly ? "PLY files" : "STL files";
  if (Status s = detail::read_whole_file(path, kMaxObjFileBytes, limit_kind, bytes); !s.ok()) {
    return s;
  }
  if (kind == Kind::kPly) return detail::parse_ply(bytes.data(), bytes.size(), path);
  bool binary = kind == Kind::kBinaryStl;
  return detail::parse_stl(bytes.data(), bytes.size(), binary, path);
}

}  // namespace

namespace detail {

Status read_whole_file(const std::string& path, int64_t max_bytes, const char* kind,
                       std::vector<char>& bytes) {
  FilePtr f;
  TextLimit limit{max_bytes, kind};
  if (Status s = open_text_file(path, limit, f); !s.ok()) return s;
  struct stat info {};
  if (fstat(fileno(f.get()), &info) == 0 && S_ISREG(info.st_mode)) {
    bytes.reserve(size_t(info.st_size));
  }
  char block[1 << 16];
  for (;;) {
    size_t n = std::fread(block, 1, sizeof block, f.get());
    if (n == 0) break;
    if (int64_t(bytes.size() + n) > max_bytes) return text_too_large(path, limit);
    bytes.insert(bytes.end(), block, block + n);
  }
  if (std::ferror(f.get())) return fail(path, std::string("cannot read: ") + std::strerror(errno));
  return {};
}

}  // namespace detail

Result<Mesh> load_ply(const std::string& path) {
  return load_whole(path, Kind::kPly);
}

Result<Mesh> load_stl(const std::string& path) {
  std::vector<char> bytes;
  if (Status s = detail::read_whole_file(path, kMaxObjFileBytes, "STL files", bytes); !s.ok()) {
    return s;
  }
  bool binary = detail::is_binary_stl(bytes.data(), bytes.size()) ||
                !starts_solid(std::string_view(bytes.data(), std::min(bytes.size(), kSniffBytes)));
  return detail::parse_stl(bytes.data(), bytes.size(), binary, path);
}

Result<Mesh> load_model(const std::string& path) {
  std::string head;
  int64_t size = -1;
  if (Status s = sniff(path, head, size); !s.ok()) return s;
  if (size < 0) return load_obj(path);  // pipes and devices are read once, as OBJ
  if (starts_with(head, "ply\n") || starts_with(head, "ply\r\n")) return load_ply(path);
  // The size decides before "solid": some binary STL writers begin their header with it.
  if (size >= 84 && head.size() >= 84 && detail::is_binary_stl(head.data(), size_t(size))) {
    return load_whole(path, Kind::kBinaryStl);
  }
  if (starts_solid(head)) return load_whole(path, Kind::kAsciiStl);
  std::string ext = lowercase_extension(path);
  if (starts_with(head, "glTF") || looks_like_gltf(head) || ext == ".gltf" || ext == ".glb") {
    return load_gltf(path);  // a .gltf or .glb name whose content is not one says why
  }
  if (const char* what = not_a_model(head)) {
    return fail(path, std::string("this is ") + what +
                          ", not a model (softrast reads OBJ, PLY, STL and glTF)");
  }
  if (const char* what = other_format(ext)) {
    return fail(path, std::string("this is ") + what + " (" + ext +
                          "), a format softrast does not read (it reads OBJ, PLY, STL and glTF "
                          "2.0): export the model as one of those");
  }
  if (ext == ".stl") return load_stl(path);  // says why it is not one
  if (ext == ".ply") return load_ply(path);
  return load_obj(path);
}

}  // namespace softrast
