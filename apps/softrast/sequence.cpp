// apps/softrast/sequence.cpp: turntable frames and the --json summary of a render.

#include "sequence.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "framing.hpp"
#include "progress.hpp"
#include "report.hpp"
#include "run.hpp"
#include "scene_files.hpp"
#include "setup.hpp"

namespace softrast::cli {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr int kMaxTurntableFrames = 100000;
constexpr double kPi = 3.14159265358979323846;

// An output name with one frame-number field: "frame_%03d.png" is {"frame_", 3, ".png"}.
struct FramePattern {
  std::string prefix;
  int width = 0;  // digits, zero-padded
  std::string suffix;

  std::string name(int frame) const {
    std::string digits = std::to_string(frame);
    if (int(digits.size()) < width) digits.insert(0, size_t(width) - digits.size(), '0');
    return prefix + digits + suffix;
  }
};

Status bad_pattern(const std::string& text) {
  return Status::error(
      "-o: with --turntable, the output needs one frame number field %d or %0Nd "
      "(N = 1..9 digits; %% for a percent sign), as in frame_%03d.png, or a "
      "folder ending in /; got '" +
      text + "'");
}

// Parses printf-like text with exactly one %d or %0Nd; %% is a literal percent sign.
Result<FramePattern> parse_pattern(const std::string& text) {
  FramePattern pattern;
  std::string* part = &pattern.prefix;
  bool found = false;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      *part += text[i];
      continue;
    }
    if (i + 1 < text.size() && text[i + 1] == '%') {
      *part += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    if (j < text.size() && text[j] == '0' && j + 1 < text.size() && text[j + 1] >= '1' &&
        text[j + 1] <= '9') {
      pattern.width = text[j + 1] - '0';
      j += 2;
    }
    if (found || j >= text.size() || text[j] != 'd') return bad_pattern(text);
    found = true;
    part = &pattern.suffix;
    i = j;
  }
  if (!found) return bad_pattern(text);
  return pattern;
}

// The frame files: -o PATTERN, -o FOLDER/ (FOLDER/frame_000.png, ...), or without -o
// softrast_000.png, ...; at least 3 digits, more when the frame count needs them.
Result<FramePattern> frame_pattern(const std::optional<std::string>& output, int frames) {
  int digits = std::max<int>(3, int(std::to_string(frames - 1).size()));
  std::string numbered = "%0" + std::to_string(digits) + "d";
  if (!output) return parse_pattern("softrast_" + numbered + ".png");
  std::error_code ec;
  if (!output->empty() && (output->back() == '/' || fs::is_directory(*output, ec))) {
    std::string folder = output->back() == '/' ? *output : *output + "/";
    std::string escaped;
    for (char c : folder) escaped += c == '%' ? std::string("%%") : std::string(1, c);
    return parse_pattern(escaped + "frame_" + numbered + ".png");
  }
  return parse_pattern(*output);
}

// The camera of frame `frame`: the first frame's eye turned about the up axis through the target
// (right-handed: counter-clockwise seen from above), framed as `softrast render --eye E --target
// T --up U` would frame it (near and far fitted unless given).
Camera orbit_camera(const Camera& first, const JobSpec& spec, const Bounds& bounds, float aspect,
                    int frame, int frames) {
  float angle = float(2.0 * kPi * double(frame) / double(frames));
  glm::mat3 turn(glm::rotate(glm::mat4(1.0f), angle, glm::normalize(first.up)));
  CameraFlags flags = spec.camera;
  flags.eye = first.target + turn * (first.eye - first.target);
  flags.target = first.target;
  flags.up = first.up;
  flags.fov = first.fov_y_degrees;
  if (first.orthographic) {
    flags.ortho =
        glm::vec4(first.ortho_left, first.ortho_right, first.ortho_bottom, first.ortho_top);
  }
  return frame_model(bounds, flags, aspect);
}

struct FrameRecord {
  std::string path;
  double render_ms = 0.0, write_ms = 0.0;
};

// Renders frame `frame` and writes it, through run_job's own two steps (so a turntable frame is
// drawn and written as `softrast render` draws and writes). Frame 0 keeps the prepared camera and
// light; `first` is that camera, turned for the frames after it.
Result<FrameRecord> render_frame(Job& job, const Camera& first, const JobSpec& spec,
                                 const Bounds& bounds, const std::string& path, int frame,
                                 int frames) {
  if (frame > 0) {
    float aspect = float(job.framebuffer.width()) / float(job.framebuffer.height());
    Camera camera = orbit_camera(first, spec, bounds, aspect, frame, frames);
    if (Status s = camera.validate(); !s.ok()) return s;
    job.scene.camera = camera;
    if (spec.headlight) {  // as prepare() does: the camera's frame to the world
      glm::mat3 camera_to_world = glm::transpose(glm::mat3(camera.view()));
      job.options.light_direction = camera_to_world * glm::normalize(spec.options.light_direction);
    }
  }
  FrameRecord record{path};
  record.render_ms = render_job_frame(job);
  auto start = std::chrono::steady_clock::now();
  job.output = path;
  if (Status s = write_job_image(job); !s.ok()) return s;
  record.write_ms = milliseconds_since(start);
  return record;
}

std::string summary_json(const Job& job, const std::vector<FrameRecord>& records,
                         std::optional<int> turntable, double total_ms) {
  json files = json::array();
  for (const FrameRecord& r : records) {
    files.push_back({{"path", r.path},
                     {"render_ms", rounded(r.render_ms, 3)},
                     {"write_ms", rounded(r.write_ms, 3)}});
  }
  json summary = {{"scene", job.scene.name},
                  {"source", job.scene.source},
                  {"shader", shader_kind_name(job.options.shader)},
                  {"width", job.framebuffer.width()},
                  {"height", job.framebuffer.height()},
                  {"triangles", job.scene.mesh.triangle_count()},
                  {"load_ms", rounded(job.scene.load_ms, 3)},
                  {"turntable", turntable ? json(*turntable) : json(nullptr)},
                  {"files", std::move(files)},
                  {"total_ms", rounded(total_ms, 3)}};
  return summary.dump(-1, ' ', false, json::error_handler_t::replace);
}

Status check_script_flags(const RawArgs& a) {
  if (a.turntable && (*a.turntable < 1 || *a.turntable > kMaxTurntableFrames)) {
    return Status::error("--turntable: must be in 1.." + std::to_string(kMaxTurntableFrames));
  }
  if (a.turntable && a.frames) return Status::error("--turntable and --frames cannot be combined");
  if (a.json && a.frames) {
    return Status::error("--json and --frames cannot be combined (--frames prints its own JSON)");
  }
  return {};
}

// The outputs: the frame pattern with --turntable, else the one image -o names.
Result<std::vector<std::string>> output_paths(const RawArgs& a) {
  if (!a.turntable) return std::vector<std::string>{a.output.value_or("softrast.png")};
  Result<FramePattern> pattern = frame_pattern(a.output, *a.turntable);
  if (!pattern) return pattern.status();
  std::vector<std::string> paths;
  for (int i = 0; i < *a.turntable; ++i) paths.push_back(pattern->name(i));
  return paths;
}

std::string closing_line(const std::vector<FrameRecord>& records, const Job& job, double total_ms) {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.2f", total_ms / 1000.0);
  std::string size =
      std::to_string(job.framebuffer.width()) + "x" + std::to_string(job.framebuffer.height());
  if (records.size() == 1)
    return "wrote " + records[0].path + " (" + size + ") in " + seconds + " s";
  return "wrote " + std::to_string(records.size()) + " frames " + records.front().path + " .. " +
         records.back().path + " (" + size + ") in " + seconds + " s";
}

}  // namespace

void define_sequence_flags(CLI::App& render, RawArgs& a) {
  render
      .add_option("--turntable", a.turntable,
                  "Write N frames, the camera turning 360/N degrees about the up axis between "
                  "frames (frame 0 is the plain render); -o frame_%03d.png or -o FOLDER/ "
                  "(FOLDER/frame_000.png ...; default softrast_000.png ...)")
      ->type_name("N");
  render.add_flag("--json", a.json,
                  "Print a JSON summary on stdout: scene, size, triangles, load_ms, files with "
                  "render_ms and write_ms, total_ms");
}

bool wants_sequence(const RawArgs& a) {
  return a.turntable.has_value() || a.json;
}

int sequence_command(const RawArgs& a) {
  auto start = std::chrono::steady_clock::now();
  if (Status s = check_script_flags(a); !s.ok()) {
    print_error(s.message());
    return kExitUsage;
  }
  Result<std::vector<std::string>> paths = output_paths(a);  // at least one
  RawArgs first = a;
  if (paths) first.output = paths->front();
  Result<JobSpec> spec = paths ? interpret(first) : Result<JobSpec>(paths.status());
  if (!spec) {
    print_error(spec.status().message());
    return kExitUsage;
  }
  // The frames' folder is made (-o FOLDER/), and removed again if nothing can be rendered.
  std::error_code ec;
  fs::path folder = fs::path(paths->front()).parent_path();
  bool made = a.turntable && !folder.empty() && fs::create_directories(folder, ec);
  Result<Job> job = prepare(*spec);
  if (!job) {
    if (made) fs::remove(folder, ec);
    print_error(job.status().message());
    return kExitRuntime;
  }
  if (!a.quiet) {
    std::fprintf(stderr, "loaded %s: %s in %.1f ms\n", job->scene.source.c_str(),
                 element_counts(job->scene.mesh).c_str(), job->scene.load_ms);
  }
  Bounds bounds = bounds_of(job->scene.mesh);
  int frames = int(paths->size());
  Progress progress("frames", frames, a.quiet);
  const Camera first_camera = job->scene.camera;
  job->quiet = true;  // the progress bar or the closing line instead of a line per image
  std::vector<FrameRecord> records;
  for (int i = 0; i < frames; ++i) {
    Result<FrameRecord> record =
        render_frame(*job, first_camera, *spec, bounds, (*paths)[size_t(i)], i, frames);
    if (!record) {
      if (progress.drawing()) std::fputc('\n', stderr);
      print_error(record.status().message());
      return kExitRuntime;
    }
    records.push_back(std::move(*record));
    progress.update(i + 1);
  }
  double total_ms = milliseconds_since(start);
  progress.finish(closing_line(records, *job, total_ms));
  if (a.json && !print_line(summary_json(*job, records, a.turntable, total_ms))) {
    print_error("cannot write the results to the standard output");
    return kExitRuntime;
  }
  return 0;
}

}  // namespace softrast::cli
