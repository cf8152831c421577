// apps/softrast/view.hpp: `softrast view MODEL...`, the live viewer: an SDL2 window showing the
// frame softrast renders, with mouse orbit, pan and zoom and keys for the render settings.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "args.hpp"

namespace softrast::cli {

struct ViewArgs {
  std::vector<std::string> models;  // none: the demo scene
  RawArgs render;                   // the render flags the viewer shares (checked the same way)
  bool continuous = false;
  std::optional<int> frames;
};

// Adds the view command's flags to `app`, storing into `args`.
void define_view_flags(CLI::App& app, ViewArgs& args);

// Runs the viewer until its window is closed. Returns the process's exit code; errors are
// reported through `report` (one line each).
int view_command(const ViewArgs& args, void (*report)(std::string message));

}  // namespace softrast::cli
