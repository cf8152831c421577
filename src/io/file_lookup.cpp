// io/file_lookup.cpp: see file_lookup.hpp.
#include "io/file_lookup.hpp"

#include <algorithm>
#include <string>
#include <system_error>

#include "softrast/mesh.hpp"

namespace softrast::detail {
namespace {

namespace fs = std::filesystem;

bool present(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

// ASCII letters folded to lower case; other bytes (UTF-8 included) as they are.
std::string folded(std::string s) {
  for (char& c : s) {
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  }
  return s;
}

// The entry of folder `dir` named `name` without regard to case: the first in name order.
std::optional<fs::path> entry_ignoring_case(const fs::path& dir, const std::string& name) {
  const std::string want = folded(name);
  std::optional<std::string> best;
  std::error_code ec;
  const fs::path listed = dir.empty() ? fs::path(".") : dir;  // "" is the working folder
  for (fs::directory_iterator it(listed, ec), end; !ec && it != end; it.increment(ec)) {
    std::string entry = it->path().filename().string();
    if (folded(entry) == want && (!best || entry < *best)) best = entry;
  }
  if (!best) return std::nullopt;
  return dir / *best;
}

// `relative` under `dir`, each component matched exactly or else without regard to case.
std::optional<fs::path> walk_ignoring_case(const fs::path& dir, const fs::path& relative) {
  fs::path at = dir;
  for (const fs::path& part : relative) {
    const std::string name = part.string();
    if (name.empty() || name == ".") continue;
    if (name == ".." || present(at / part)) {
      at /= part;
      continue;
    }
    std::optional<fs::path> found = entry_ignoring_case(at, name);
    if (!found) return std::nullopt;
    at = *found;
  }
  return at;
}

}  // namespace

std::optional<FoundFile> find_named_file(const fs::path& dir, std::string_view name) {
  if (name.empty()) return std::nullopt;
  const std::string written(name);
  if (present(dir / written)) return FoundFile{dir / written, FoundAs::kWritten};
  std::string slashes = written;
  std::replace(slashes.begin(), slashes.end(), '\\', '/');
  const fs::path converted(slashes);
  if (slashes != written && present(dir / converted)) {
    return FoundFile{dir / converted, FoundAs::kWritten};
  }
  // "C:/Users/..." is a relative path here; walking it fails at "C:", as it should.
  if (converted.is_relative()) {
    if (std::optional<fs::path> found = walk_ignoring_case(dir, converted)) {
      return FoundFile{*found, FoundAs::kIgnoringCase};
    }
  }
  const fs::path file = converted.filename();
  if (file.empty() || file == converted) return std::nullopt;  // no folders to leave out
  if (present(dir / file)) return FoundFile{dir / file, FoundAs::kBeside};
  if (std::optional<fs::path> found = entry_ignoring_case(dir, file.string())) {
    return FoundFile{*found, FoundAs::kBeside};
  }
  return std::nullopt;
}

}  // namespace softrast::detail

namespace softrast {

std::optional<std::string> find_referenced_file(const std::string& folder,
                                                const std::string& name) {
  std::optional<detail::FoundFile> found = detail::find_named_file(folder, name);
  if (!found) return std::nullopt;
  return found->path.string();
}

}  // namespace softrast
