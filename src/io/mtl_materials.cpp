// io/mtl_materials.cpp: MTL libraries through tinyobj's LoadMtl (see mtl_materials.hpp).
// tinyobj cannot tell a missing Kd from Kd 0 0 0, so which materials had one is scanned here.

#include "io/mtl_materials.hpp"

#include <cmath>
#include <cstring>
#include <memory>
#include <sstream>
#include <string_view>
#include <system_error>

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

// For each material that tinyobj::LoadMtl will produce from `text`, in its order, whether the
// MTL gave it a Kd. Mirrors LoadMtl: one material per `newmtl` line (names are never empty
// after its trimming), or a single unnamed one if there is no `newmtl` at all.
std::vector<bool> scan_kd(const std::string& text) {
  std::vector<bool> has_kd;
  bool unnamed_kd = false;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line, '\n')) {
    const char* token = line.c_str() + std::strspn(line.c_str(), " \t");
    bool is_newmtl = std::strncmp(token, "newmtl", 6) == 0 && (token[6] == ' ' || token[6] == '\t');
    bool is_kd = token[0] == 'K' && token[1] == 'd' && (token[2] == ' ' || token[2] == '\t');
    if (is_newmtl) has_kd.push_back(false);
    if (is_kd && has_kd.empty()) unnamed_kd = true;
    if (is_kd && !has_kd.empty()) has_kd.back() = true;
  }
  if (has_kd.empty()) has_kd.push_back(unnamed_kd);
  return has_kd;
}

}  // namespace

Status ObjMaterials::load_library(const std::string& name, const std::string& obj_path,
                                  size_t obj_line) {
  if (!loaded_.insert(name).second) return {};
  fs::path path = obj_dir_ / name;
  std::error_code ignored;
  if (!fs::exists(path, ignored)) {
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": material library '" + name +
                        "' not found; its materials get the default colour");
    return {};
  }
  if (fs::exists(path, ignored) && !fs::is_regular_file(path, ignored) &&
      !fs::is_directory(path, ignored)) {
    // A pipe or device that a model names (opening a FIFO would wait for a writer forever).
    warnings_.push_back(obj_path + ":" + std::to_string(obj_line) + ": material library '" + name +
                        "' is not a regular file (a pipe or device); its materials get the "
                        "default colour");
    return {};
  }
  std::string text;
  Status read = read_lines(
      path.string(), {max_bytes_, "MTL files"}, [&](std::string_view line, size_t number) {
        ObjWords words(line);
        for (std::string_view w = words.next(); !w.empty(); w = words.next()) {
          if (mtl_number_out_of_range(w)) {
            return fail_at(path.string(), number, "number " + std::string(w) + " is out of range");
          }
        }
        text.append(line);
        text += '\n';
        return Status();
      });
  if (!read.ok()) return read;
  size_t first = all_.size();
  std::istringstream in(text);
  std::string warn;
  tinyobj::LoadMtl(&ids_, &all_, &in, &warn, nullptr);
  std::vector<bool> kd = scan_kd(text);
  // Should the scan ever disagree with tinyobj, trust tinyobj's Kd values.
  kd.resize(all_.size() - first, true);
  has_kd_.insert(has_kd_.end(), kd.begin(), kd.end());
  dirs_.resize(all_.size(), path.parent_path());
  return {};
}

namespace {

// Returns the texture at `file`, loading it on first use so that materials share it.
using TextureCache = std::map<std::string, std::shared_ptr<const Texture>>;

Result<std::shared_ptr<const Texture>> texture_at(const fs::path& file, TextureCache& cache) {
  std::string key = file.lexically_normal().string();
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  std::error_code ec;
  if (fs::exists(file, ec) && !fs::is_regular_file(file, ec) && !fs::is_directory(file, ec)) {
    // A pipe or device that a material names: opening a FIFO would wait for a writer forever.
    return Status::error(key + ": not a regular file (a pipe or device)");
  }
  Result<Image> image = load_image(key);
  if (!image.ok()) return image.status();
  auto texture = std::make_shared<const Texture>(Texture::from_image(*image));
  cache.emplace(key, texture);
  return std::shared_ptr<const Texture>(texture);
}

}  // namespace

Result<std::vector<Material>> ObjMaterials::convert(const std::string& path,
                                                    std::vector<std::string>& warnings) const {
  std::vector<Material> materials;
  TextureCache cache;
  for (size_t i = 0; i < all_.size(); ++i) {
    const tinyobj::material_t& source = all_[i];
    Material material;
    material.name = source.name;
    if (has_kd_[i]) {
      material.diffuse = {source.diffuse[0], source.diffuse[1], source.diffuse[2]};
      if (!std::isfinite(material.diffuse.x + material.diffuse.y + material.diffuse.z)) {
        return fail(path, "Kd of material '" + source.name + "' is not finite");
      }
    }
    if (!source.diffuse_texname.empty()) {
      auto texture = texture_at(dirs_[i] / source.diffuse_texname, cache);
      if (texture.ok()) {
        material.diffuse_map = *texture;
      } else {
        warnings.push_back(path + ": material '" + source.name + "': map_Kd: " +
                           texture.status().message() + "; drawn without this texture");
      }
    }
    materials.push_back(std::move(material));
  }
  return materials;
}

}  // namespace softrast::detail
