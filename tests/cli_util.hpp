// tests/cli_util.hpp: running the softrast command line from a test: a fresh folder per test,
// files written into it, the program run there as a shell would, and the images it writes.
#pragma once

#ifdef SOFTRAST_CLI_PATH

#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "softrast/image.hpp"

namespace softrast::test {

struct CliResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Single quotes for sh; a single quote inside becomes '\''.
inline std::string shell_quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

inline std::string read_whole_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A temporary folder (removed at the end) where the program runs.
class CliFolder {
 public:
  CliFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "softrast_cli_XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) root_ = pattern;
    std::filesystem::create_directories(root_ / "work");
  }
  ~CliFolder() {
    std::error_code ec;
    std::filesystem::remove_all(root_, ec);
  }
  CliFolder(const CliFolder&) = delete;
  CliFolder& operator=(const CliFolder&) = delete;

  std::filesystem::path dir() const { return root_ / "work"; }
  std::string path(const std::string& name) const { return (dir() / name).string(); }
  void write(const std::string& name, const std::string& bytes) const {
    std::filesystem::path p = dir() / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
  }

  // Runs `softrast ARGS` (ARGS as typed in a shell) in the folder.
  CliResult run(const std::string& args) const {
    std::filesystem::path out = root_ / "stdout", err = root_ / "stderr";
    std::string command =
        "cd " + shell_quote(dir().string()) + " && " + shell_quote(SOFTRAST_CLI_PATH) + " " + args +
        " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string()) + " </dev/null";
    int status = std::system(command.c_str());
    CliResult result;
    if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
    result.out = read_whole_file(out);
    result.err = read_whole_file(err);
    return result;
  }

  // Runs `softrast ARGS -o NAME` and loads the image; an empty image (and a test failure) if
  // the program fails.
  Image render(const std::string& args, const std::string& name = "out.png") const {
    CliResult r = run(args + " -q -o " + name);
    EXPECT_EQ(r.exit_code, 0) << "softrast " << args << "\n" << r.err;
    if (r.exit_code != 0) return {};
    Result<Image> image = load_image(path(name));
    EXPECT_TRUE(image.ok()) << image.status().message();
    return image.ok() ? *image : Image();
  }

 private:
  std::filesystem::path root_;
};

}  // namespace softrast::test

#endif  // SOFTRAST_CLI_PATH
