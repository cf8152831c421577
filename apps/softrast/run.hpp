// apps/softrast/run.hpp: rendering a prepared job once, or timing it over frames, and writing
// the image. Progress goes to stderr (unless quiet), the benchmark's JSON line to stdout.
#pragma once

#include "setup.hpp"
#include "softrast/status.hpp"

namespace softrast::cli {

// Renders and writes the job's image; the only error left at this point is a failed write.
Status run_job(Job& job);

// The two steps of run_job, for commands that render a job more than once (--turntable): one
// frame exactly as run_job draws it (milliseconds), and the image written to *job.output
// exactly as run_job writes it (with a "wrote" line unless job.quiet).
double render_job_frame(Job& job);
Status write_job_image(const Job& job);

}  // namespace softrast::cli
