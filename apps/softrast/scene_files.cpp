// apps/softrast/scene_files.cpp: several model files as one scene.

#include "scene_files.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace softrast::cli {
namespace {

namespace fs = std::filesystem;

// The extensions a folder's model files have (compared in lower case); each file is then read by
// load_model(), which tells the formats apart by content.
constexpr std::array<std::string_view, 5> kModelExtensions = {".obj", ".ply", ".stl", ".gltf",
                                                              ".glb"};

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

bool is_model_file(const fs::directory_entry& entry) {
  std::error_code ec;
  if (!entry.is_regular_file(ec)) return false;
  std::string ext = lowercase(entry.path().extension().string());
  return std::find(kModelExtensions.begin(), kModelExtensions.end(), ext) != kModelExtensions.end();
}

std::string extension_list() {
  std::string list;
  for (std::string_view ext : kModelExtensions)
    list += (list.empty() ? "" : ", ") + std::string(ext);
  return list;
}

Result<std::vector<std::string>> folder_models(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    if (is_model_file(entry)) files.push_back(entry.path().string());
  }
  if (ec) return Status::error(folder + ": cannot list the folder: " + ec.message());
  if (files.empty()) {
    return Status::error(folder + ": no model files (" + extension_list() + ") in this folder");
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The loader's warnings (missing MTL or map files), where this version of Mesh carries them.
template <class M>
void take_loader_warnings(const M& mesh, std::vector<std::string>& out) {
  if constexpr (requires { mesh.warnings; }) {
    for (const auto& w : mesh.warnings) out.push_back(std::string(w));
  }
}

bool has_varying_uvs(const Mesh& mesh) {
  for (const glm::vec2& uv : mesh.uvs) {
    if (uv != mesh.uvs.front()) return true;
  }
  return false;
}

bool has_maps(const Mesh& mesh) {
  return std::any_of(mesh.materials.begin(), mesh.materials.end(),
                     [](const Material& m) { return m.diffuse_map != nullptr; });
}

}  // namespace

Result<std::vector<std::string>> expand_model_paths(const std::vector<std::string>& args) {
  std::vector<std::string> paths;
  for (const std::string& arg : args) {
    std::error_code ec;
    if (!fs::is_directory(arg, ec)) {
      paths.push_back(arg);
      continue;
    }
    Result<std::vector<std::string>> files = folder_models(arg);
    if (!files) return files.status();
    paths.insert(paths.end(), files->begin(), files->end());
  }
  return paths;
}

std::string element_counts(const Mesh& mesh) {
  std::string text = std::to_string(mesh.triangle_count()) + " triangles";
  if (!mesh.line_indices.empty()) {
    text += ", " + std::to_string(mesh.line_indices.size() / 2) + " line segments";
  }
  if (!mesh.point_indices.empty())
    text += ", " + std::to_string(mesh.point_indices.size()) + " points";
  return text;
}

// One kind of element of `part` (triangles, lines or points) appended to the scene's: indices
// shifted past the scene's vertices, runs past its indices and materials (a part without runs is
// one run of the default material).
void append_elements(std::vector<uint32_t>& indices, std::vector<SubMesh>& runs,
                     const std::vector<uint32_t>& part_indices,
                     const std::vector<SubMesh>& part_runs, uint32_t base, int material_base) {
  if (part_indices.empty()) return;
  const uint32_t first = uint32_t(indices.size());
  for (uint32_t i : part_indices) indices.push_back(base + i);
  if (part_runs.empty()) runs.push_back({first, uint32_t(part_indices.size()), -1});
  for (SubMesh run : part_runs) {
    run.first_index += first;
    if (run.material >= 0) run.material += material_base;
    runs.push_back(run);
  }
}

Status append_mesh(Mesh& scene, const Mesh& part) {
  size_t base = scene.positions.size();
  if (base + part.positions.size() > size_t(UINT32_MAX) ||
      scene.indices.size() + part.indices.size() > size_t(UINT32_MAX) ||
      scene.line_indices.size() + part.line_indices.size() > size_t(UINT32_MAX) ||
      scene.point_indices.size() + part.point_indices.size() > size_t(UINT32_MAX)) {
    return Status::error("the scene has more than 2^32 vertices or indices");
  }
  int material_base = int(scene.materials.size());
  scene.positions.insert(scene.positions.end(), part.positions.begin(), part.positions.end());
  scene.normals.insert(scene.normals.end(), part.normals.begin(), part.normals.end());
  scene.uvs.insert(scene.uvs.end(), part.uvs.begin(), part.uvs.end());
  // Tangents only while every part has them (else the renderer computes them if needed).
  if (scene.tangents.size() == base && part.tangents.size() == part.positions.size()) {
    scene.tangents.insert(scene.tangents.end(), part.tangents.begin(), part.tangents.end());
  } else {
    scene.tangents.clear();
  }
  // Vertex colours where any part has them: white for the vertices of parts without.
  const bool part_colored = part.colors.size() == part.positions.size() && !part.colors.empty();
  if (part_colored || !scene.colors.empty()) {
    scene.colors.resize(base, glm::vec4(1.0f));
    if (part_colored) {
      scene.colors.insert(scene.colors.end(), part.colors.begin(), part.colors.end());
    } else {
      scene.colors.resize(scene.positions.size(), glm::vec4(1.0f));
    }
  }
  scene.materials.insert(scene.materials.end(), part.materials.begin(), part.materials.end());
  append_elements(scene.indices, scene.submeshes, part.indices, part.submeshes, uint32_t(base),
                  material_base);
  append_elements(scene.line_indices, scene.line_submeshes, part.line_indices, part.line_submeshes,
                  uint32_t(base), material_base);
  append_elements(scene.point_indices, scene.point_submeshes, part.point_indices,
                  part.point_submeshes, uint32_t(base), material_base);
  return {};
}

Result<LoadedModels> load_models(const std::vector<std::string>& paths, const ModelLoader& load) {
  LoadedModels loaded;
  for (const std::string& path : paths) {
    Result<Mesh> mesh = load ? load(path) : load_model(path);
    if (!mesh) return mesh.status();
    take_loader_warnings(*mesh, loaded.warnings);
    loaded.parts.push_back({path, has_varying_uvs(*mesh), has_maps(*mesh)});
    if (paths.size() == 1) {
      loaded.mesh = std::move(*mesh);
    } else if (Status s = append_mesh(loaded.mesh, *mesh); !s.ok()) {
      return s;
    }
  }
  return loaded;
}

std::vector<std::string> texture_warnings(const std::vector<ModelPart>& parts,
                                          const RenderOptions& options, bool texture_flag) {
  std::vector<std::string> warnings;
  bool textured_shader =
      options.shader == ShaderKind::kTexture || options.shader == ShaderKind::kPhong;
  if (!textured_shader) return warnings;
  bool any_map =
      std::any_of(parts.begin(), parts.end(), [](const ModelPart& p) { return p.has_maps; });
  if (options.shader == ShaderKind::kTexture && !texture_flag && !any_map) {
    warnings.push_back(
        "--shader texture: the model has no texture (no --texture, no map_Kd in its "
        "materials), so it is drawn white");
  }
  for (const ModelPart& part : parts) {
    if ((texture_flag || part.has_maps) && !part.has_uvs) {
      warnings.push_back(part.path +
                         ": the model has no texture coordinates (vt), so its texture shows "
                         "as one colour");
    }
  }
  return warnings;
}

}  // namespace softrast::cli
