// io/gltf_document.cpp: read_gltf_document. Checks what TinyGLTF 2.7 takes on trust before handing
// it the bytes: the GLB chunk framing (its own check lets the BIN chunk run 8 bytes past the
// file), data URIs (a malformed one became a file name), the size of each external buffer, the
// byte ranges of images in bufferViews (read unchecked), and extensionsRequired (ignored). Then
// TinyGLTF parses, with file reads and image decoding through softrast's own bounded functions.

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <nlohmann/json.hpp>

#include "io/gltf_document.hpp"
#include "io/model_formats.hpp"

namespace softrast::detail {
namespace {

using json = nlohmann::json;

constexpr std::array<std::string_view, 3> kSupportedExtensions = {
    "KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_mesh_quantization"};

// The data-URI media types TinyGLTF decodes (its IsDataURI); others it would take for file names.
constexpr std::array<std::string_view, 7> kDataUriTypes = {"application/octet-stream",
                                                           "application/gltf-buffer",
                                                           "text/plain",
                                                           "image/png",
                                                           "image/jpeg",
                                                           "image/bmp",
                                                           "image/gif"};

Status fail(const std::string& name, const std::string& reason) {
  return Status::error(name + ": " + reason);
}

// At most 80 characters of `s`, for quoting file content in a message.
std::string excerpt(std::string_view s) {
  std::string out(s.substr(0, 80));
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return "'" + out + (s.size() > 80 ? "...'" : "'");
}

uint32_t le32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The GLB container: 12-byte header, a JSON chunk, optionally a BIN chunk, each chunk 8 bytes of
// length and type before its data, all inside the length the header declares.
struct GlbChunks {
  uint32_t length = 0;  // the whole GLB, as declared
  std::string_view json;
  uint64_t bin_size = 0;
  bool has_bin = false;
};

Result<GlbChunks> read_glb_framing(const uint8_t* data, size_t size, const std::string& name) {
  if (size < 20) return fail(name, "truncated GLB: " + std::to_string(size) + " bytes");
  GlbChunks g;
  uint32_t version = le32(data + 4);
  g.length = le32(data + 8);
  if (version == 1) {
    return fail(name, "GLB version 1, a glTF 1.0 file; softrast reads glTF 2.0: convert it first");
  }
  if (version != 2) return fail(name, "GLB version " + std::to_string(version) + " (expected 2)");
  if (g.length > size) {
    return fail(name, "truncated GLB: the header declares " + std::to_string(g.length) +
                          " bytes, the file has " + std::to_string(size));
  }
  uint64_t json_length = le32(data + 12);
  if (le32(data + 16) != 0x4E4F534Au) return fail(name, "GLB: the first chunk is not JSON");
  if (json_length == 0 || 20 + json_length > g.length) {
    return fail(name, "GLB: the JSON chunk (" + std::to_string(json_length) +
                          " bytes) does not fit in the file's " + std::to_string(g.length));
  }
  g.json = std::string_view(reinterpret_cast<const char*>(data + 20), size_t(json_length));
  uint64_t next = 20 + json_length;
  if (next == g.length) return g;
  if (next + 8 > g.length) return fail(name, "GLB: truncated chunk header after the JSON chunk");
  g.bin_size = le32(data + next);
  if (le32(data + next + 4) != 0x004E4942u) return fail(name, "GLB: the second chunk is not BIN");
  if (next + 8 + g.bin_size > g.length) {
    return fail(name, "GLB: the BIN chunk (" + std::to_string(g.bin_size) +
                          " bytes) runs past the end of the file");
  }
  g.has_bin = true;
  return g;
}

bool is_base64_payload(std::string_view s) {
  if (s.size() % 4 != 0) return false;
  size_t padding = 0;
  while (padding < 2 && padding < s.size() && s[s.size() - 1 - padding] == '=') ++padding;
  for (size_t i = 0; i + padding < s.size(); ++i) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    if (!(std::isalnum(c) || c == '+' || c == '/')) return false;
  }
  return true;
}

// %XX and '+' decoded as TinyGLTF's urldecode does, so both open the same file.
std::string url_decoded(std::string_view uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) &&
               std::isxdigit((unsigned char)uri[i + 2])) {
      out += char(std::stoi(std::string(uri.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// A non-negative integer member (default `fallback` when absent), or an error.
Result<uint64_t> unsigned_member(const json& o, const char* key, uint64_t fallback,
                                 const std::string& what) {
  auto it = o.find(key);
  if (it == o.end()) return fallback;
  if (it->is_number_unsigned()) return it->get<uint64_t>();
  if (it->is_number_integer() && it->get<int64_t>() >= 0) return uint64_t(it->get<int64_t>());
  return Status::error(what + ": '" + key + "' is not a non-negative integer");
}

Status check_data_uri(std::string_view uri, uint64_t byte_length, const std::string& what) {
  size_t comma = uri.find(',');
  std::string_view header = uri.substr(5, comma == std::string_view::npos ? 0 : comma - 5);
  constexpr std::string_view kBase64 = ";base64";
  bool base64 = comma != std::string_view::npos && header.size() >= kBase64.size() &&
                header.substr(header.size() - kBase64.size()) == kBase64;
  if (!base64 || !is_base64_payload(uri.substr(comma + 1))) {
    return Status::error(what + ": the data URI is not base64 (" + excerpt(uri) + ")");
  }
  std::string_view type = header.substr(0, header.size() - kBase64.size());
  if (std::find(kDataUriTypes.begin(), kDataUriTypes.end(), type) == kDataUriTypes.end()) {
    return Status::error(what + ": data URI of unsupported type " + excerpt(type));
  }
  std::string_view payload = uri.substr(comma + 1);
  uint64_t decoded = payload.size() / 4 * 3;
  if (!payload.empty())
    decoded -= (payload.back() == '=') + (payload.size() > 1 && payload[payload.size() - 2] == '=');
  if (byte_length != ~uint64_t(0) && decoded != byte_length) {
    return Status::error(what + ": the data URI holds " + std::to_string(decoded) +
                         " bytes, byteLength says " + std::to_string(byte_length));
  }
  return {};
}

Status check_buffer(const json& b, size_t index, const GlbChunks* glb, const std::string& base_dir,
                    std::vector<uint64_t>& lengths) {
  std::string what = "buffer " + std::to_string(index);
  if (!b.is_object()) return Status::error(what + ": not a JSON object");
  Result<uint64_t> length = unsigned_member(b, "byteLength", ~uint64_t(0), what);
  if (!length) return length.status();
  if (*length == ~uint64_t(0)) return Status::error(what + ": no byteLength");
  lengths.push_back(*length);
  auto uri_it = b.find("uri");
  if (uri_it == b.end()) {
    if (!glb || index != 0)
      return Status::error(what + ": no uri (only a GLB's first buffer may omit it)");
    if (!glb->has_bin) return Status::error(what + ": the GLB has no BIN chunk");
    if (*length > glb->bin_size) {
      return Status::error(what + ": byteLength " + std::to_string(*length) +
                           " is more than the GLB's BIN chunk (" + std::to_string(glb->bin_size) +
                           " bytes)");
    }
    return {};
  }
  if (!uri_it->is_string()) return Status::error(what + ": uri is not a string");
  const std::string& uri = uri_it->get_ref<const std::string&>();
  if (uri.rfind("data:", 0) == 0) return check_data_uri(uri, *length, what);
  if (*length > uint64_t(kMaxGltfFileBytes)) {
    return Status::error(what + ": byteLength " + std::to_string(*length) + " is over the limit (" +
                         std::to_string(kMaxGltfFileBytes >> 20) + " MiB)");
  }
  if (base_dir.empty())
    return Status::error(what + ": external file " + excerpt(uri) + " not allowed here");
  std::string file = url_decoded(uri);
  std::string path = (std::filesystem::path(base_dir) / file).string();
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    return Status::error(what + ": cannot open '" + file + "': " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) return Status::error(what + ": '" + file + "' is not a regular file");
  if (uint64_t(info.st_size) != *length) {
    return Status::error(what + ": '" + file + "' has " + std::to_string(info.st_size) +
                         " bytes, byteLength says " + std::to_string(*length));
  }
  return {};
}

// Images stored in bufferViews: TinyGLTF hands out a pointer into the buffer without checking the
// view's range, so the range is checked here against the buffer's byteLength.
Status check_image_views(const json& root, const std::vector<uint64_t>& lengths) {
  auto images = root.find("images");
  auto views = root.find("bufferViews");
  if (images == root.end() || !images->is_array()) return {};
  for (size_t i = 0; i < images->size(); ++i) {
    const json& image = (*images)[i];
    if (!image.is_object() || !image.contains("bufferView")) continue;
    std::string what = "image " + std::to_string(i);
    Result<uint64_t> view = unsigned_member(image, "bufferView", 0, what);
    if (!view) return view.status();
    if (views == root.end() || !views->is_array() || *view >= views->size() ||
        !(*views)[*view].is_object()) {
      return Status::error(what + ": bufferView " + std::to_string(*view) + " does not exist");
    }
    const json& v = (*views)[*view];
    std::string view_what = "bufferView " + std::to_string(*view);
    Result<uint64_t> buffer = unsigned_member(v, "buffer", ~uint64_t(0), view_what);
    Result<uint64_t> offset = unsigned_member(v, "byteOffset", 0, view_what);
    Result<uint64_t> length = unsigned_member(v, "byteLength", ~uint64_t(0), view_what);
    for (const auto* r : {&buffer, &offset, &length}) {
      if (!*r) return r->status();
    }
    if (*buffer >= lengths.size()) return Status::error(view_what + ": buffer does not exist");
    uint64_t have = lengths[*buffer];
    if (*offset > have || *length > have - *offset) {
      return Status::error(view_what + ": bytes " + std::to_string(*offset) + " + " +
                           std::to_string(*length) + " run past its buffer's " +
                           std::to_string(have));
    }
  }
  return {};
}

// glTF 1.0 (2015), which TinyGLTF does not read either: asset.version "1.0" (or the number 1),
// or, where there is no asset (the version 1.0 schema did not require one), meshes held in an
// object by name rather than in an array. Said as such instead of TinyGLTF's "asset not found"
// or, for a document it half reads, "no triangles to draw".
bool glTF_1(const json& root) {
  auto asset = root.find("asset");
  if (asset != root.end() && asset->is_object()) {
    auto version = asset->find("version");
    if (version == asset->end()) return false;
    if (version->is_number()) return version->get<double>() < 2.0;
    return version->is_string() && version->get<std::string>().rfind("1.", 0) == 0;
  }
  auto meshes = root.find("meshes");
  return meshes != root.end() && meshes->is_object();
}

Status precheck(std::string_view text, const GlbChunks* glb, const std::string& base_dir) {
  json root;
  try {
    root = json::parse(text.begin(), text.end());
  } catch (const json::exception& e) {
    std::string message = e.what();
    size_t bracket = message.find("] ");  // drop "[json.exception.parse_error.101] "
    if (message.rfind("[json.", 0) == 0 && bracket != std::string::npos) {
      message = message.substr(bracket + 2);
    }
    return Status::error("invalid JSON: " + message);
  }
  if (!root.is_object()) return Status::error("the JSON is not an object");
  if (glTF_1(root)) {
    return Status::error(
        "a glTF 1.0 file (its meshes, nodes and materials are named objects, "
        "with shader techniques); softrast reads glTF 2.0: convert it first");
  }
  if (auto req = root.find("extensionsRequired"); req != root.end() && req->is_array()) {
    for (const json& e : *req) {
      std::string ext = e.is_string() ? e.get<std::string>() : e.dump();
      if (!gltf_extension_supported(ext)) {
        return Status::error("requires the extension " + excerpt(ext) +
                             ", which softrast does not support (it reads "
                             "KHR_texture_transform, KHR_materials_emissive_strength and "
                             "KHR_mesh_quantization)");
      }
    }
  }
  std::vector<uint64_t> lengths;
  if (auto buffers = root.find("buffers"); buffers != root.end() && buffers->is_array()) {
    for (size_t i = 0; i < buffers->size(); ++i) {
      if (Status s = check_buffer((*buffers)[i], i, glb, base_dir, lengths); !s.ok()) return s;
    }
  }
  return check_image_views(root, lengths);
}

// What TinyGLTF's callbacks need.
struct Context {
  std::string name;
  std::string base_dir;
  GltfDocument* doc = nullptr;
};

bool file_exists(const std::string& path, void* user) {
  auto* ctx = static_cast<Context*>(user);
  struct stat info {};
  return !ctx->base_dir.empty() && ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

std::string expand_path(const std::string& path, void*) {
  return path;
}

bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
               void* user) {
  auto* ctx = static_cast<Context*>(user);
  if (ctx->base_dir.empty()) return false;
  std::vector<char> bytes;
  if (Status s = read_whole_file(path, kMaxGltfFileBytes, "glTF buffers", bytes); !s.ok()) {
    if (err) *err = s.message();
    return false;
  }
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "softrast does not write glTF files";
  return false;
}

// Images from data URIs are decoded here; those in bufferViews later (gltf_loader.cpp), once
// the view's range has been checked; the pointer TinyGLTF passes for them is not read.
bool load_image_data(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                     const unsigned char* bytes, int size, void* user) {
  auto* ctx = static_cast<Context*>(user);
  if (image->bufferView != -1 || index < 0 || size <= 0) return true;
  std::string what = ctx->name + ": image " + std::to_string(index);
  Result<Image> decoded = decode_image(bytes, size_t(size), what);
  if (!decoded) {
    ctx->doc->warnings.push_back(decoded.status().message() + "; drawn without this texture");
    return true;
  }
  if (ctx->doc->images.size() <= size_t(index)) ctx->doc->images.resize(size_t(index) + 1);
  ctx->doc->images[size_t(index)] = std::make_shared<Image>(std::move(*decoded));
  return true;
}

// TinyGLTF's error text: its first line, at most 200 characters (some quote a whole URI).
std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  if (line.size() > 200) line = line.substr(0, 200) + "...";
  return line.empty() ? "TinyGLTF could not read the file" : line;
}

}  // namespace

bool gltf_extension_supported(const std::string& name) {
  return std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), name) !=
         kSupportedExtensions.end();
}

Result<GltfDocument> read_gltf_document(const uint8_t* data, size_t size, const std::string& name,
                                        const std::string& base_dir) {
  bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  GlbChunks glb;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  if (binary) {
    Result<GlbChunks> chunks = read_glb_framing(data, size, name);
    if (!chunks) return chunks.status();
    glb = *chunks;
    text = glb.json;
  }
  if (Status s = precheck(text, binary ? &glb : nullptr, base_dir); !s.ok()) {
    return fail(name, s.message());
  }
  GltfDocument doc;
  Context ctx{name, base_dir, &doc};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&file_exists, &expand_path, &read_file, &write_file, &ctx});
  loader.SetImageLoader(&load_image_data, &ctx);
  std::string err, warn;
  bool ok = binary
                ? loader.LoadBinaryFromMemory(&doc.model, &err, &warn, data, glb.length, base_dir)
                : loader.LoadASCIIFromString(&doc.model, &err, &warn, text.data(),
                                             unsigned(text.size()), base_dir);
  if (!ok) return fail(name, first_line(err));
  doc.images.resize(doc.model.images.size());
  return doc;
}

}  // namespace softrast::detail
