// apps/softrast/batch_jobs.cpp: a job line -> JSON object -> render flags -> JobSpec. The flags
// are parsed by the render command's own CLI11 definitions, so every render flag (present and
// future) works in a job, with the same checks and messages.

#include "batch_jobs.hpp"

#include <algorithm>
#include <set>
#include <string_view>
#include <utility>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "args.hpp"
#include "parse_errors.hpp"
#include "values.hpp"

namespace softrast::cli {
namespace {

using nlohmann::json;

constexpr const char* kModelKey = "model";
constexpr const char* kOutputKey = "output";

// Render flags that have no place in a job, and what to do instead.
struct Refused {
  std::string_view key, reason;
};
constexpr Refused kRefusedKeys[] = {
    {"out", "write \"output\""},
    {"frames", "a benchmark is not a batch job (run softrast render --frames)"},
    {"quiet", "give -q to softrast batch"},
    {"json", "give --json to softrast batch"},
    {"turntable", "a job writes one image: write one line per frame"},
    {"help", "not a render setting"},
    {"version", "not a render setting"},
};

std::optional<std::string_view> refusal(std::string_view key) {
  for (const Refused& r : kRefusedKeys) {
    if (r.key == key) return r.reason;
  }
  return std::nullopt;
}

// The flag spelled --`key` in `app` (which holds the render flags), or null.
const CLI::Option* long_option(const CLI::App& app, const std::string& key) {
  for (const CLI::Option* option : app.get_options()) {
    const std::vector<std::string>& names = option->get_lnames();
    if (std::find(names.begin(), names.end(), key) != names.end()) return option;
  }
  return nullptr;
}

std::vector<std::string> known_keys(const CLI::App& app) {
  std::vector<std::string> keys = {kModelKey, kOutputKey};
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) {
      if (!refusal(name)) keys.push_back(name);
    }
  }
  return keys;
}

Status unknown_key(const std::string& key, const CLI::App& app) {
  std::string closest;
  size_t best = 3;  // suggest only keys at most 2 edits away (edit_distance: values.hpp)
  for (const std::string& known : known_keys(app)) {
    size_t d = edit_distance(key, known);
    if (d < best) best = d, closest = known;
  }
  std::string hint = closest.empty() ? " (see softrast batch --help for the keys)"
                                     : " (did you mean \"" + closest + "\"?)";
  return Status::error("unknown key \"" + key + "\"" + hint);
}

// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string parse_error_text(const json::parse_error& e) {
  std::string_view text = e.what();
  if (size_t end = text.find("] "); text.rfind("[json.exception", 0) == 0 && end != text.npos) {
    text.remove_prefix(end + 2);
  }
  // The JSON is one line of the file: its "line 1" would only mislead.
  std::string message(text);
  if (size_t at = message.find("at line 1, column "); at != message.npos) {
    message.replace(at, 18, "at column ");
  }
  return message;
}

// The line as a JSON object; a key given twice is an error (JSON parsers disagree on which wins).
Result<json> parse_object(const std::string& text) {
  std::set<std::string> keys;
  std::string twice;
  auto note_keys = [&](int depth, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::key && depth == 1 &&
        !keys.insert(parsed.get<std::string>()).second && twice.empty()) {
      twice = parsed.get<std::string>();
    }
    return true;
  };
  json job;
  try {
    job = json::parse(text, note_keys);
  } catch (const json::parse_error& e) {
    return Status::error("not valid JSON: " + parse_error_text(e));
  } catch (const json::out_of_range& e) {  // a number beyond double's range, such as 1e400
    std::string what = e.what();
    size_t end = what.find("] ");  // "[json.exception.out_of_range.406] number overflow ..."
    return Status::error("not valid JSON: " +
                         (end == std::string::npos ? what : what.substr(end + 2)));
  }
  if (!job.is_object()) return Status::error("a job must be a JSON object {...}");
  if (!twice.empty()) return Status::error("key \"" + twice + "\" is given twice");
  return job;
}

Status wrong_kind(const std::string& key, const json& value, const char* expected) {
  return Status::error("\"" + key + "\": expected " + expected + ", got " + value.dump());
}

// The text a flag's value stands for: strings as they are, numbers in JSON's shortest form,
// arrays of numbers joined by commas ("size": [W, H] by an x).
Result<std::string> value_text(const std::string& key, const json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number()) return value.dump();
  bool numbers =
      value.is_array() && !value.empty() &&
      std::all_of(value.begin(), value.end(), [](const json& v) { return v.is_number(); });
  if (!numbers) return wrong_kind(key, value, "a string, a number or an array of numbers");
  std::string text, separator = key == "size" ? "x" : ",";
  for (const json& v : value) text += (text.empty() ? "" : separator) + v.dump();
  return text;
}

Status add_models(const json& value, std::vector<std::string>& models) {
  if (value.is_string()) {
    models.push_back(value.get<std::string>());
    return {};
  }
  bool strings =
      value.is_array() && !value.empty() &&
      std::all_of(value.begin(), value.end(), [](const json& v) { return v.is_string(); });
  if (!strings) return wrong_kind(kModelKey, value, "a path or an array of paths");
  for (const json& v : value) models.push_back(v.get<std::string>());
  return {};
}

// One key of the job as command-line words, appended to `flags`.
Status add_flag(const CLI::App& app, const std::string& key, const json& value,
                std::vector<std::string>& flags) {
  if (std::optional<std::string_view> reason = refusal(key)) {
    return Status::error("\"" + key + "\" has no place in a job: " + std::string(*reason));
  }
  const CLI::Option* option = long_option(app, key);
  if (!option) return unknown_key(key, app);
  if (option->get_expected_max() == 0) {  // a flag without a value
    if (!value.is_boolean()) return wrong_kind(key, value, "true or false");
    if (value.get<bool>()) flags.push_back("--" + key);
    return {};
  }
  Result<std::string> text = value_text(key, value);
  if (!text) return text.status();
  // "--key=value": a value starting with '-' is not taken for a flag.
  flags.push_back("--" + key + "=" + *text);
  return {};
}

// As many models as the render command's MODEL argument takes.
Status check_model_count(const CLI::App& app, size_t count) {
  for (const CLI::Option* option : app.get_options()) {
    if (!option->get_positional() || option->nonpositional()) continue;
    size_t most = size_t(std::max(option->get_items_expected_max(), 0));
    if (count > most) {
      return Status::error("\"model\": at most " + std::to_string(most) + " model" +
                           (most == 1 ? "" : "s") + " per job, got " + std::to_string(count));
    }
  }
  return {};
}

// The job as the words of a render command line: flags, then "--", then the models (so that a
// model path starting with '-' is not read as a flag).
Result<std::vector<std::string>> job_words(const json& job, const CLI::App& app) {
  std::vector<std::string> flags, models;
  for (const auto& [key, value] : job.items()) {
    Status s;
    if (key == kModelKey) {
      s = add_models(value, models);
    } else if (key == kOutputKey) {
      if (!value.is_string()) return wrong_kind(key, value, "a path");
      // (An empty path made "--out=" take the "--" that follows as the path.)
      if (value.get<std::string>().empty()) {
        return Status::error("\"output\" is empty: every job names the image it writes");
      }
      flags.push_back("--out=" + value.get<std::string>());
    } else {
      s = add_flag(app, key, value, flags);
    }
    if (!s.ok()) return s;
  }
  if (!job.contains(kOutputKey)) {
    return Status::error("no \"output\": every job names the image it writes");
  }
  if (Status s = check_model_count(app, models.size()); !s.ok()) return s;
  if (!models.empty()) flags.push_back("--");
  flags.insert(flags.end(), models.begin(), models.end());
  return flags;
}

}  // namespace

std::vector<JobLine> split_jobs(const std::string& content) {
  std::vector<JobLine> jobs;
  size_t line = 0;
  size_t first = content.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;  // a UTF-8 byte order mark
  for (size_t start = first; start < content.size();) {
    size_t end = std::min(content.find('\n', start), content.size());
    std::string text = content.substr(start, end - start);
    ++line;
    start = end + 1;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.find_first_not_of(" \t") == std::string::npos) continue;
    jobs.push_back({line, jobs.size(), std::move(text)});
  }
  return jobs;
}

std::optional<std::string> output_of(const std::string& text) {
  json job = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!job.is_object()) return std::nullopt;
  auto it = job.find(kOutputKey);
  if (it == job.end() || !it->is_string()) return std::nullopt;
  return it->get<std::string>();
}

Result<JobSpec> interpret_job(const std::string& text, const std::string& defaults) {
  Result<json> job = parse_object(text);
  if (!job) return job.status();
  Result<json> shared = parse_object(defaults);
  if (!shared) return shared.status();
  for (const auto& [key, value] : shared->items()) job->emplace(key, value);
  RawArgs raw;
  CLI::App app;
  define_render_flags(app, raw);
  Result<std::vector<std::string>> words = job_words(*job, app);
  if (!words) return words.status();
  std::vector<std::string> reversed(words->rbegin(), words->rend());  // CLI11 takes them reversed
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    const CLI::App* commands[] = {&app};
    return Status::error(parse_error_message(commands, e));
  }
  return interpret(raw);
}

Status check_defaults(const std::string& defaults) {
  Result<json> shared = parse_object(defaults);
  if (!shared) return shared.status();
  if (shared->contains(kOutputKey)) return Status::error("\"output\" differs from job to job");
  Result<JobSpec> spec = interpret_job("{\"output\": \"check.png\"}", defaults);
  return spec ? Status() : spec.status();
}

std::string job_keys() {
  RawArgs raw;
  CLI::App app;
  define_render_flags(app, raw);
  std::string list;
  for (const std::string& key : known_keys(app)) list += (list.empty() ? "" : ", ") + key;
  return list;
}

}  // namespace softrast::cli
