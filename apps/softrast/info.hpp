// apps/softrast/info.hpp: `softrast info MODEL...`: what a model holds (triangles, vertices,
// bounds, submeshes, materials) and which files it refers to (MTL libraries and texture maps),
// each marked found or missing; --json for one JSON object per model.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace softrast::cli {

struct InfoArgs {
  std::vector<std::string> models;
  bool json = false;
};

void define_info_flags(CLI::App& app, InfoArgs& args);

// Describes every model; 0 when all loaded, 1 when one did not (its error is printed, and with
// --json its object carries "error").
int info_command(const InfoArgs& args);

}  // namespace softrast::cli
