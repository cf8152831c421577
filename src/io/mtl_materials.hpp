// io/mtl_materials.hpp: the MTL libraries an OBJ file names, read through tinyobjloader's
// LoadMtl after their numbers are checked, and turned into softrast materials with textures.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <tiny_obj_loader.h>

#include "softrast/mesh.hpp"

namespace softrast::detail {

// Which of the statements tinyobj cannot tell from their zero defaults a material had.
struct MtlGiven {
  bool kd = false, ks = false, ns = false, illum = false;
};

// The materials of every MTL library the OBJ names, relative to the OBJ's folder, each with its
// MTL's folder (texture paths are relative to it) and whether it had a Kd. A missing MTL is not an
// error but a warning: the OBJ then has no materials from it, as with other loaders.
class ObjMaterials {
 public:
  ObjMaterials(std::filesystem::path obj_dir, int64_t max_mtl_bytes)
      : obj_dir_(std::move(obj_dir)), max_bytes_(max_mtl_bytes) {}

  // Reads library `name` once (later mentions are ignored). `obj_line` is where the OBJ names it,
  // for the warning if it is missing; an MTL that exists but cannot be read, is too large or has
  // a number tinyobj would overflow on is an error naming the MTL file and line.
  Status load_library(const std::string& name, const std::string& obj_path, size_t obj_line);

  // Whether library `name` is found where load_library would look, as it is named.
  bool library_exists(const std::string& name) const;

  // The material's index, or -1 (the default material) for a name no library defined. A name of
  // several words matches a newmtl line of the same words, however spaced (tinyobj keeps the whole
  // rest of the line as the name: "Hard Shiny Plastic White"); failing that, as OBJ readers that
  // take one word do, its first word.
  int id(const std::string& name) const;

  // The materials with their maps (colour maps as sRGB textures, a grey bump map turned into a
  // normal map); a map that cannot be loaded adds a warning instead. Errors: Kd or Ks not
  // finite, Ns outside [0, 1000], d outside [0, 1].
  Result<std::vector<Material>> convert(const std::string& path,
                                        std::vector<std::string>& warnings) const;

  // id() for `usemtl name` at line `obj_line` of `obj_path`. A name that no library defines adds a
  // warning, once per name, when the OBJ's libraries were all read (a missing one has its own)
  // and at least one was: "model.obj:12: usemtl 'skin': no material of that name in the MTL files
  // read; drawn with the default colour".
  int use(const std::string& name, const std::string& obj_path, size_t obj_line);

  std::vector<std::string> take_warnings() { return std::move(warnings_); }

 private:
  std::filesystem::path obj_dir_;
  int64_t max_bytes_;
  std::set<std::string> loaded_;
  std::map<std::string, int> ids_;
  std::map<std::string, int> spaced_ids_;  // ids_ by the names' words, the first material of each
  std::vector<tinyobj::material_t> all_;
  std::vector<std::filesystem::path> dirs_;
  std::vector<MtlGiven> given_;
  std::vector<std::string> warnings_;
  bool library_missing_ = false;   // a library the OBJ named was not read
  std::set<std::string> unknown_;  // the undefined names already warned about
};

// The material of the tutorial models' convention for the OBJ at `obj_path` (see load_obj):
// its <model>_diffuse.tga, _spec.tga, _nm_tangent.tga or _nm.tga beside it, or nullopt when there
// is none. A map that exists but cannot be loaded adds a warning.
std::optional<Material> tutorial_material(const std::string& obj_path,
                                          std::vector<std::string>& warnings);

}  // namespace softrast::detail
