// apps/softrast/run.cpp: the render loop, frame statistics and the benchmark's JSON line.

#include "run.hpp"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "scene_files.hpp"
#include "softrast/image.hpp"
#include "softrast/renderer.hpp"
#include "softrast/simd_level.hpp"

namespace softrast::cli {
namespace {

// Untimed frames before the timed ones (SCENES.md): caches, page faults, lazy allocations.
constexpr int kWarmupFrames = 2;

void progress(const Job& job, const std::string& message) {
  if (!job.quiet) std::fprintf(stderr, "%s\n", message.c_str());
}

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

std::string size_text(const Job& job) {
  return std::to_string(job.framebuffer.width()) + "x" + std::to_string(job.framebuffer.height());
}

// CPU time of the whole process (every thread), milliseconds.
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

struct FrameTime {
  double wall_ms = 0.0;
  double cpu_ms = 0.0;  // CPU time of all threads: the work, whatever else the machine runs
};

// One frame as SCENES.md defines it: clear colour (--background) and depth, draw everything.
FrameTime render_frame(Job& job) {
  auto start = std::chrono::steady_clock::now();
  double cpu_start = process_cpu_ms();
  job.framebuffer.clear(job.background, 1.0f, job.options.state.threads);
  render_mesh(job.framebuffer, job.scene.mesh, job.scene.camera, job.options);
  FrameTime t;
  t.cpu_ms = process_cpu_ms() - cpu_start;
  t.wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return t;
}

struct FrameStats {
  double median_ms, min_ms, max_ms, cpu_median_ms;
};

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Precondition: at least one frame.
FrameStats stats_of(const std::vector<FrameTime>& frames) {
  std::vector<double> wall, cpu;
  for (const FrameTime& f : frames) wall.push_back(f.wall_ms), cpu.push_back(f.cpu_ms);
  return {median_of(wall), *std::min_element(wall.begin(), wall.end()),
          *std::max_element(wall.begin(), wall.end()), median_of(cpu)};
}

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
    } else if (c < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    } else {
      out += char(c);
    }
  }
  return out + "\"";
}

// The process's peak resident memory so far, in MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return double(usage.ru_maxrss) / 1024.0;
}

std::string json_line(const Job& job, const FrameStats& s) {
  // A clock too coarse for the frame would give a zero median; the rates stay finite numbers.
  double seconds = std::max(s.median_ms, 1e-6) / 1000.0;
  double pixels = double(job.framebuffer.width()) * double(job.framebuffer.height());
  double triangles = double(job.scene.mesh.triangle_count());
  return "{\"scene\":" + json_string(job.scene.name) +
         ",\"shader\":" + json_string(shader_kind_name(job.options.shader)) +
         ",\"width\":" + std::to_string(job.framebuffer.width()) +
         ",\"height\":" + std::to_string(job.framebuffer.height()) +
         ",\"frames\":" + std::to_string(job.frames) +
         ",\"triangles\":" + std::to_string(job.scene.mesh.triangle_count()) +
         ",\"median_ms\":" + format("%.3f", s.median_ms) +
         ",\"min_ms\":" + format("%.3f", s.min_ms) + ",\"max_ms\":" + format("%.3f", s.max_ms) +
         ",\"cpu_ms\":" + format("%.3f", s.cpu_median_ms) +
         ",\"mtris_per_s\":" + format("%.3f", triangles / seconds / 1e6) +
         ",\"mpix_per_s\":" + format("%.3f", pixels / seconds / 1e6) +
         ",\"simd\":" + json_string(simd_level_name(simd_level())) +
         ",\"gathers\":" + json_string(gather_mode_name(gather_mode(simd_level()))) +
         ",\"peak_rss_mib\":" + format("%.1f", peak_rss_mib()) + "}";
}

Status benchmark(Job& job) {
  for (int i = 0; i < kWarmupFrames; ++i) render_frame(job);
  std::vector<FrameTime> times;
  for (int i = 0; i < job.frames; ++i) times.push_back(render_frame(job));
  FrameStats s = stats_of(times);
  std::string line = json_line(job, s) + "\n";
  if (std::fputs(line.c_str(), stdout) == EOF || std::fflush(stdout) != 0) {
    return Status::error("cannot write the results to the standard output");
  }
  progress(job, "rendered " + std::to_string(job.frames) + " frames of " + size_text(job) +
                    ", median " + format("%.2f", s.median_ms) + " ms");
  return {};
}

// "-o -": the PNG bytes go straight to the standard output, no temporary file.
Status write_to_stdout(const Image& image) {
  Result<std::vector<uint8_t>> png = encode_image(image, ImageFormat::kPng);
  if (!png) return Status::error("standard output: " + png.status().message());
  if (std::fwrite(png->data(), 1, png->size(), stdout) != png->size() || std::fflush(stdout) != 0) {
    return Status::error("cannot write the image to the standard output");
  }
  return {};
}

Status write_image(const Job& job) {
  bool to_stdout = *job.output == "-";
  Status s = to_stdout ? write_to_stdout(job.framebuffer.to_image())
                       : save_image(*job.output, job.framebuffer.to_image(), job.jpeg_quality);
  if (s.ok()) progress(job, "wrote " + (to_stdout ? std::string("standard output") : *job.output));
  return s;
}

}  // namespace

Status run_job(Job& job) {
  // What the render works around (a texture that cannot show, a file a model names that is
  // missing), before the progress lines; --quiet silences these too.
  if (!job.quiet) {
    for (const std::string& warning : job.scene.warnings) {
      std::fprintf(stderr, "softrast: warning: %s\n", warning.c_str());
    }
  }
  progress(job, "loaded " + job.scene.source + ": " + element_counts(job.scene.mesh) + " in " +
                    format("%.1f", job.scene.load_ms) + " ms");
  if (job.frames > 0) {
    if (Status s = benchmark(job); !s.ok()) return s;
  } else {
    // One image: each texture is drawn once, too few times to repay a copy in row pairs
    // (set_texture_row_pairs), whose memory would only raise the peak.
    const bool row_pairs = texture_row_pairs();
    set_texture_row_pairs(false);
    double ms = render_frame(job).wall_ms;
    set_texture_row_pairs(row_pairs);
    progress(job, "rendered " + size_text(job) + " in " + format("%.1f", ms) + " ms");
  }
  if (!job.output) return {};
  // The frame is drawn: give the mesh and its textures back before the output image is made, so
  // that its buffer reuses their memory (a smaller peak, and fewer fresh pages to fault in).
  job.scene.mesh = Mesh();
  job.options.texture.reset();
  return write_image(job);
}

double render_job_frame(Job& job) {
  return render_frame(job).wall_ms;
}

Status write_job_image(const Job& job) {
  return write_image(job);
}

}  // namespace softrast::cli
