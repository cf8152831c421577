// apps/softrast/batch.hpp: `softrast batch JOBS.jsonl`: one render per line of a file, each line
// interpreted into the JobSpec of `softrast render`; sharded (--shard K/N takes every N-th job from
// K), idempotent (an existing output is skipped), resumable, and a bad job fails only itself.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace softrast::cli {

struct BatchArgs {
  std::string jobs;  // a path, or "-" for the standard input
  std::optional<std::string> shard;
  std::string defaults = "{}";  // a JSON object of keys for every job that lacks them
  bool force = false;           // render even when the output exists
  bool fail_fast = false;       // stop at the first failed job
  bool json = false;            // one JSON record per job and a summary on stdout
  bool quiet = false;
};

// Adds the batch command's arguments and help to `app` (the `batch` subcommand).
void define_batch_flags(CLI::App& app, BatchArgs& args);

// Runs the jobs; returns the exit code: 0 when no job failed, 1 when one did (or the jobs file
// cannot be read), 2 for a bad --shard or --defaults.
int batch_command(const BatchArgs& args);

}  // namespace softrast::cli
