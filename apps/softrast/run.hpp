// apps/softrast/run.hpp: rendering a prepared job once, or timing it over frames, and writing
// the image. Progress goes to stderr (unless quiet), the benchmark's JSON line to stdout.
#pragma once

#include "setup.hpp"
#include "softrast/status.hpp"

namespace softrast::cli {

// Renders and writes the job's image; the only error left at this point is a failed write.
Status run_job(Job& job);

}  // namespace softrast::cli
