// tests/cli_flag_errors_test.cpp: every flag of `softrast render`, `view`, `batch` and `info`
// given a bad value ends the program with one error line that names the flag and says what it
// takes, exit status 2 (usage) and no file written. Complements cli_test.cpp's table (which checks
// the shape of the line) with the wording: a value that is not a number is "expected a number",
// a fraction where an integer belongs "expected a whole number", and a value given to a flag
// without one "takes no value", never CLI11's "Could not convert" or a flag quietly taken as true.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#ifdef SOFTRAST_CLI_PATH

namespace softrast {
namespace {

namespace fs = std::filesystem;

struct FlagError {
  const char* name;
  const char* args;      // as typed in a shell, after `softrast`
  const char* expected;  // the error line must contain this
};
void PrintTo(const FlagError& e, std::ostream* os) {
  *os << "softrast " << e.args;
}

const FlagError kFlagErrors[] = {
    // render: numbers that are not numbers.
    {"AzimuthWord", "render --azimuth east", "--azimuth: expected a number, got 'east'"},
    {"ElevationWord", "render --elevation up", "--elevation: expected a number, got 'up'"},
    {"ZoomWord", "render --zoom big", "--zoom: expected a number, got 'big'"},
    {"FovWord", "render --fov wide", "--fov: expected a number, got 'wide'"},
    {"NearWord", "render --near close", "--near: expected a number, got 'close'"},
    {"FarWord", "render --far away", "--far: expected a number, got 'away'"},
    {"AmbientWord", "render --ambient dim", "--ambient: expected a number, got 'dim'"},
    {"LightIntensityWord", "render --light-intensity x",
     "--light-intensity: expected a number, got 'x'"},
    {"AlphaWord", "render --alpha half", "--alpha: expected a number, got 'half'"},
    // render: whole numbers (a word is "expected a number" for these too).
    {"ThreadsFraction", "render --threads 1.5", "--threads: expected a whole number, got '1.5'"},
    {"FramesWord", "render --frames ten", "--frames: expected a number, got 'ten'"},
    {"QualityWord", "render --quality best -o out.jpg", "--quality: expected a number, got 'best'"},
    {"TurntableWord", "render --turntable x", "--turntable: expected a number, got 'x'"},
    {"QualityFraction", "render --quality 90.5 -o out.jpg",
     "--quality: expected a whole number, got '90.5'"},
    // render: flags given a value.
    {"WireframeValue", "render --wireframe=5", "--wireframe: takes no value"},
    {"WireframeFalse", "render --wireframe=false", "--wireframe: takes no value"},
    {"ReferencePathValue", "render --reference-path=2", "--reference-path: takes no value"},
    {"JsonValue", "render --json=yes", "--json: takes no value"},
    {"QuietValue", "render --quiet=1", "--quiet: takes no value"},
    // render: values out of range (the wording of values.cpp and setup.cpp).
    {"QualityZero", "render --quality 0 -o out.jpg", "--quality: must be in 1..100"},
    {"TurntableZero", "render --turntable 0", "--turntable: must be in 1..100000"},
    {"ThreadsTooMany", "render --threads 100000", "--threads: must be in 0..1024"},
    {"ZoomNegative", "render --zoom=-1", "--zoom: must be in (0, 1000]"},
    {"LightIntensityTooHigh", "render --light-intensity 101", "--light-intensity: must be in"},
    {"DebugUnknown", "render --debug heat", "--debug: unknown value 'heat'"},
    // view (checked before any window is opened).
    {"ViewSizeZero", "view --size 0x0", "--size: expected WIDTHxHEIGHT"},
    {"ViewThreadsWord", "view --threads many", "--threads: expected a number, got 'many'"},
    {"ViewFramesZero", "view --frames 0", "--frames: must be in"},
    {"ViewFramesFraction", "view --frames 2.5", "--frames: expected a whole number, got '2.5'"},
    {"ViewShaderUnknown", "view --shader toon", "--shader: unknown shader 'toon'"},
    {"ViewCullUnknown", "view --cull sideways", "--cull: unknown value 'sideways'"},
    {"ViewRasterUnknown", "view --raster magic", "--raster: unknown value 'magic'"},
    {"ViewDebugUnknown", "view --debug heat", "--debug: unknown value 'heat'"},
    {"ViewWireframeValue", "view --wireframe=1", "--wireframe: takes no value"},
    {"ViewContinuousValue", "view --continuous=yes", "--continuous: takes no value"},
    // batch.
    {"BatchWithoutJobs", "batch", "JOBS is required"},
    {"BatchShardPastEnd", "batch jobs.jsonl --shard 4/4", "--shard: expected K/N"},
    {"BatchShardWord", "batch jobs.jsonl --shard x", "--shard: expected K/N"},
    {"BatchDefaultsNotObject", "batch jobs.jsonl --defaults '[1]'",
     "--defaults: a job must be a JSON object"},
    {"BatchDefaultsUnknownKey", "batch jobs.jsonl --defaults '{\"sz\": 1}'",
     "--defaults: unknown key \"sz\" (did you mean \"size\"?)"},
    {"BatchForceValue", "batch jobs.jsonl --force=1", "--force: takes no value"},
    {"BatchFailFastValue", "batch jobs.jsonl --fail-fast=no", "--fail-fast: takes no value"},
    // info.
    {"InfoWithoutModel", "info", "MODEL is required"},
    {"InfoJsonValue", "info quad.obj --json=1", "--json: takes no value"},
};

class CliFlagErrorTest : public testing::TestWithParam<FlagError> {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_flags_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    std::ofstream(dir_ / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    std::ofstream(dir_ / "jobs.jsonl") << "{\"output\": \"a.png\", \"size\": \"16x16\"}\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

TEST_P(CliFlagErrorTest, OneLineNamingTheFlag) {
  const FlagError& e = GetParam();
  fs::path err = dir_ / "stderr.txt";
  // No display: a `view` whose flags were accepted would fail for that reason instead.
  std::string command = "cd '" + dir_.string() + "' && env -u DISPLAY -u WAYLAND_DISPLAY '" +
                        SOFTRAST_CLI_PATH + "' " + e.args + " >/dev/null 2>'" + err.string() +
                        "' </dev/null";
  int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << e.args;
  std::stringstream text;
  text << std::ifstream(err).rdbuf();
  std::string message = text.str();
  ASSERT_FALSE(message.empty());
  EXPECT_EQ(message.find('\n'), message.size() - 1) << "more than one line:\n" << message;
  EXPECT_EQ(message.rfind("softrast: error: ", 0), 0u) << message;
  EXPECT_NE(message.find(e.expected), std::string::npos) << message;
  for (const char* name : {"softrast.png", "out.jpg", "a.png", "softrast_000.png"}) {
    EXPECT_FALSE(fs::exists(dir_ / name)) << name << " was written";
  }
}

// A batch job with a bad value fails alone, with the same words after its file and line.
TEST(CliFlagErrorBatch, JobWithAWordForANumberNamesTheKey) {
  std::string pattern = (fs::temp_directory_path() / "softrast_flags_XXXXXX").string();
  ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
  fs::path dir = pattern;
  std::ofstream(dir / "jobs.jsonl") << "{\"output\": \"a.png\", \"size\": \"16x16\"}\n"
                                    << "{\"output\": \"b.png\", \"azimuth\": \"east\"}\n";
  fs::path err = dir / "stderr.txt";
  std::string command = "cd '" + dir.string() + "' && '" + SOFTRAST_CLI_PATH +
                        "' batch jobs.jsonl -q >/dev/null 2>'" + err.string() + "'";
  int status = std::system(command.c_str());
  std::stringstream text;
  text << std::ifstream(err).rdbuf();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << text.str();
  EXPECT_NE(text.str().find("softrast: error: jobs.jsonl:2: --azimuth: expected a number, got "
                            "'east'\n"),
            std::string::npos)
      << text.str();
  EXPECT_TRUE(fs::exists(dir / "a.png"));
  EXPECT_FALSE(fs::exists(dir / "b.png"));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Cli, CliFlagErrorTest, testing::ValuesIn(kFlagErrors),
                         [](const testing::TestParamInfo<FlagError>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace softrast

#endif  // SOFTRAST_CLI_PATH
