// fuzz/cli_args_fuzz.cpp: the render command's argument parsing, and the batch command's job files
// (fuzz_batch, at the end). The input is split at newlines
// into an argument vector (at most 64 arguments), parsed by CLI11 with the CLI's own flag
// definitions (apps/softrast/args.cpp) the way main.cpp does it (`render` inserted when absent),
// then checked by interpret() (apps/softrast/setup.cpp). Nothing is loaded or rendered. Every
// input must end as a CLI11 parse error, a usage error with a one-line message, or a JobSpec
// within the documented limits; any other exception is a finding.
#include <algorithm>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "args.hpp"
#include "batch_jobs.hpp"
#include "fuzz_entries.hpp"
#include "setup.hpp"
#include "softrast/image.hpp"

namespace softrast::fuzz {
namespace {

std::vector<std::string> split_arguments(const uint8_t* data, size_t size) {
  std::vector<std::string> args;
  std::string current;
  for (size_t i = 0; i < size && args.size() < 64; ++i) {
    if (data[i] == '\n') {
      args.push_back(current);
      current.clear();
    } else {
      current += char(data[i]);
    }
  }
  if (!current.empty() && args.size() < 64) args.push_back(current);
  return args;
}

void check_spec(const cli::JobSpec& spec) {
  SOFTRAST_FUZZ_REQUIRE(spec.width >= 1 && spec.width <= kMaxImageSize,
                        "width outside 1..kMaxImageSize");
  SOFTRAST_FUZZ_REQUIRE(spec.height >= 1 && spec.height <= kMaxImageSize,
                        "height outside 1..kMaxImageSize");
  SOFTRAST_FUZZ_REQUIRE(spec.frames >= 0, "negative frame count");
  SOFTRAST_FUZZ_REQUIRE(spec.output || spec.frames > 0, "no output and no benchmark");
  SOFTRAST_FUZZ_REQUIRE(spec.options.alpha >= 0.0f && spec.options.alpha <= 1.0f,
                        "alpha outside [0, 1]");
  SOFTRAST_FUZZ_REQUIRE(spec.options.state.threads >= 0, "negative thread count");
}

}  // namespace

int fuzz_cli_args(const uint8_t* data, size_t size) {
  std::vector<std::string> args = split_arguments(data, size);
  if (args.empty() || args.front() != "render") args.insert(args.begin(), "render");
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first

  CLI::App app{"softrast: a software rasterizer", "softrast"};
  CLI::App* render = app.add_subcommand("render", "Render a model");
  cli::RawArgs raw;
  cli::define_render_flags(*render, raw);
  app.require_subcommand(1, 1);
  render->set_version_flag("--version", "softrast");
  try {
    app.parse(args);
  } catch (const CLI::ParseError&) {
    return 0;  // main.cpp prints e.what() on one line (or the help) and exits 2 (or 0)
  }
  Result<cli::JobSpec> spec = cli::interpret(raw);
  if (!spec) {
    const std::string& m = spec.status().message();
    SOFTRAST_FUZZ_REQUIRE(!m.empty(), "usage error without a message");
    return 0;
  }
  check_spec(*spec);
  return 0;
}

int fuzz_batch(const uint8_t* data, size_t size) {
  std::string content(reinterpret_cast<const char*>(data), size);
  std::vector<cli::JobLine> lines = cli::split_jobs(content);
  // The first line doubles as a --defaults object for the others when it is one.
  std::string defaults = "{}";
  if (!lines.empty() && cli::check_defaults(lines.front().text).ok()) {
    defaults = lines.front().text;
  }
  size_t previous = 0;
  for (size_t k = 0; k < lines.size() && k < 32; ++k) {
    const cli::JobLine& line = lines[k];
    SOFTRAST_FUZZ_REQUIRE(line.line > previous && line.index == k, "job lines out of order");
    SOFTRAST_FUZZ_REQUIRE(line.text.find('\n') == std::string::npos, "a job line holds a newline");
    previous = line.line;
    Result<cli::JobSpec> spec = cli::interpret_job(line.text, defaults);
    if (!spec) {
      const std::string& m = spec.status().message();
      // A message may quote a value holding a line break ("output": "a\nb"); the CLI prints
      // every error on one line (main.cpp and report.cpp turn line breaks into spaces).
      SOFTRAST_FUZZ_REQUIRE(!m.empty(), "job error without a message");
      continue;
    }
    check_spec(*spec);
    SOFTRAST_FUZZ_REQUIRE(spec->output.has_value(), "a job without an output image");
    SOFTRAST_FUZZ_REQUIRE(cli::output_of(line.text).has_value(),
                          "a job accepted whose line names no output");
  }
  return 0;
}

}  // namespace softrast::fuzz
