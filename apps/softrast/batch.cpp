// apps/softrast/batch.cpp: the batch command: read the jobs, take this shard's, and run each one
// through interpret/prepare/run_job like `softrast render`, keeping the models jobs share.

#include "batch.hpp"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <list>
#include <map>
#include <memory>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "batch_jobs.hpp"
#include "report.hpp"
#include "run.hpp"
#include "setup.hpp"
#include "softrast/image.hpp"
#include "softrast/texture.hpp"

namespace softrast::cli {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr int64_t kMaxJobsFileBytes = int64_t(256) << 20;
constexpr int64_t kMaxShards = 1000000;
// Models and textures kept between jobs, least recently used dropped first: a mesh costs 32 bytes
// per vertex and 12 per triangle, so 1 GiB holds some 20 million triangles; 512 MiB holds 24
// textures of 2048x2048 with their mip chains. A jobs file rendering many views of each model in
// turn reads every file once.
constexpr size_t kModelCacheBytes = size_t(1) << 30;
constexpr size_t kTextureCacheBytes = size_t(512) << 20;

struct Shard {
  int64_t index = 0, count = 1;
  bool takes(size_t job) const { return int64_t(job % size_t(count)) == index; }
};

// "K/N", digits only, 0 <= K < N <= kMaxShards.
Result<Shard> parse_shard(const std::string& text) {
  Shard shard;
  size_t slash = text.find('/');
  auto whole = [](std::string_view digits, int64_t& value) {
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    return !digits.empty() && ec == std::errc() && end == digits.data() + digits.size() &&
           digits.find_first_not_of("0123456789") == digits.npos;
  };
  std::string_view view = text;
  bool ok = slash != text.npos && whole(view.substr(0, slash), shard.index) &&
            whole(view.substr(slash + 1), shard.count) && shard.count >= 1 &&
            shard.count <= kMaxShards && shard.index < shard.count;
  if (!ok) {
    return Status::error("--shard: expected K/N with 0 <= K < N <= " + std::to_string(kMaxShards) +
                         " (job i runs in shard i mod N), got '" + text + "'");
  }
  return shard;
}

Result<std::string> read_jobs(const std::string& path) {
  std::ifstream file;
  std::istream* in = &std::cin;
  if (path != "-") {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return Status::error(path + ": is a folder, not a jobs file");
    file.open(path, std::ios::binary);
    if (!file) return Status::error(path + ": cannot open the jobs file");
    in = &file;
  }
  std::string content;
  char buffer[1 << 16];
  while (in->read(buffer, sizeof buffer) || in->gcount() > 0) {
    content.append(buffer, size_t(in->gcount()));
    if (int64_t(content.size()) > kMaxJobsFileBytes) {
      return Status::error(path + ": jobs file larger than 256 MiB");
    }
  }
  if (in->bad()) return Status::error(path + ": cannot read the jobs file");
  return content;
}

// Where a path leads, independent of how a job spells it ("a.obj", "./a.obj").
std::string normal_path(const std::string& path) {
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  return (ec ? fs::path(path) : absolute).lexically_normal().string();
}

// Files read for earlier jobs, kept for later jobs naming the same path; the least recently used
// are dropped once they hold more than `max_bytes`. A job gets its own copy of a value (for a
// mesh, copying is far cheaper than parsing the OBJ again; a texture is a shared pointer). Failed
// reads are not kept, so each job naming a bad file reports it.
template <class T>
class FileCache {
 public:
  using Reader = Result<T> (*)(const std::string& path);
  using Sizer = size_t (*)(const T& value);
  FileCache(size_t max_bytes, Reader read, Sizer size)
      : max_bytes_(max_bytes), read_(read), size_(size) {}

  Result<T> get(const std::string& path) {
    std::string key = normal_path(path);
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      if (it->key != key) continue;
      entries_.splice(entries_.begin(), entries_, it);
      return it->value;
    }
    Result<T> value = read_(path);
    ++files_read_;
    if (value) keep(key, *value);
    return value;
  }
  int files_read() const { return files_read_; }

 private:
  struct Entry {
    std::string key;
    T value;
    size_t bytes;
  };

  void keep(const std::string& key, const T& value) {
    size_t bytes = size_(value);
    if (bytes > max_bytes_) return;
    while (!entries_.empty() && bytes_ + bytes > max_bytes_) {
      bytes_ -= entries_.back().bytes;
      entries_.pop_back();
    }
    entries_.push_front({key, value, bytes});
    bytes_ += bytes;
  }

  size_t max_bytes_;
  Reader read_;
  Sizer size_;
  std::list<Entry> entries_;  // most recently used first
  size_t bytes_ = 0;
  int files_read_ = 0;
};

size_t mesh_bytes(const Mesh& m) {
  return m.positions.size() * sizeof(glm::vec3) + m.normals.size() * sizeof(glm::vec3) +
         m.uvs.size() * sizeof(glm::vec2) + m.indices.size() * sizeof(uint32_t);
}

using TexturePtr = std::shared_ptr<const Texture>;

Result<TexturePtr> read_texture(const std::string& path) {
  Result<Image> image = load_image(path);
  if (!image) return image.status();
  // A colour texture, as `softrast render --texture` reads it: sRGB data.
  return TexturePtr(std::make_shared<Texture>(Texture::from_image(*image, ColorSpace::kSrgb)));
}

// The texels and their mip chain (a third more).
size_t texture_bytes(const TexturePtr& t) {
  return size_t(t->width()) * size_t(t->height()) * 4 * 4 / 3;
}

enum class Outcome { kRendered, kSkipped, kFailed };

struct JobResult {
  Outcome outcome = Outcome::kFailed;
  std::string output;   // as written in the job
  std::string message;  // the error of a failed job
  double ms = 0.0;
  int models_loaded = 0;    // model files parsed for this job (0: all from the cache)
  int textures_loaded = 0;  // texture files (--texture) decoded for this job
};

struct Batch {
  const BatchArgs& args;
  std::string name;                          // the jobs file in messages
  std::map<std::string, size_t> first_line;  // output (normal path) -> first line writing it
  FileCache<Mesh> models{kModelCacheBytes, load_model, mesh_bytes};
  FileCache<TexturePtr> textures{kTextureCacheBytes, read_texture, texture_bytes};
};

// Every output and the first line that writes it, over the whole file (all shards), so that two
// jobs writing one file fail the same way whichever shards they land in.
std::map<std::string, size_t> first_writers(const std::vector<JobLine>& jobs) {
  std::map<std::string, size_t> first;
  for (const JobLine& job : jobs) {
    if (std::optional<std::string> output = output_of(job.text)) {
      first.emplace(normal_path(*output), job.line);
    }
  }
  return first;
}

JobResult failed(JobResult result, std::string message) {
  result.outcome = Outcome::kFailed;
  result.message = std::move(message);
  return result;
}

Status make_parent_folder(const std::string& output) {
  fs::path parent = fs::path(output).parent_path();
  std::error_code ec;
  if (parent.empty() || fs::is_directory(parent, ec)) return {};
  std::error_code made;
  fs::create_directories(parent, made);
  // Another shard may have made it in the meantime: what matters is that it exists now.
  if (made && !fs::is_directory(parent, ec)) {
    return Status::error(output + ": cannot create folder '" + parent.string() +
                         "': " + made.message());
  }
  return {};
}

// Checks the job, skips it when its output exists, else renders and writes it.
JobResult run_one(const JobLine& line, Batch& batch) {
  auto start = std::chrono::steady_clock::now();
  JobResult result;
  Result<JobSpec> spec = interpret_job(line.text, batch.args.defaults);
  if (!spec) return failed(result, spec.status().message());
  result.output = spec->output.value_or("");
  auto first_writer = batch.first_line.find(normal_path(result.output));
  size_t first = first_writer == batch.first_line.end() ? line.line : first_writer->second;
  if (first != line.line) {
    return failed(result, result.output + ": also the output of line " + std::to_string(first));
  }
  std::error_code ec;
  if (!batch.args.force && fs::is_regular_file(result.output, ec)) {
    result.outcome = Outcome::kSkipped;
    return result;
  }
  if (Status s = make_parent_folder(result.output); !s.ok()) return failed(result, s.message());
  spec->quiet = true;
  int models_before = batch.models.files_read(), textures_before = batch.textures.files_read();
  Loaders loaders{[&](const std::string& path) { return batch.models.get(path); },
                  [&](const std::string& path) { return batch.textures.get(path); }};
  Result<Job> job = prepare(*spec, loaders);
  result.models_loaded = batch.models.files_read() - models_before;
  result.textures_loaded = batch.textures.files_read() - textures_before;
  if (!job) return failed(result, job.status().message());
  if (Status s = run_job(*job); !s.ok()) return failed(result, s.message());
  result.outcome = Outcome::kRendered;
  result.ms = milliseconds_since(start);
  return result;
}

const char* outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::kRendered:
      return "rendered";
    case Outcome::kSkipped:
      return "skipped";
    case Outcome::kFailed:
      return "failed";
  }
  return "failed";
}

std::string job_record(const JobLine& line, const JobResult& r) {
  json record = {{"line", line.line}, {"job", line.index}, {"status", outcome_name(r.outcome)}};
  if (!r.output.empty()) record["output"] = r.output;
  if (r.outcome == Outcome::kRendered) {
    record["ms"] = rounded(r.ms, 3);
    record["models_loaded"] = r.models_loaded;
    record["textures_loaded"] = r.textures_loaded;
  }
  if (r.outcome == Outcome::kFailed) record["error"] = r.message;
  return record.dump(-1, ' ', false, json::error_handler_t::replace);
}

// Errors always; progress lines unless quiet; the JSON record with --json.
bool report(const JobLine& line, const JobResult& r, const Batch& batch) {
  std::string where = batch.name + ":" + std::to_string(line.line) + ": ";
  if (r.outcome == Outcome::kFailed) {
    print_error(where + r.message);
  } else if (!batch.args.quiet) {
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.1f", r.ms);
    std::string what = r.outcome == Outcome::kRendered
                           ? "rendered " + r.output + " in " + ms + " ms"
                           : "skipped " + r.output + " (exists)";
    std::fprintf(stderr, "batch: %s%s\n", where.c_str(), what.c_str());
  }
  return !batch.args.json || print_line(job_record(line, r));
}

}  // namespace

void define_batch_flags(CLI::App& app, BatchArgs& a) {
  app.add_option("JOBS", a.jobs,
                 "Jobs file: one JSON object per line, one render each ('-': stdin)")
      ->required();
  app.add_option("--shard", a.shard,
                 "Run only the jobs i with i mod N = K (i counts the non-blank lines from 0)")
      ->type_name("K/N");
  app.add_option("--defaults", a.defaults,
                 "A JSON object of job keys for every job that does not give them, e.g. "
                 "'{\"threads\": 1, \"size\": \"256x256\"}'")
      ->type_name("JSON");
  app.add_flag("--force", a.force, "Render every job, replacing outputs that exist");
  app.add_flag("--fail-fast", a.fail_fast,
               "Stop at the first failed job (default: keep going, report each failure)");
  app.add_flag("--json", a.json,
               "One JSON record per job on stdout (line, job, status, output, ms, error) and a "
               "summary record last");
  app.add_flag("-q,--quiet", a.quiet, "No progress lines (errors and the summary still print)");
  app.footer(
      "Each line is one render: a JSON object whose keys are the flags of softrast render without "
      "'--', plus \"model\" (a path, or an array of paths) and \"output\" (required):\n"
      "  {\"model\": \"bunny.obj\", \"output\": \"out/bunny_front.png\", \"size\": \"256x256\",\n"
      "   \"shader\": \"phong\", \"eye\": [0, 1, 3], \"target\": \"0,0,0\", \"wireframe\": true}\n"
      "Values are strings as typed after the flag, numbers, arrays of numbers (joined by commas; "
      "size [W, H]) or true/false for flags without a value. Keys: " +
      job_keys() +
      ". Unknown keys, a key given twice, a missing output and every bad value fail the job with "
      "FILE:LINE: and the reason. Paths are relative to the current folder; an output's folder is "
      "created.\n\n"
      "A job whose output file exists is skipped (outputs appear complete or not at all: "
      "written to a temporary file, then renamed), so a killed batch resumes where it stopped "
      "when run again. A failed job does not stop the others. The last line on stderr is "
      "'batch: R rendered, S skipped, F failed'; the exit status is 1 if any job failed. Jobs "
      "sharing a model or texture read it once.\n\n"
      "Examples:\n"
      "  softrast batch jobs.jsonl\n"
      "  softrast batch jobs.jsonl --shard 2/8      # jobs 2, 10, 18, ... (one of 8 machines)\n"
      "  parallel softrast batch jobs.jsonl --shard {}/4 ::: 0 1 2 3");
}

int batch_command(const BatchArgs& args) {
  Shard shard;
  if (args.shard) {
    Result<Shard> parsed = parse_shard(*args.shard);
    if (!parsed) {
      print_error(parsed.status().message());
      return kExitUsage;
    }
    shard = *parsed;
  }
  if (Status s = check_defaults(args.defaults); !s.ok()) {
    print_error("--defaults: " + s.message());
    return kExitUsage;
  }
  Result<std::string> content = read_jobs(args.jobs);
  if (!content) {
    print_error(content.status().message());
    return kExitRuntime;
  }
  std::vector<JobLine> jobs = split_jobs(*content);
  Batch batch{args, args.jobs == "-" ? "<stdin>" : args.jobs, first_writers(jobs)};
  auto start = std::chrono::steady_clock::now();
  int counts[3] = {0, 0, 0};
  bool output_ok = true;
  for (const JobLine& line : jobs) {
    if (!shard.takes(line.index)) continue;
    JobResult result = run_one(line, batch);
    ++counts[int(result.outcome)];
    output_ok = report(line, result, batch) && output_ok;
    if (result.outcome == Outcome::kFailed && args.fail_fast) break;
  }
  int rendered = counts[0], skipped = counts[1], failed = counts[2];
  std::fprintf(stderr, "batch: %d rendered, %d skipped, %d failed\n", rendered, skipped, failed);
  if (args.json) {
    json summary = {{"summary",
                     {{"rendered", rendered},
                      {"skipped", skipped},
                      {"failed", failed},
                      {"jobs", jobs.size()},
                      {"shard", std::to_string(shard.index) + "/" + std::to_string(shard.count)},
                      {"ms", rounded(milliseconds_since(start), 3)}}}};
    output_ok = print_line(summary.dump()) && output_ok;
  }
  if (!output_ok) print_error("cannot write the results to the standard output");
  return failed > 0 || !output_ok ? kExitRuntime : 0;
}

}  // namespace softrast::cli
