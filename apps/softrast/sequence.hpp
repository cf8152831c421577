// apps/softrast/sequence.hpp: `softrast render` for scripts: --turntable N writes N frames with
// the camera orbiting the model about its up axis, and --json prints what was done (files, times)
// as one JSON object on stdout. Frame 0 is exactly the image the same command without
// --turntable draws; frame i is the render from the eye turned by 360 * i / N degrees.
#pragma once

#include <CLI/CLI.hpp>

#include "args.hpp"

namespace softrast::cli {

// Adds --turntable and --json to the render command (not to batch jobs).
void define_sequence_flags(CLI::App& render, RawArgs& args);

// Whether the render command is one for render_sequence(): --turntable or --json given.
bool wants_sequence(const RawArgs& args);

// Checks, loads, renders and writes every frame; returns the exit code (0, 1 runtime, 2 usage)
// after printing any error.
int sequence_command(const RawArgs& args);

}  // namespace softrast::cli
