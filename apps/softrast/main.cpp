// apps/softrast/main.cpp: the softrast command line. Exit codes: 0 success, 1 runtime error
// (files, memory, failed batch jobs), 2 usage error (flags); every error is one line
// "softrast: error: ..." (here, and in batch, info and sequence through report.hpp). SIGINT,
// SIGTERM and SIGHUP still end it as signals, after removing any temporary image file and
// printing one error line; past a file-size limit the write fails as any failed write does.
//
//   softrast [render] [MODEL...] [-o out.png] [flags]     see `softrast --help`
//   softrast batch JOBS.jsonl [--shard K/N]               see `softrast batch --help`
//   softrast info MODEL... [--json]
//   softrast view [MODEL...]
//   softrast help [COMMAND]

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "args.hpp"
#include "batch.hpp"
#include "info.hpp"
#include "parse_errors.hpp"
#include "run.hpp"
#include "sequence.hpp"
#include "setup.hpp"
#include "softrast/image.hpp"
#include "values.hpp"
#include "view.hpp"

namespace {

using namespace softrast;
using namespace softrast::cli;

constexpr int kExitRuntime = 1;
constexpr int kExitUsage = 2;
constexpr const char* kVersion = "softrast 0.1.0";

// Every error is one line on stderr with this prefix, whatever produced it.
void report_error(std::string message) {
  std::replace_if(
      message.begin(), message.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!message.empty() && message.back() == ' ') message.pop_back();
  std::fprintf(stderr, "softrast: error: %s\n", message.c_str());
}

// The arguments after the program name, for CLI11 (which wants them reversed), with the
// `render` subcommand inserted when the first argument names no command (render, batch, info):
// `softrast` alone is `softrast render`.
std::vector<std::string> command_arguments(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  const std::vector<std::string> kCommands = {"render", "batch", "info", "view"};
  if (args.empty() ||
      std::find(kCommands.begin(), kCommands.end(), args.front()) == kCommands.end()) {
    args.insert(args.begin(), "render");
  }
  std::reverse(args.begin(), args.end());
  return args;
}

void describe(CLI::App& app, CLI::App& render) {
  app.require_subcommand(1, 1);
  render.set_version_flag("--version", kVersion);
  render.footer(
      "Without MODEL, renders the built-in demo scene with its camera. Without --eye, the models "
      "are framed to fill 90% of the image's width or height, seen from --view (default front) "
      "relative to --up-axis. `softrast` without a subcommand is `softrast render`; `softrast "
      "help [COMMAND]` prints this help. `softrast view [MODEL...]` opens the live viewer "
      "(softrast view --help).\n\n"
      "Materials: the MTL files an OBJ names (mtllib) are read, with each material's colour (Kd) "
      "and texture (map_Kd); --texture overrides their maps. Also Ks, Ns, d, map_Ks, map_d, norm "
      "and map_Bump (-bm); an OBJ without materials takes <model>_diffuse.tga, _spec.tga and "
      "_nm_tangent.tga (or _nm.tga) from beside it. phong draws every map (--maps diffuse: only "
      "the colour maps).\n"
      "Depth: --depth sets the depth test (which surface hides which); --shader depth is the "
      "depth view (grey by distance, white nearest, black farthest).\n\n"
      "Examples:\n"
      "  softrast render -o demo.png\n"
      "  softrast render model.obj --size 1920x1080 --shader gouraud --wireframe\n"
      "  softrast render body.obj head.obj --view iso -o character.png\n"
      "  softrast render parts/ --up-axis +z --view left --background 1,1,1,0 -o thumb.png\n"
      "  softrast render model.obj --eye 0,1,3 --target 0,0,0 --fov 45 --near 0.1 --far 100\n"
      "  softrast render scene.obj --cull back --frames 10    # one JSON line of timings\n"
      "  softrast render model.obj --turntable 36 -o frames/   # frames/frame_000.png ...\n\n"
      "Other commands (each with --help):\n"
      "  softrast info MODEL... [--json]           # triangles, bounds, materials, maps found\n"
      "  softrast batch JOBS.jsonl [--shard K/N]   # one render per JSON line, resumable");
}

// SIGINT, SIGTERM or SIGHUP (the terminal closed): remove the temporary file of an image being
// written, then die of the signal (SA_RESETHAND has restored the default action; the raised
// signal is delivered when the handler returns), so the exit status still says which signal ended
// the program. One line on stderr says why the program stopped (write() only: async-signal-safe).
void on_terminating_signal(int signal) {
  remove_pending_temporary_file();
  static constexpr char kInterrupt[] =
      "softrast: error: interrupted by SIGINT; no partial output file is left\n";
  static constexpr char kTerminate[] =
      "softrast: error: terminated by SIGTERM; no partial output file is left\n";
  static constexpr char kHangUp[] =
      "softrast: error: hung up (SIGHUP); no partial output file is left\n";
  const char* line = signal == SIGINT ? kInterrupt : signal == SIGHUP ? kHangUp : kTerminate;
  size_t size = signal == SIGINT   ? sizeof kInterrupt - 1
                : signal == SIGHUP ? sizeof kHangUp - 1
                                   : sizeof kTerminate - 1;
  [[maybe_unused]] ssize_t written = write(STDERR_FILENO, line, size);
  raise(signal);
}

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = on_terminating_signal;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGHUP, &action, nullptr);
  // A file-size limit (ulimit -f) reached while an image is written: SIGXFSZ ignored, the write
  // fails with EFBIG instead and is reported as any failed write is, and the temporary file is
  // removed (by default the signal killed the program and left it).
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, nullptr);
}

// `softrast help [COMMAND]`: the help of COMMAND (default render, as `softrast --help`).
int help_command(CLI::App& app, const std::vector<std::string>& words) {
  std::string name = words.size() > 1 ? words[1] : "render";
  std::vector<CLI::App*> commands = app.get_subcommands([](CLI::App*) { return true; });
  std::string names;
  for (CLI::App* command : commands) {
    if (command->get_name() == name && words.size() <= 2) {
      std::fputs(command->help(app.get_name()).c_str(), stdout);
      return 0;
    }
    names += (names.empty() ? "" : ", ") + command->get_name();
  }
  report_error(words.size() > 2 ? "help: expected at most one command (" + names + ")"
                                : "help: unknown command '" + name + "' (commands: " + names + ")");
  return kExitUsage;
}

// The message for an argument CLI11 did not expect: an unknown flag gets the closest known one
// ("did you mean --shader?") when it is a likely typo.
std::string unexpected_message(const CLI::App& command, const CLI::ParseError& e) {
  std::vector<std::string> extras = command.remaining();
  auto flag = std::find_if(extras.begin(), extras.end(),
                           [](const std::string& a) { return a.size() > 1 && a[0] == '-'; });
  if (flag == extras.end()) return std::string(e.what()) + " (see softrast --help)";
  std::string word = flag->substr(0, flag->find('='));
  std::vector<std::string> known;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& n : option->get_lnames()) known.push_back("--" + n);
    for (const std::string& n : option->get_snames()) known.push_back("-" + n);
  }
  std::string message = "unknown flag '" + word + "'";
  if (std::optional<std::string> close = closest_word(word, known)) {
    message += "; did you mean " + *close + "?";
  }
  return message + " (see softrast --help)";
}

// Parses and checks everything, then loads, renders and writes.
int render_command(const RawArgs& raw) {
  if (wants_sequence(raw)) return sequence_command(raw);  // --turntable, --json
  Result<JobSpec> spec = interpret(raw);
  if (!spec) {
    report_error(spec.status().message());
    return kExitUsage;
  }
  Result<Job> job = prepare(*spec);
  if (!job) {
    report_error(job.status().message());
    return kExitRuntime;
  }
  if (Status s = run_job(*job); !s.ok()) {
    report_error(s.message());
    return kExitRuntime;
  }
  return 0;
}

int run(int argc, char** argv) {
  CLI::App app{"softrast: a software rasterizer", "softrast"};
  // Flags take no value: `--wireframe=5` is an error, not a quiet `true` (inherited by the
  // subcommands, which copy the defaults when they are added).
  app.option_defaults()->disable_flag_override();
  CLI::App* render = app.add_subcommand("render", "Render a model (or the demo scene) to an image");
  RawArgs raw;
  define_render_flags(*render, raw);
  define_sequence_flags(*render, raw);
  describe(app, *render);
  CLI::App* view = app.add_subcommand("view", "Show a model (or the demo scene) in a live window");
  ViewArgs view_args;
  define_view_flags(*view, view_args);
  CLI::App* batch = app.add_subcommand("batch", "Render every job of a JSON-lines file");
  BatchArgs batch_args;
  define_batch_flags(*batch, batch_args);
  CLI::App* info = app.add_subcommand("info", "Describe models: triangles, bounds, materials");
  InfoArgs info_args;
  define_info_flags(*info, info_args);
  std::vector<std::string> words(argv + 1, argv + argc);
  if (!words.empty() && words.front() == "help") return help_command(app, words);
  try {
    std::vector<std::string> args = command_arguments(argc, argv);
    app.parse(args);
  } catch (const CLI::ExtrasError& e) {
    report_error(unexpected_message(*render, e));
    return kExitUsage;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    const CLI::App* commands[] = {render, view, batch, info};
    report_error(parse_error_message(commands, e) + " (see softrast --help)");
    return kExitUsage;
  }
  if (view->parsed()) return view_command(view_args, report_error);
  if (batch->parsed()) return batch_command(batch_args);
  if (info->parsed()) return info_command(info_args);
  return render_command(raw);
}

}  // namespace

// glibc reads its malloc tunables only when a process starts. A render allocates a few large
// buffers (decoded images, textures, the framebuffer, the output image); with glibc's defaults
// each is a fresh mapping, faulted in 4 KiB at a time and unmapped when freed, which was a third
// of the CPU time of a whole `softrast render` of a textured model. So the command line runs
// itself once more, at once, with tunables that keep freed memory for reuse and let the heap use
// transparent huge pages where the system allows them on request (madvise). Skipped when
// GLIBC_TUNABLES is already set or SOFTRAST_MALLOC_TUNING is set (to anything: 0 turns it off);
// if the exec fails, the run goes on untuned. Neither variable reaches the processes the run
// starts.
constexpr const char* kTunables =
    "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:"
    "glibc.malloc.trim_threshold=1073741824";

void tune_malloc(char** argv) {
  if (const char* mark = std::getenv("SOFTRAST_MALLOC_TUNING")) {
    if (std::string(mark) == "applied") {  // this is the tuned run: keep children untuned
      unsetenv("SOFTRAST_MALLOC_TUNING");
      unsetenv("GLIBC_TUNABLES");
    }
    return;
  }
  if (std::getenv("GLIBC_TUNABLES") != nullptr) return;
  setenv("SOFTRAST_MALLOC_TUNING", "applied", 1);
  setenv("GLIBC_TUNABLES", kTunables, 1);
  execv("/proc/self/exe", argv);
  unsetenv("SOFTRAST_MALLOC_TUNING");
  unsetenv("GLIBC_TUNABLES");
}

int main(int argc, char** argv) {
  tune_malloc(argv);
  install_signal_handlers();
  try {
    return run(argc, argv);
  } catch (const std::bad_alloc&) {
    report_error("out of memory");
  } catch (const std::exception& e) {
    report_error(e.what());
  } catch (...) {
    report_error("unexpected failure");
  }
  return kExitRuntime;
}
