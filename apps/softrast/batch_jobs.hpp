// apps/softrast/batch_jobs.hpp: the lines of a jobs file, and one line (a JSON object) turned into
// the JobSpec that `softrast render` builds from the same settings given as flags.
//
// A job is one JSON object on one line. Its keys are the long flags of `softrast render` without
// the leading "--" ("size", "shader", "eye", "texture", "cull", ...), plus "model" (the MODEL
// argument: a string, or an array of strings) and "output" (the image, required). Values: a string
// as typed after the flag ("64x64", "0,1,3"), a number, an array of numbers (joined with commas;
// "size": [64, 64] is "64x64"), or true/false for a flag without a value (false: not given).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "setup.hpp"
#include "softrast/status.hpp"

namespace softrast::cli {

struct JobLine {
  size_t line = 0;   // 1-based line number in the file
  size_t index = 0;  // 0-based among the non-blank lines: the job's number for --shard
  std::string text;
};

// The jobs of a file: every line that is not blank (spaces only) is one job. A '\r' before the
// newline and a UTF-8 byte order mark at the start are dropped.
std::vector<JobLine> split_jobs(const std::string& content);

// The "output" of a job line, when the line is a JSON object whose "output" is a string.
std::optional<std::string> output_of(const std::string& text);

// The job as the render command would see it. Errors (without the file:line prefix): not JSON,
// not an object, a key given twice, an unknown key (with the closest known one), a key that has no
// place in a job (frames, quiet, out, ...), a value of the wrong kind, no "output", and every error
// of the render flags' own checks ("--size: expected WIDTHxHEIGHT such as 800x600, got '64'").
// `defaults` is a JSON object of keys for the jobs that do not give them ("output" excluded).
Result<JobSpec> interpret_job(const std::string& text, const std::string& defaults = "{}");

// Checks a --defaults object as a job of its own would be checked (an error without prefix).
Status check_defaults(const std::string& defaults);

// The keys a job may have, for --help: "model, output, size, eye, ...".
std::string job_keys();

}  // namespace softrast::cli
