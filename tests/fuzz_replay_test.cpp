// tests/fuzz_replay_test.cpp: the fuzz targets' corpora replayed through the same entry functions
// (fuzz/fuzz_entries.hpp) in the normal test pass, compiled with the project's compiler and
// without libFuzzer: every committed seed, every input fuzzing added (scripts/fuzz.sh --merge)
// and every crash it found (fuzz/regressions/TARGET/) must pass the target's checks here, so the
// corpora and the checks stay meaningful as the code changes. Under the debug preset the replay
// runs with ASan and UBSan too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"

namespace softrast::fuzz {
namespace {

namespace fs = std::filesystem;

struct Target {
  const char* name;
  int (*entry)(const uint8_t*, size_t);
};

const Target kTargets[] = {{"obj", fuzz_obj},           {"png", fuzz_image},
                           {"tga", fuzz_image},         {"jpeg", fuzz_image},
                           {"cli_args", fuzz_cli_args}, {"batch", fuzz_batch},
                           {"geometry", fuzz_geometry}, {"gltf", fuzz_gltf},
                           {"ply", fuzz_ply},           {"stl", fuzz_stl}};

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs every file of `dir` through the target; returns how many ran.
size_t replay(const Target& target, const fs::path& dir) {
  std::vector<fs::path> files = files_in(dir);
  for (const fs::path& file : files) {
    std::vector<uint8_t> bytes = read_bytes(file);
    try {
      target.entry(bytes.data(), bytes.size());
    } catch (const FuzzFailure& e) {
      ADD_FAILURE() << file.string() << ": " << e.what() << "\n(reproduce: build/fuzz/fuzz/fuzz_"
                    << target.name << " " << file.string() << ")";
    }
  }
  return files.size();
}

class FuzzReplay : public testing::TestWithParam<Target> {};

TEST_P(FuzzReplay, CorpusAndRegressionsPassTheChecks) {
  const Target& t = GetParam();
  fs::path root = SOFTRAST_FUZZ_DIR;
  size_t seeds = replay(t, root / "corpus" / t.name);
  replay(t, root / "regressions" / t.name);
  EXPECT_GE(seeds, 4u) << "the seed corpus fuzz/corpus/" << t.name << " is missing or tiny";
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, testing::ValuesIn(kTargets),
                         [](const testing::TestParamInfo<Target>& info) {
                           return std::string(info.param.name);
                         });

// The geometry target's checks are not vacuous: a right triangle whose edges run through pixel
// centres (window (6.5, 6.5), (6.5, 26.5), (26.5, 6.5): grid x = (window - 16) * 256) passes
// them, and a fill rule that kept the samples on its right or bottom edges would not.
TEST(FuzzReplay, GeometryChecksRunOnAValidTriangle) {
  std::vector<uint8_t> input = {0x04, 0x00};  // grid vertices, full scissor
  auto vertex = [&](double wx, double wy) {
    int x = int((wx - 16.0) * 256.0), y = int((wy - 16.0) * 256.0);
    input.insert(input.end(), {uint8_t(x & 255), uint8_t(x >> 8 & 255), uint8_t(y & 255),
                               uint8_t(y >> 8 & 255), 0, 0, 0, 0});
  };
  vertex(6.5, 6.5);
  vertex(6.5, 26.5);
  vertex(26.5, 6.5);
  EXPECT_NO_THROW(fuzz_geometry(input.data(), input.size()));
}

}  // namespace
}  // namespace softrast::fuzz
