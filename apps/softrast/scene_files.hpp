// apps/softrast/scene_files.hpp: the models named on the command line as one scene. Folders
// become their model files (sorted by name), each file is loaded with its own materials and
// maps, and all are merged into one mesh that is framed and drawn as a whole.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"
#include "softrast/status.hpp"

namespace softrast::cli {

// What the warnings need to know of each file of a scene.
struct ModelPart {
  std::string path;
  bool has_uvs = false;   // texture coordinates that are not all the same
  bool has_maps = false;  // a material with a diffuse map
};

struct LoadedModels {
  Mesh mesh;
  std::vector<ModelPart> parts;
  std::vector<std::string> warnings;  // the loader's, "path: ..." each
};

// The model files of `args` in order, every folder replaced by the model files directly in it,
// sorted by name. Errors: a folder without model files (a missing path is left to the loader,
// whose message names it).
Result<std::vector<std::string>> expand_model_paths(const std::vector<std::string>& args);

// Reads one model file (softrast batch passes one that keeps the models its jobs share).
using ModelLoader = std::function<Result<Mesh>(const std::string& path)>;

// Loads every file (with `load`, or the library's loader when it is empty) and merges them
// (precondition: `paths` is not empty).
Result<LoadedModels> load_models(const std::vector<std::string>& paths,
                                 const ModelLoader& load = {});

// What the mesh draws, for progress lines: "12 triangles", or with its lines and points
// "0 triangles, 24 line segments, 8 points".
std::string element_counts(const Mesh& mesh);

// Appends `part` to `scene`: vertices after the scene's, its materials after the scene's (so
// equal material names in two files stay two materials), its runs re-based.
Status append_mesh(Mesh& scene, const Mesh& part);

// The "no silent surprises" warnings about textures: the texture shader with no texture at all,
// a texture drawn on a model without texture coordinates.
std::vector<std::string> texture_warnings(const std::vector<ModelPart>& parts,
                                          const RenderOptions& options, bool texture_flag);

}  // namespace softrast::cli
