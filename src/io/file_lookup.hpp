// io/file_lookup.hpp: the files a model names (MTL libraries, texture maps), found the way the
// model's author meant them.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>

namespace softrast::detail {

// How find_named_file found a file.
enum class FoundAs {
  kWritten,       // the path as written (or with its backslashes read as folder separators)
  kIgnoringCase,  // its folders and name matched without regard to case
  kBeside,        // its folders do not exist here: the file of its name in `dir`
};

struct FoundFile {
  std::filesystem::path path;
  FoundAs how = FoundAs::kWritten;
};

// The file that `name`, as a model file writes it, means relative to `dir`:
//   1. the path as written, if it exists;
//   2. with backslashes read as folder separators (files written on Windows: "tex\wood.png");
//   3. each folder and the file name matched without regard to case ("Wood.PNG" on disk for
//      "wood.png" in the file), the first match in name order where several differ only by case;
//   4. where the folders do not exist here (an absolute path from the author's machine,
//      "C:\Users\me\wood.png"), the file of that name in `dir`, again without regard to case.
// nullopt when none exists. Folders are listed only when the path as written is missing.
std::optional<FoundFile> find_named_file(const std::filesystem::path& dir, std::string_view name);

}  // namespace softrast::detail
