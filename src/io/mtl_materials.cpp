// io/mtl_materials.cpp: MTL libraries through tinyobj's LoadMtl (see mtl_materials.hpp).
// tinyobj cannot tell a missing Kd, Ks or Ns from a zero, so which materials had one is scanned
// here. Also the tutorial models' maps beside an OBJ without materials.

#include "io/mtl_materials.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>

#include <glm/geometric.hpp>
#include "io/file_lookup.hpp"
#include "io/obj_piece.hpp"
#include "io/text_lines.hpp"

#include "softrast/image.hpp"

namespace softrast::detail {
namespace {

namespace fs = std::filesystem;

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

Status fail_at(const std::string& path, size_t line, const std::string& reason) {
  return Status::error(path + ":" + std::to_string(line) + ": " + reason);
}

// Whether tinyobj's number parser would overflow on `word`, or cast it to a float out of range
// (both undefined behaviour). It adds exponent digits to an int, checking only before
// multiplying, so more than 9 significant exponent digits are refused even at the start of a word
// (it parses prefixes); nine stay below 2^31 / 10, and a sane file never has more than three.
bool mtl_number_out_of_range(std::string_view word) {
  float ignored = 0.0f;
  if (parse_obj_float(word, ignored) == ObjNumber::kOutOfRange &&
      word.find_first_of("nN") == word.npos) {
    return true;  // inf and nan are words tinyobj does not parse as numbers
  }
  size_t e = word.find_first_of("eE");
  if (e == std::string_view::npos) return false;
  size_t start = word.find_first_not_of("+-0", e + 1);
  if (start == std::string_view::npos) return false;
  size_t digits = 0;
  while (start + digits < word.size() && word[start + digits] >= '0' &&
         word[start + digits] <= '9') {
    ++digits;
  }
  return digits > 9;
}

// A map statement's line with the numbers of -o, -s and -t written out to three. MTL lets v and w
// be left out ("map_Kd -s 2 2 tiles.png"), but tinyobj reads three numbers after each: it takes
// the file's name for the missing w, and the map is lost. The missing ones are their defaults:
// 1 for -s, 0 for -o and -t. Other lines, and everything from the file's name on, are as they
// were (a name may hold spaces).
std::string complete_map_options(std::string_view line) {
  size_t at = 0;
  auto next_word = [&]() -> std::string_view {
    at = line.find_first_not_of(" \t", at);
    if (at == std::string_view::npos) return at = line.size(), std::string_view{};
    size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
    std::string_view word = line.substr(at, end - at);
    at = end;
    return word;
  };
  auto is_number = [](std::string_view w) {
    float ignored = 0.0f;
    return !w.empty() && parse_obj_float(w, ignored) == ObjNumber::kOk;
  };
  // Map statements: map_Kd, map_Bump, ... and the older bump, disp, decal, refl, norm.
  std::string_view statement = next_word();
  bool map = statement.starts_with("map_") || statement == "bump" || statement == "disp" ||
             statement == "decal" || statement == "refl" || statement == "norm";
  if (!map) return std::string(line);
  std::string out(line.substr(0, at));
  for (;;) {
    size_t word_start = at;
    std::string_view word = next_word();
    if (word != "-o" && word != "-s" && word != "-t") {
      // Another option's words pass as they are; the first word that is no option's starts
      // the file's name (and the rest of the line goes with it).
      out.append(line.substr(word_start));
      return out;
    }
    out.append(line.substr(word_start, at - word_start));
    int numbers = 0;
    while (numbers < 3) {
      size_t before = at;
      std::string_view value = next_word();
      if (!is_number(value)) {
        at = before;
        break;
      }
      out.append(line.substr(before, at - before));
      ++numbers;
    }
    if (numbers == 0) continue;  // nothing to complete: tinyobj's own reading stands
    for (; numbers < 3; ++numbers) out.append(word == "-s" ? " 1" : " 0");
  }
}

// For each material that tinyobj::LoadMtl will produce from `text`, in its order, which of Kd,
// Ks, Ns and illum the MTL gave it (tinyobj cannot tell a missing one from its zero default).
// Mirrors LoadMtl: one material per `newmtl` line (names are never empty after its trimming), or a
// single unnamed one if there is no `newmtl` at all.
std::vector<MtlGiven> scan_given(const std::string& text) {
  std::vector<MtlGiven> given;
  MtlGiven unnamed;
  std::istringstream in(text);
  std::string line;
  auto is_key = [](const char* token, const char* key) {
    size_t n = std::strlen(key);
    return std::strncmp(token, key, n) == 0 && (token[n] == ' ' || token[n] == '\t');
  };
  while (std::getline(in, line, '\n')) {
    const char* token = line.c_str() + std::strspn(line.c_str(), " \t");
    if (is_key(token, "newmtl")) given.push_back({});
    MtlGiven& g = given.empty() ? unnamed : given.back();
    g.kd = g.kd || is_key(token, "Kd");
    g.ks = g.ks || is_key(token, "Ks");
    g.ns = g.ns || is_key(token, "Ns");
    g.illum = g.illum || is_key(token, "illum");
  }
  if (given.empty()) given.push_back(unnamed);
  return given;
}

}  // namespace

int ObjMaterials::id(const std::string& name) const {
  if (auto it = ids_.find(name); it != ids_.end()) return it->second;
  if (auto it = spaced_ids_.find(ObjWords(name).joined()); it != spaced_ids_.end()) {
    return it->second;
  }
  size_t space = name.find(' ');
  return space == name.npos ? -1 : id(name.substr(0, space));
}

bool ObjMaterials::library_exists(const std::string& name) const {
  std::optional<FoundFile> found = find_named_file(obj_dir_, name);
  return found && found->how != FoundAs::kBeside;
}

Status ObjMaterials::load_library(const std::string& name, const std::string& obj_path,
                                  size_t obj_line) {
  if (!loaded_.insert(name).second) return {};
  std::optional<FoundFile> found = find_named_file(obj_dir_, name);
  if (!found) {
    library_missing_ = true;
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": material library '" + name +
                        "' not found; its materials get the default colour");
    return {};
  }
  fs::path path = found->path;
  if (found->how == FoundAs::kBeside) {
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": material library '" + name +
                        "' is not there; took " + path.string() +
                        ", the file of its name beside "
                        "the model");
  }
  std::error_code ignored;
  if (fs::exists(path, ignored) && !fs::is_regular_file(path, ignored) &&
      !fs::is_directory(path, ignored)) {
    // A pipe or device that a model names (opening a FIFO would wait for a writer forever).
    library_missing_ = true;
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": material library '" + name +
                        "' is not a regular file (a pipe or device); its materials get the "
                        "default colour");
    return {};
  }
  std::string text;
  Status read = read_lines(
      path.string(), {max_bytes_, "MTL files"}, [&](std::string_view line, size_t number) {
        ObjWords words(line);
        // The numbers of a colour or scalar statement: tinyobj reads nan and inf as 0 (a black
        // Kd, an invisible d), so they are refused here as the OBJ's own numbers are.
        const std::string_view key = words.next();
        const bool numeric = key == "Ka" || key == "Kd" || key == "Ks" || key == "Ke" ||
                             key == "Tf" || key == "Ns" || key == "Ni" || key == "d" || key == "Tr";
        for (std::string_view w = key; !w.empty(); w = words.next()) {
          float value = 0.0f;
          if (numeric && w != key && w.find_first_of("nN") != w.npos &&
              parse_obj_float(w, value) == ObjNumber::kOutOfRange) {
            return fail_at(path.string(), number,
                           "number " + std::string(w) + " is not finite as a 32-bit float");
          }
          if (mtl_number_out_of_range(w)) {
            return fail_at(path.string(), number, "number " + std::string(w) + " is out of range");
          }
        }
        text.append(complete_map_options(line));
        text += '\n';
        return Status();
      });
  if (!read.ok()) return read;
  size_t first = all_.size();
  std::istringstream in(text);
  std::string warn;
  tinyobj::LoadMtl(&ids_, &all_, &in, &warn, nullptr);
  for (const auto& [material, index] : ids_) {
    auto [it, added] = spaced_ids_.emplace(ObjWords(material).joined(), index);
    if (!added) it->second = std::min(it->second, index);
  }
  std::vector<MtlGiven> given = scan_given(text);
  // Should the scan ever disagree with tinyobj, trust tinyobj's values.
  given.resize(all_.size() - first, MtlGiven{true, true, true});
  given_.insert(given_.end(), given.begin(), given.end());
  dirs_.resize(all_.size(), path.parent_path());
  return {};
}

int ObjMaterials::use(const std::string& name, const std::string& obj_path, size_t obj_line) {
  int index = id(name);
  if (index < 0 && !name.empty() && !loaded_.empty() && !library_missing_ &&
      unknown_.insert(name).second) {
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": usemtl '" + name +
                        "': no material of that name in the MTL files read; drawn with the "
                        "default colour");
  }
  return index;
}

namespace {

// What a map holds: colour (sRGB, as images are stored), other data (linear), or a normal map
// that may come as a greyscale height map (bump).
enum class MapKind { kColor, kData, kBump };

struct LoadedMap {
  std::shared_ptr<const Texture> texture;
  bool from_height = false;  // a greyscale bump map turned into a normal map
};
using TextureCache = std::map<std::string, LoadedMap>;

// Whether every pixel of `image` is grey (r = g = b): a bump map then holds heights.
bool is_greyscale(const Image& image) {
  for (size_t k = 0; k + 3 < image.rgba.size(); k += 4) {
    if (image.rgba[k] != image.rgba[k + 1] || image.rgba[k] != image.rgba[k + 2]) return false;
  }
  return true;
}

// Tangent-space normals of a height map (red / 255), by central differences with wrap-around:
// n = normalize(-kSlope * scale * dh/du, -kSlope * scale * dh/dv, 1) per texel, dh in full
// range per texel. kSlope = 8: a rise of 1/8 of the range over one texel tilts by 45 degrees,
// so the gentle gradients of a typical 8-bit bump map show without a -bm.
Image height_to_normals(const Image& height, float scale) {
  constexpr float kSlope = 8.0f;
  Image out = height;
  const int w = height.width, h = height.height;
  auto at = [&](int x, int y) {
    x = (x % w + w) % w, y = (y % h + h) % h;
    return float(height.pixel(x, y)[0]) / 255.0f;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // Rows run top-down in an image and v up: dh/dv is the row above minus the row below.
      float du = 0.5f * (at(x + 1, y) - at(x - 1, y)) * kSlope * scale;
      float dv = 0.5f * (at(x, y - 1) - at(x, y + 1)) * kSlope * scale;
      glm::vec3 n = glm::normalize(glm::vec3(-du, -dv, 1.0f));
      uint8_t* p = &out.rgba[(size_t(y) * size_t(w) + size_t(x)) * 4];
      for (int c = 0; c < 3; ++c) p[c] = uint8_t((n[c] * 0.5f + 0.5f) * 255.0f + 0.5f);
      p[3] = 255;
    }
  }
  return out;
}

// Returns the map at `file`, loading it on first use so that materials share it.
Result<LoadedMap> texture_at(const fs::path& file, TextureCache& cache, MapKind kind,
                             float bump_scale = 1.0f) {
  std::string key = file.lexically_normal().string();
  std::string cache_key = key + "\n" + std::to_string(int(kind));
  if (kind == MapKind::kBump) cache_key.append(" ").append(std::to_string(bump_scale));
  if (auto it = cache.find(cache_key); it != cache.end()) return it->second;
  std::error_code ec;
  if (fs::exists(file, ec) && !fs::is_regular_file(file, ec) && !fs::is_directory(file, ec)) {
    // A pipe or device that a material names: opening a FIFO would wait for a writer forever.
    return Status::error(key + ": not a regular file (a pipe or device)");
  }
  Result<Image> image = load_image(key);
  if (!image.ok()) return image.status();
  LoadedMap map;
  ColorSpace space = kind == MapKind::kColor ? ColorSpace::kSrgb : ColorSpace::kLinear;
  if (kind == MapKind::kBump && is_greyscale(*image)) {
    map.from_height = true;
    map.texture =
        std::make_shared<const Texture>(Texture::from_image(height_to_normals(*image, bump_scale)));
  } else {
    map.texture = std::make_shared<const Texture>(Texture::from_image(*image, space));
  }
  cache.emplace(cache_key, map);
  return map;
}

// Loads map `name` (relative to `dir`) of kind `kind` for `statement`; a map that cannot be
// loaded is a warning and leaves the material without it.
std::optional<LoadedMap> load_map(const fs::path& dir, const std::string& name, MapKind kind,
                                  float bump_scale, TextureCache& cache, const std::string& where,
                                  const std::string& statement,
                                  std::vector<std::string>& warnings) {
  if (name.empty()) return std::nullopt;
  std::optional<FoundFile> found = find_named_file(dir, name);
  Result<LoadedMap> map = texture_at(found ? found->path : dir / name, cache, kind, bump_scale);
  if (map.ok()) {
    if (found->how == FoundAs::kBeside) {
      warnings.push_back(where + statement + ": '" + name + "' is not there; took " +
                         found->path.string() + ", the file of its name beside the material");
    }
    return *map;
  }
  warnings.push_back(where + statement + ": " + map.status().message() +
                     "; drawn without this texture");
  return std::nullopt;
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x + v.y + v.z);
}

// A map's placement options as Material keeps them (-s and -o in u and v; w is for 3D maps).
struct Placement {
  glm::vec2 scale{1.0f};
  glm::vec2 offset{0.0f};
  bool clamp = false;
  bool operator==(const Placement&) const = default;
};

Placement placement_of(const tinyobj::texture_option_t& o) {
  return {{float(o.scale[0]), float(o.scale[1])},
          {float(o.origin_offset[0]), float(o.origin_offset[1])},
          o.clamp};
}

}  // namespace

Result<std::vector<Material>> ObjMaterials::convert(const std::string& path,
                                                    std::vector<std::string>& warnings) const {
  std::vector<Material> materials;
  TextureCache cache;
  for (size_t i = 0; i < all_.size(); ++i) {
    const tinyobj::material_t& source = all_[i];
    Material m;
    m.name = source.name;
    const std::string named = "material '" + source.name + "'";
    if (given_[i].kd) m.diffuse = {source.diffuse[0], source.diffuse[1], source.diffuse[2]};
    if (given_[i].ks) m.specular = {source.specular[0], source.specular[1], source.specular[2]};
    if (given_[i].ns) m.shininess = source.shininess;
    m.opacity = source.dissolve;
    if (!finite(m.diffuse)) return fail(path, "Kd of " + named + " is not finite");
    if (!finite(m.specular)) return fail(path, "Ks of " + named + " is not finite");
    if (!(m.shininess >= 0.0f && m.shininess <= 1000.0f)) {
      return fail(path, "Ns of " + named + " is " + std::to_string(m.shininess) +
                            "; it must be in [0, 1000]");
    }
    // No highlight where the MTL turns it off: illum 0 and 1 (colour, or colour and ambient, in
    // the MTL's list of illumination models: no specular term), and Ns 0, which Blinn-Phong would
    // make a highlight of Ks over the whole lit side. That is what 3ds Max's Max2Mtl writes for a
    // material without a highlight (Ks 0.9 and Ns 0: assimp's regr01.obj drew white), and what
    // assimp takes shininess 0 to mean.
    const bool no_highlight = (given_[i].illum && (source.illum == 0 || source.illum == 1)) ||
                              (given_[i].ns && source.shininess == 0.0f);
    if (no_highlight) m.specular = glm::vec3(0.0f);
    if (!(m.opacity >= 0.0f && m.opacity <= 1.0f)) {
      return fail(path, "d (or Tr) of " + named + " is " + std::to_string(m.opacity) +
                            "; it must be in [0, 1]");
    }
    const fs::path& dir = dirs_[i];
    const std::string where = path + ": " + named + ": ";
    if (auto map = load_map(dir, source.diffuse_texname, MapKind::kColor, 1.0f, cache, where,
                            "map_Kd", warnings)) {
      m.diffuse_map = map->texture;
    }
    if (auto map = load_map(dir, source.specular_texname, MapKind::kData, 1.0f, cache, where,
                            "map_Ks", warnings)) {
      m.specular_map = map->texture;
    }
    if (auto map = load_map(dir, source.alpha_texname, MapKind::kData, 1.0f, cache, where, "map_d",
                            warnings)) {
      m.alpha_map = map->texture;
    }
    // norm is a normal map; map_Bump / bump is one too in most exporters' files, or a height
    // map when it is grey. -bm scales either.
    bool norm = !source.normal_texname.empty();
    const std::string& bump_name = norm ? source.normal_texname : source.bump_texname;
    float scale = norm ? source.normal_texopt.bump_multiplier : source.bump_texopt.bump_multiplier;
    if (!std::isfinite(scale)) return fail(path, "-bm of " + named + " is not finite");
    if (auto map = load_map(dir, bump_name, MapKind::kBump, scale, cache, where,
                            norm ? "norm" : "map_Bump", warnings)) {
      m.normal_map = map->texture;
      m.normal_scale = map->from_height ? 1.0f : scale;
    }
    // The placement of the maps: map_Kd's options (the map most of the surface shows), else
    // those of the first map that has any. MTL allows them per map; a material whose maps
    // differ is drawn with that one's, and says so.
    struct Named {
      const char* statement;
      const std::string& texname;
      const tinyobj::texture_option_t& options;
    };
    const Named maps[] = {
        {"map_Kd", source.diffuse_texname, source.diffuse_texopt},
        {"map_Ks", source.specular_texname, source.specular_texopt},
        {"map_d", source.alpha_texname, source.alpha_texopt},
        {norm ? "norm" : "map_Bump", bump_name, norm ? source.normal_texopt : source.bump_texopt},
    };
    const Named* placed = nullptr;
    for (const Named& map : maps) {
      if (map.texname.empty()) continue;
      if (placed == nullptr) placed = &map;
      if (&map == &maps[0] || placement_of(map.options) != Placement{}) {
        placed = &map;
        break;
      }
    }
    if (placed != nullptr) {
      Placement p = placement_of(placed->options);
      if (!std::isfinite(p.scale.x + p.scale.y + p.offset.x + p.offset.y)) {
        return fail(
            path, std::string(placed->statement) + " of " + named + ": its -s or -o is not finite");
      }
      m.uv_scale = p.scale;
      m.uv_offset = p.offset;
      m.clamp_maps = p.clamp;
      for (const Named& map : maps) {
        if (!map.texname.empty() && placement_of(map.options) != p) {
          warnings.push_back(where + map.statement + ": its -s, -o or -clamp differ from " +
                             placed->statement + "'s; every map of the material is placed as " +
                             placed->statement + " is");
        }
      }
    }
    materials.push_back(std::move(m));
  }
  return materials;
}

std::optional<Material> tutorial_material(const std::string& obj_path,
                                          std::vector<std::string>& warnings) {
  fs::path obj(obj_path);
  fs::path dir = obj.parent_path();
  std::string stem = obj.stem().string();
  auto beside = [&](const char* suffix) {
    fs::path file = dir / (stem + suffix);
    std::error_code ec;
    return fs::is_regular_file(file, ec) ? file.filename().string() : std::string();
  };
  std::string diffuse = beside("_diffuse.tga"), spec = beside("_spec.tga");
  std::string tangent = beside("_nm_tangent.tga"), object = beside("_nm.tga");
  if (diffuse.empty() && spec.empty() && tangent.empty() && object.empty()) return std::nullopt;
  Material m;
  m.name = stem;
  TextureCache cache;
  const std::string where = obj_path + ": ";
  if (auto map = load_map(dir, diffuse, MapKind::kColor, 1.0f, cache, where, diffuse, warnings)) {
    m.diffuse_map = map->texture;
  }
  if (auto map = load_map(dir, spec, MapKind::kData, 1.0f, cache, where, spec, warnings)) {
    m.specular_map = map->texture;
  }
  const std::string& normal = tangent.empty() ? object : tangent;
  if (auto map = load_map(dir, normal, MapKind::kData, 1.0f, cache, where, normal, warnings)) {
    m.normal_map = map->texture;
    m.normal_space = tangent.empty() ? NormalSpace::kObject : NormalSpace::kTangent;
  }
  return m;
}

}  // namespace softrast::detail
