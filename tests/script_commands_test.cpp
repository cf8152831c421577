// tests/script_commands_test.cpp: the commands for scripts, run as separate processes in a fresh
// folder: `softrast batch` (sharding across parallel processes, idempotence, resuming after
// SIGTERM, bad jobs failing alone, every render flag in a job), `softrast info` and
// `softrast render --turntable / --json`.
#ifdef SOFTRAST_CLI_PATH

#include <fcntl.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "softrast/image.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A 2 x 2 square facing +z, with uvs.
constexpr const char* kQuadObj =
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";

// A cube from -1 to 1 with one normal per face, so the normals shader colours each face apart:
// +x (1, 0.5, 0.5), -x (0, 0.5, 0.5), +z (0.5, 0.5, 1), -z (0.5, 0.5, 0), ...
constexpr const char* kCubeObj =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "vn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\nvn 0 0 1\nvn 0 0 -1\n"
    "f 2//1 3//1 7//1 6//1\nf 1//2 5//2 8//2 4//2\nf 4//3 8//3 7//3 3//3\n"
    "f 1//4 2//4 6//4 5//4\nf 5//5 6//5 7//5 8//5\nf 1//6 4//6 3//6 2//6\n";

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

// Every regular file under `dir`, by path relative to it, with its bytes.
std::map<std::string, std::string> tree(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_file(e.path());
  }
  return files;
}

bool has_temporary(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.path().filename().string().find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

// Starts softrast with `args` in `dir`, stdout and stderr to files in `logs` named after `tag`;
// `env` is added to the environment. Returns the pid.
pid_t start(const fs::path& dir, const std::vector<std::string>& args, const fs::path& logs,
            const std::string& tag, const std::vector<std::string>& env = {}) {
  std::vector<std::string> env_text = env;
  for (char** e = environ; *e; ++e) env_text.emplace_back(*e);
  std::vector<std::string> arg_text = {SOFTRAST_CLI_PATH};
  arg_text.insert(arg_text.end(), args.begin(), args.end());
  std::vector<char*> envp, argv;
  for (std::string& e : env_text) envp.push_back(e.data());
  for (std::string& a : arg_text) argv.push_back(a.data());
  envp.push_back(nullptr);
  argv.push_back(nullptr);
  std::string out = (logs / (tag + ".out")).string(), err = (logs / (tag + ".err")).string();
  pid_t pid = fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    int in = open("/dev/null", O_RDONLY);
    int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (chdir(dir.c_str()) != 0 || in < 0 || o < 0 || e < 0) _exit(127);
    dup2(in, 0), dup2(o, 1), dup2(e, 2);
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

class ScriptTest : public testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_script_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    fs::create_directories(root_ / "logs");
    make_work_dir(work());
  }
  void TearDown() override { fs::remove_all(root_); }

  // A folder with the models and texture the jobs use.
  void make_work_dir(const fs::path& dir) const {
    fs::create_directories(dir);
    std::ofstream(dir / "quad.obj") << kQuadObj;
    std::ofstream(dir / "cube.obj") << kCubeObj;
    Image texture(4, 4);
    for (size_t i = 0; i < texture.rgba.size(); ++i) texture.rgba[i] = uint8_t(i * 37 % 256);
    ASSERT_TRUE(save_image((dir / "texture.png").string(), texture).ok());
  }
  fs::path work() const { return root_ / "work"; }
  void write(const fs::path& path, const std::string& text) const {
    std::ofstream(path, std::ios::binary) << text;
  }

  // `softrast ARGS` (as typed in a shell) in `dir`.
  Outcome run(const std::string& args, const fs::path& dir = {},
              const std::string& stdin_path = "/dev/null") const {
    fs::path out = root_ / "logs" / "stdout", err = root_ / "logs" / "stderr";
    std::string command = "cd " + quote((dir.empty() ? work() : dir).string()) + " && " +
                          quote(SOFTRAST_CLI_PATH) + " " + args + " >" + quote(out.string()) +
                          " 2>" + quote(err.string()) + " <" + quote(stdin_path);
    int status = std::system(command.c_str());
    Outcome r;
    if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  fs::path root_;
};

// ---------------------------------------------------------------------------------------------
// batch

// Twelve small renders: two models and the demo scene, several shaders, cameras, a texture, two
// sizes, outputs in two folders.
std::string twelve_jobs() {
  return R"({"model": "quad.obj", "output": "out/a/quad_phong.png", "size": "64x64"}
{"model": "quad.obj", "output": "out/a/quad_flat.png", "size": [64, 64], "shader": "flat"}
{"model": "cube.obj", "output": "out/b/cube_normals.png", "size": "64x64", "shader": "normals"}

{"model": "cube.obj", "output": "out/b/cube_side.png", "size": "64x64", "eye": [3, 2, 4], "target": "0,0,0"}
{"model": "cube.obj", "output": "out/b/cube_wire.png", "size": "64x64", "wireframe": true, "cull": "none"}
{"output": "out/demo.png", "size": "64x48"}
{"model": "quad.obj", "output": "out/a/quad_tex.png", "size": "64x64", "shader": "texture", "texture": "texture.png", "filter": "nearest"}
{"model": "cube.obj", "output": "out/b/cube_depth.png", "size": "64x64", "shader": "depth"}
{"model": "quad.obj", "output": "out/a/quad_gouraud.tga", "size": "64x64", "shader": "gouraud", "light": [0, 0, 1]}
{"model": "cube.obj", "output": "out/b/cube_ortho.png", "size": "64x64", "ortho": [-2, 2, -2, 2], "eye": [0, 0, 5]}
{"model": "cube.obj", "output": "out/b/cube_scanline.png", "size": "64x64", "raster": "scanline", "threads": 1}
{"model": "quad.obj", "output": "out/a/quad_alpha.png", "size": "64x64", "alpha": 0.5, "blend": "alpha"}
)";
}

// The summary line: the last line of stderr.
std::string summary(const std::string& err) {
  std::vector<std::string> lines = lines_of(err);
  return lines.empty() ? "" : lines.back();
}

TEST_F(ScriptTest, FourParallelShardsWriteExactlyTheUnshardedOutputs) {
  write(work() / "jobs.jsonl", twelve_jobs());
  Outcome whole = run("batch jobs.jsonl");
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_EQ(summary(whole.err), "batch: 12 rendered, 0 skipped, 0 failed");
  std::map<std::string, std::string> expected = tree(work() / "out");
  ASSERT_EQ(expected.size(), 12u);

  fs::path sharded = root_ / "sharded";
  make_work_dir(sharded);
  write(sharded / "jobs.jsonl", twelve_jobs());
  std::vector<pid_t> pids;
  for (int k = 0; k < 4; ++k) {
    pids.push_back(start(sharded, {"batch", "jobs.jsonl", "--shard", std::to_string(k) + "/4"},
                         root_ / "logs", "shard" + std::to_string(k)));
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(wait_exit(pids[size_t(k)]), 0) << "shard " << k;
    std::string err = read_file(root_ / "logs" / ("shard" + std::to_string(k) + ".err"));
    EXPECT_EQ(summary(err), "batch: 3 rendered, 0 skipped, 0 failed") << err;
  }
  std::map<std::string, std::string> got = tree(sharded / "out");
  EXPECT_EQ(got.size(), expected.size());
  for (const auto& [name, bytes] : expected) {
    ASSERT_TRUE(got.count(name)) << name << " missing from the sharded run";
    EXPECT_TRUE(got[name] == bytes) << name << " differs from the unsharded run";
  }
  // Every output decodes at its size (not just equal garbage).
  Result<Image> demo = load_image((work() / "out/demo.png").string());
  ASSERT_TRUE(demo.ok());
  EXPECT_EQ(demo->width, 64);
  EXPECT_EQ(demo->height, 48);
}

TEST_F(ScriptTest, SecondRunSkipsEveryCompleteOutput) {
  write(work() / "jobs.jsonl", twelve_jobs());
  ASSERT_EQ(run("batch jobs.jsonl -q").exit_code, 0);
  std::map<std::string, fs::file_time_type> times;
  for (const auto& e : fs::recursive_directory_iterator(work() / "out")) {
    times[e.path().string()] = fs::last_write_time(e.path());
  }
  Outcome again = run("batch jobs.jsonl");
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(summary(again.err), "batch: 0 rendered, 12 skipped, 0 failed");
  EXPECT_NE(again.err.find("batch: jobs.jsonl:1: skipped out/a/quad_phong.png (exists)"),
            std::string::npos)
      << again.err;
  for (const auto& [path, time] : times) EXPECT_EQ(fs::last_write_time(path), time) << path;
  // --force renders them again.
  Outcome forced = run("batch jobs.jsonl --force -q");
  EXPECT_EQ(summary(forced.err), "batch: 12 rendered, 0 skipped, 0 failed");
}

TEST_F(ScriptTest, BadJobsFailAloneWithTheirLineNumbers) {
  write(work() / "jobs.jsonl",
        "{\"model\": \"quad.obj\", \"output\": \"good1.png\", \"size\": \"32x32\"}\n"
        "{\"model\": \"quad.obj\", \"output\": \"bad.png\", \"size\": \n"                // 2
        "{\"model\": \"missing.obj\", \"output\": \"missing.png\"}\n"                    // 3
        "{\"model\": \"quad.obj\", \"output\": \"shadr.png\", \"shadr\": \"flat\"}\n"    // 4
        "{\"model\": \"quad.obj\", \"output\": \"zero.png\", \"size\": \"0x5\"}\n"       // 5
        "{\"model\": \"quad.obj\", \"size\": \"32x32\"}\n"                               // 6
        "{\"model\": \"quad.obj\", \"output\": \"good1.png\"}\n"                         // 7
        "{\"model\": \"quad.obj\", \"output\": \"x.png\", \"output\": \"y.png\"}\n"      // 8
        "{\"model\": \"quad.obj\", \"output\": \"frames.png\", \"frames\": 3}\n"         // 9
        "[1, 2]\n"                                                                       // 10
        "{\"model\": \"quad.obj\", \"output\": \"flag.png\", \"wireframe\": \"yes\"}\n"  // 11
        "{\"model\": \"quad.obj\", \"output\": \"\"}\n"                                  // 12
        "{\"model\": \"quad.obj\", \"output\": \"good2.png\", \"size\": \"32x32\"}\n");  // 13
  Outcome r = run("batch jobs.jsonl");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(summary(r.err), "batch: 2 rendered, 0 skipped, 11 failed");
  std::vector<std::string> errors;
  for (const std::string& line : lines_of(r.err)) {
    if (line.rfind("softrast: error: ", 0) == 0) errors.push_back(line.substr(17));
  }
  ASSERT_EQ(errors.size(), 11u) << r.err;
  auto starts = [](const std::string& text, const std::string& prefix) {
    return text.rfind(prefix, 0) == 0;
  };
  EXPECT_TRUE(starts(errors[0], "jobs.jsonl:2: not valid JSON: ")) << errors[0];
  EXPECT_TRUE(starts(errors[1], "jobs.jsonl:3: missing.obj: ")) << errors[1];
  EXPECT_EQ(errors[2], "jobs.jsonl:4: unknown key \"shadr\" (did you mean \"shader\"?)");
  EXPECT_TRUE(starts(errors[3], "jobs.jsonl:5: --size: ")) << errors[3];
  EXPECT_EQ(errors[4], "jobs.jsonl:6: no \"output\": every job names the image it writes");
  EXPECT_EQ(errors[5], "jobs.jsonl:7: good1.png: also the output of line 1");
  EXPECT_EQ(errors[6], "jobs.jsonl:8: key \"output\" is given twice");
  EXPECT_TRUE(starts(errors[7], "jobs.jsonl:9: \"frames\" has no place in a job")) << errors[7];
  EXPECT_EQ(errors[8], "jobs.jsonl:10: a job must be a JSON object {...}");
  EXPECT_EQ(errors[9], "jobs.jsonl:11: \"wireframe\": expected true or false, got \"yes\"");
  EXPECT_EQ(errors[10], "jobs.jsonl:12: \"output\" is empty: every job names the image it writes");
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(work())) files.insert(e.path().filename().string());
  EXPECT_EQ(files, (std::set<std::string>{"quad.obj", "cube.obj", "texture.png", "jobs.jsonl",
                                          "good1.png", "good2.png"}));
  // --fail-fast stops at the first failure.
  fs::remove(work() / "good2.png");
  Outcome fast = run("batch jobs.jsonl --fail-fast");
  EXPECT_EQ(fast.exit_code, 1);
  EXPECT_EQ(summary(fast.err), "batch: 0 rendered, 1 skipped, 1 failed");
}

TEST_F(ScriptTest, SigtermMidBatchLeavesNoTemporaryAndARerunCompletes) {
  // Six 256x256 TGAs (256 KiB, four 64 KiB chunks each): with 60 ms after each chunk a job takes
  // a quarter of a second to write, so the signal lands in the middle of the batch.
  std::string jobs;
  for (int i = 0; i < 6; ++i) {
    jobs += "{\"model\": \"cube.obj\", \"output\": \"out/f" + std::to_string(i) +
            ".tga\", \"size\": \"256x256\", \"eye\": [" + std::to_string(i) + ", 2, 4]}\n";
  }
  write(work() / "jobs.jsonl", jobs);
  pid_t pid = start(work(), {"batch", "jobs.jsonl"}, root_ / "logs", "killed",
                    {"SOFTRAST_TEST_SLOW_WRITE_MS=60"});
  ASSERT_GT(pid, 0);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  // Wait for the second job's temporary file: one output done, one half-written.
  while (std::chrono::steady_clock::now() < deadline &&
         !(fs::exists(work() / "out/f0.tga") && has_temporary(work() / "out"))) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  bool mid_write = has_temporary(work() / "out");
  kill(pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(mid_write) << "the batch never reached its second write";
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
  EXPECT_FALSE(has_temporary(work() / "out"));
  size_t done = tree(work() / "out").size();
  EXPECT_GE(done, 1u);
  EXPECT_LT(done, 6u);

  Outcome rerun = run("batch jobs.jsonl");
  EXPECT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_EQ(summary(rerun.err), "batch: " + std::to_string(6 - done) + " rendered, " +
                                    std::to_string(done) + " skipped, 0 failed");
  // The resumed outputs are those of an uninterrupted batch.
  fs::path fresh = root_ / "fresh";
  make_work_dir(fresh);
  write(fresh / "jobs.jsonl", jobs);
  ASSERT_EQ(run("batch jobs.jsonl -q", fresh).exit_code, 0);
  EXPECT_TRUE(tree(work() / "out") == tree(fresh / "out"));
}

TEST_F(ScriptTest, AJobIsTheRenderCommandWithTheSameFlags) {
  write(
      work() / "jobs.jsonl",
      R"({"model": "quad.obj", "output": "job.png", "size": [40, 30], "shader": "gouraud", "cull": "none", "front-face": "cw", "depth": "lequal", "blend": "alpha", "alpha": 0.5, "raster": "scanline", "filter": "nearest", "wrap": "clamp", "wireframe": true, "threads": 1, "color": [0.2, 0.4, 0.6], "fov": 60, "near": 0.5, "far": 50, "eye": [0.5, -0.25, 5], "target": "0,0,0", "up": [0, 1, 0], "reference-path": true, "light": "1,1,1"}
{"model": "quad.obj", "output": "tex.png", "size": "40x30", "shader": "texture", "texture": "texture.png", "wrap": "mirror", "ortho": [-2, 2, -1.5, 1.5], "near": -1, "far": 10}
)");
  Outcome batch = run("batch jobs.jsonl");
  ASSERT_EQ(batch.exit_code, 0) << batch.err;
  Outcome plain = run(
      "render quad.obj -o plain.png --size 40x30 --shader gouraud --cull none --front-face cw "
      "--depth lequal --blend alpha --alpha 0.5 --raster scanline --filter nearest --wrap clamp "
      "--wireframe --threads 1 --color 0.2,0.4,0.6 --fov 60 --near 0.5 --far 50 "
      "--eye 0.5,-0.25,5 --target 0,0,0 --up 0,1,0 --reference-path --light 1,1,1");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  Outcome tex =
      run("render quad.obj -o plain_tex.png --size 40x30 --shader texture --texture texture.png "
          "--wrap mirror --ortho -2,2,-1.5,1.5 --near -1 --far 10");
  ASSERT_EQ(tex.exit_code, 0) << tex.err;
  EXPECT_TRUE(read_file(work() / "job.png") == read_file(work() / "plain.png"));
  EXPECT_TRUE(read_file(work() / "tex.png") == read_file(work() / "plain_tex.png"));
}

TEST_F(ScriptTest, JsonRecordsAndFilesReadOnce) {
  std::string jobs;
  for (const char* model : {"quad.obj", "cube.obj", "./quad.obj", "cube.obj", "quad.obj"}) {
    jobs += "{\"model\": \"" + std::string(model) + "\", \"output\": \"o" +
            std::to_string(jobs.size()) +
            ".png\", \"size\": \"16x16\", \"texture\": " + "\"texture.png\"}\n";
  }
  write(work() / "jobs.jsonl", jobs);
  Outcome r = run("batch jobs.jsonl --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 6u) << r.out;
  std::vector<int> loads, textures;
  for (size_t i = 0; i < 5; ++i) {
    json record = json::parse(lines[i]);
    EXPECT_EQ(record["line"], i + 1);
    EXPECT_EQ(record["job"], i);
    EXPECT_EQ(record["status"], "rendered");
    EXPECT_TRUE(fs::exists(work() / record["output"].get<std::string>()));
    EXPECT_GE(record["ms"].get<double>(), 0.0);
    loads.push_back(record["models_loaded"].get<int>());
    textures.push_back(record["textures_loaded"].get<int>());
  }
  EXPECT_EQ(loads, (std::vector<int>{1, 1, 0, 0, 0}));
  EXPECT_EQ(textures, (std::vector<int>{1, 0, 0, 0, 0}));
  json last = json::parse(lines[5]);
  EXPECT_EQ(last["summary"]["rendered"], 5);
  EXPECT_EQ(last["summary"]["skipped"], 0);
  EXPECT_EQ(last["summary"]["failed"], 0);
  EXPECT_EQ(last["summary"]["shard"], "0/1");
  // The jobs can come from stdin; now all exist.
  Outcome piped = run("batch - --json -q", work(), (work() / "jobs.jsonl").string());
  EXPECT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(json::parse(lines_of(piped.out).back())["summary"]["skipped"], 5);
}

TEST_F(ScriptTest, ShardMustBeKOverNWithKBelowN) {
  write(work() / "jobs.jsonl", "{\"output\": \"a.png\"}\n");
  for (const char* shard : {"4/4", "1/0", "a/b", "1", "-1/4", "1/4x", "/4", "0/1000001"}) {
    Outcome r = run(std::string("batch jobs.jsonl --shard '") + shard + "'");
    EXPECT_EQ(r.exit_code, 2) << shard;
    EXPECT_EQ(r.err,
              "softrast: error: --shard: expected K/N with 0 <= K < N <= 1000000 (job i "
              "runs in shard i mod N), got '" +
                  std::string(shard) + "'\n");
  }
  Outcome missing = run("batch nothing.jsonl");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(missing.err, "softrast: error: nothing.jsonl: cannot open the jobs file\n");
  EXPECT_FALSE(fs::exists(work() / "a.png"));
  // A shard past the number of jobs has nothing to do.
  Outcome empty = run("batch jobs.jsonl --shard 3/5");
  EXPECT_EQ(empty.exit_code, 0);
  EXPECT_EQ(summary(empty.err), "batch: 0 rendered, 0 skipped, 0 failed");
}

TEST_F(ScriptTest, DefaultsFillWhatAJobDoesNotGive) {
  write(work() / "jobs.jsonl",
        "{\"model\": \"quad.obj\", \"output\": \"d.png\"}\n"
        "{\"model\": \"quad.obj\", \"output\": \"own.png\", \"size\": \"8x6\"}\n");
  Outcome r = run("batch jobs.jsonl --defaults '{\"size\": [20, 10], \"shader\": \"flat\"}'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<Image> d = load_image((work() / "d.png").string());
  Result<Image> own = load_image((work() / "own.png").string());
  ASSERT_TRUE(d.ok() && own.ok());
  EXPECT_EQ(d->width, 20);
  EXPECT_EQ(own->width, 8);
  ASSERT_EQ(run("render quad.obj --size 20x10 --shader flat -o plain.png").exit_code, 0);
  EXPECT_TRUE(read_file(work() / "d.png") == read_file(work() / "plain.png"));
  for (const char* bad :
       {"'{\"sise\": 1}'", "'{\"output\": \"x.png\"}'", "'[1]'", "'{\"size\": \"0x0\"}'"}) {
    Outcome b = run(std::string("batch jobs.jsonl --force --defaults ") + bad);
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_EQ(b.err.rfind("softrast: error: --defaults: ", 0), 0u) << b.err;
    EXPECT_EQ(lines_of(b.err).size(), 1u) << b.err;
  }
}

// The text after `key` in `text` up to the end of its line.
std::string rest_of_line(const std::string& text, const std::string& key) {
  size_t at = text.find(key);
  if (at == std::string::npos) return "";
  at += key.size();
  return text.substr(at, text.find('\n', at) - at);
}

// The jobs each process rendered and skipped, from the summary record its --json output ends with.
std::pair<int, int> rendered_and_skipped(const fs::path& stdout_log) {
  std::vector<std::string> lines = lines_of(read_file(stdout_log));
  if (lines.empty()) return {-1, -1};
  json summary = json::parse(lines.back())["summary"];
  return {summary["rendered"].get<int>(), summary["skipped"].get<int>()};
}

// The Kubernetes manifest and the Slurm script of docs/batch/ run as their schedulers would run
// them (one process per index, with the variables they set; srun a pass-through): together they
// render every job once. docs/batch.md shows both files word for word.
TEST_F(ScriptTest, ClusterFilesInDocsRunEveryJobOnce) {
  fs::path docs = SOFTRAST_DOCS_DIR;
  std::string manifest = read_file(docs / "batch/indexed-job.yaml");
  std::string script = read_file(docs / "batch/job-array.sbatch");
  std::string guide = read_file(docs / "batch.md");
  EXPECT_NE(guide.find(manifest), std::string::npos) << "batch.md differs from the manifest";
  EXPECT_NE(guide.find(script), std::string::npos) << "batch.md differs from the script";
  write(work() / "jobs.jsonl", twelve_jobs());
  fs::path bin = fs::path(SOFTRAST_CLI_PATH).parent_path(), shim = root_ / "shim";
  fs::create_directories(shim);
  write(shim / "srun", "#!/bin/sh\nexec \"$@\"\n");
  fs::permissions(shim / "srun", fs::perms::owner_all);
  std::string path = "PATH=" + quote(shim.string() + ":" + bin.string()) + ":\"$PATH\" ";

  int pods = std::atoi(rest_of_line(manifest, "completions: ").c_str());
  std::string command = rest_of_line(manifest, "args:\n            - ");
  ASSERT_EQ(pods, 8);
  ASSERT_NE(command.find("--shard"), std::string::npos) << command;
  // Slurm: --array=FIRST-LAST.
  std::string range = rest_of_line(script, "#SBATCH --array=");
  int first = std::atoi(range.c_str()), last = std::atoi(range.substr(range.find('-') + 1).c_str());
  ASSERT_EQ(first, 0);
  ASSERT_EQ(last, 7);

  for (const char* scheduler : {"kubernetes", "slurm"}) {
    SCOPED_TRACE(scheduler);
    fs::remove_all(work() / "out");
    int rendered = 0, skipped = 0;
    for (int k = 0; k < 8; ++k) {
      fs::path out = root_ / "logs" / (scheduler + std::to_string(k));
      std::string index = std::to_string(k);
      std::string run_one =
          std::string(scheduler) == "kubernetes"
              ? "JOB_COMPLETION_INDEX=" + index + " " + path + "sh -c " + quote(command)
              : "SLURM_ARRAY_TASK_ID=" + index + " SLURM_SUBMIT_DIR=" + quote(work().string()) +
                    " " + path + "bash " + quote((docs / "batch/job-array.sbatch").string());
      std::string line = "cd " + quote(work().string()) + " && " + run_one + " >" +
                         quote(out.string()) + " 2>/dev/null </dev/null";
      ASSERT_EQ(std::system(line.c_str()), 0) << line;
      auto [r, s] = rendered_and_skipped(out);
      rendered += r, skipped += s;
    }
    EXPECT_EQ(rendered, 12);
    EXPECT_EQ(skipped, 0);
    EXPECT_EQ(tree(work() / "out").size(), 12u);
  }
}

TEST_F(ScriptTest, HelpDocumentsTheScriptCommands) {
  Outcome r = run("batch --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* text : {"--shard", "K/N", "--force", "--fail-fast", "--json", "--defaults",
                           "\"model\"", "\"output\"", "size", "shader", "eye", "texture",
                           "reference-path", "skipped", "batch: R rendered, S skipped, F failed"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << "batch --help does not mention " << text;
  }
  Outcome render = run("--help");
  EXPECT_EQ(render.exit_code, 0);
  for (const char* text :
       {"--turntable", "--json", "frame_%03d.png", "FOLDER/", "softrast info", "softrast batch"}) {
    EXPECT_NE(render.out.find(text), std::string::npos) << "--help does not mention " << text;
  }
  Outcome info = run("info --help");
  EXPECT_EQ(info.exit_code, 0);
  for (const char* text : {"MODEL", "--json", "bounds", "MISSING"}) {
    EXPECT_NE(info.out.find(text), std::string::npos) << "info --help does not mention " << text;
  }
}

// ---------------------------------------------------------------------------------------------
// info

TEST_F(ScriptTest, InfoReportsGeometryMaterialsAndMaps) {
  write(work() / "parts.mtl",
        "newmtl red\nKd 1 0 0\nmap_Kd texture.png\nmap_Bump -bm 0.5 bump.png\n"
        "newmtl plain\nKd 0 0.5 1\n");
  write(work() / "parts.obj",
        "mtllib parts.mtl gone.mtl\n"
        "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 -3\nv 5 5 5\nvt 0 0\nvt 1 0\nvt 1 1\n"
        "usemtl red\nf 1/1 2/2 3/3\nf 1/1 3/3 4/3\n"
        "usemtl plain\nf 2 3 5\n");
  Outcome r = run("info parts.obj --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  json info = json::parse(lines[0]);
  EXPECT_EQ(info["model"], "parts.obj");
  EXPECT_EQ(info["triangles"], 3);
  EXPECT_EQ(info["file"]["positions"], 5);
  EXPECT_EQ(info["file"]["texcoords"], 3);
  EXPECT_EQ(info["file"]["normals"], 0);
  EXPECT_EQ(info["file"]["faces"], 3);
  EXPECT_EQ(info["bounds"]["min"], json::parse("[0, 0, -3]"));
  EXPECT_EQ(info["bounds"]["max"], json::parse("[5, 5, 5]"));
  EXPECT_EQ(info["bounds"]["size"], json::parse("[5, 5, 8]"));
  EXPECT_EQ(info["bounds"]["center"], json::parse("[2.5, 2.5, 1]"));
  ASSERT_EQ(info["submeshes"].size(), 2u);
  EXPECT_EQ(info["submeshes"][0]["material"], "red");
  EXPECT_EQ(info["submeshes"][0]["triangles"], 2);
  EXPECT_EQ(info["submeshes"][1]["material"], "plain");
  EXPECT_EQ(info["submeshes"][1]["triangles"], 1);
  ASSERT_EQ(info["libraries"].size(), 2u);
  EXPECT_EQ(info["libraries"][0]["path"], "parts.mtl");
  EXPECT_EQ(info["libraries"][0]["found"], true);
  EXPECT_EQ(info["libraries"][1]["path"], "gone.mtl");
  EXPECT_EQ(info["libraries"][1]["found"], false);
  ASSERT_EQ(info["materials"].size(), 2u);
  json red = info["materials"][0];
  EXPECT_EQ(red["name"], "red");
  EXPECT_EQ(red["diffuse"], json::parse("[1, 0, 0]"));
  EXPECT_EQ(red["diffuse_map_loaded"], true);
  EXPECT_EQ(red["uv_scale"], json::parse("[1, 1]"));  // no -s, -o or -clamp: as the file's uvs
  EXPECT_EQ(red["clamp_maps"], false);
  ASSERT_EQ(red["maps"].size(), 2u);
  EXPECT_EQ(red["maps"][0]["kind"], "map_Kd");
  EXPECT_EQ(red["maps"][0]["path"], "texture.png");
  EXPECT_EQ(red["maps"][0]["found"], true);
  EXPECT_EQ(red["maps"][1]["kind"], "map_Bump");
  EXPECT_EQ(red["maps"][1]["path"], "bump.png");
  EXPECT_EQ(red["maps"][1]["found"], false);
  EXPECT_EQ(info["materials"][1]["diffuse_map_loaded"], false);
  EXPECT_EQ(info["materials"][1]["maps"].size(), 0u);
  // Vertices: one per distinct corner (position/uv pairs 1/1 2/2 3/3 4/3, then 2 3 5 without uv).
  EXPECT_EQ(info["vertices"], 7);

  Outcome text = run("info parts.obj");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const char* part :
       {"parts.obj\n", "  triangles  3\n", "bounds     min 0 0 -3  max 5 5 5",
        "  mtllib     gone.mtl (MISSING)\n", "      map_Kd texture.png (found)\n",
        "      map_Bump bump.png (MISSING)\n", "    red: 2 triangles\n"}) {
    EXPECT_NE(text.out.find(part), std::string::npos) << "no '" << part << "' in\n" << text.out;
  }
  EXPECT_EQ(text.out.find("maps placed"), std::string::npos) << text.out;
}

// info resolves the files a model names as the render does (find_referenced_file): a map name
// after options and with a space, Windows separators and another case; one from another
// machine's folder, found beside the material.
TEST_F(ScriptTest, InfoResolvesMapsAsTheRenderDoes) {
  fs::create_directories(work() / "tex");
  write(work() / "tex" / "my tex.png", "x");
  write(work() / "spec.png", "x");
  write(work() / "m.mtl",
        "newmtl a\nmap_Kd -s 2 2 1 -clamp on TEX\\My Tex.PNG\nmap_Ks C:\\art\\spec.png\n");
  write(work() / "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  Outcome r = run("info m.obj --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json info = json::parse(lines_of(r.out).at(0));
  json maps = info["materials"][0]["maps"];
  ASSERT_EQ(maps.size(), 2u) << r.out;
  EXPECT_EQ(maps[0]["path"], "TEX\\My Tex.PNG");
  EXPECT_EQ(maps[0]["found"], true);
  EXPECT_EQ(fs::path(maps[0]["resolved"].get<std::string>()).filename(), "my tex.png");
  EXPECT_EQ(maps[1]["path"], "C:\\art\\spec.png");
  EXPECT_EQ(maps[1]["found"], true);
  EXPECT_EQ(fs::path(maps[1]["resolved"].get<std::string>()).filename(), "spec.png");
  // map_Kd's -s and -clamp place every map of the material, and info says so.
  EXPECT_EQ(info["materials"][0]["uv_scale"], json::parse("[2, 2]"));
  EXPECT_EQ(info["materials"][0]["uv_offset"], json::parse("[0, 0]"));
  EXPECT_EQ(info["materials"][0]["clamp_maps"], true);
  Outcome text = run("info m.obj");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("      maps placed at uv * (2 2) + (0 0), clamped to the edge\n"),
            std::string::npos)
      << text.out;
}

// info on a PLY and a glTF file: no OBJ statement counts (they would all be 0) and no MTL
// libraries; the glTF's material as loaded, unnamed ones said so.
TEST_F(ScriptTest, InfoOnPlyAndGltfListsWhatTheyHold) {
  write(work() / "tri.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  fs::copy_file(fs::path(SOFTRAST_FUZZ_DIR) / "corpus" / "gltf" / "cube.glb", work() / "cube.glb");
  Outcome r = run("info tri.ply cube.glb --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 2u) << r.out;
  json ply = json::parse(lines[0]), glb = json::parse(lines[1]);
  EXPECT_EQ(ply["triangles"], 1);
  EXPECT_FALSE(ply.contains("file"));
  EXPECT_FALSE(ply.contains("libraries"));
  EXPECT_EQ(ply["materials"].size(), 0u);
  EXPECT_EQ(glb["triangles"], 12);
  EXPECT_FALSE(glb.contains("file"));
  ASSERT_EQ(glb["materials"].size(), 1u);
  EXPECT_EQ(glb["materials"][0]["pbr"], true);
  EXPECT_EQ(glb["materials"][0]["diffuse_map_loaded"], true);
  Outcome text = run("info cube.glb");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_EQ(text.out.find("(the file:"), std::string::npos) << text.out;
  for (const char* part : {"  vertices   24\n", "    (unnamed material): 12 triangles\n",
                           "  materials  1\n", "    (unnamed)  Kd 1 1 1  (metallic-roughness)"}) {
    EXPECT_NE(text.out.find(part), std::string::npos) << "no '" << part << "' in\n" << text.out;
  }
}

TEST_F(ScriptTest, InfoOnABrokenModelSaysWhyAndStillListsItsFiles) {
  write(work() / "broken.mtl", "newmtl skin\nmap_Kd skin.png\n");
  write(work() / "broken.obj",
        "mtllib broken.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl skin\nf 1 2 3\n");
  Outcome r = run("info broken.obj missing.obj quad.obj --json");
  EXPECT_EQ(r.exit_code, 1);
  std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;
  json broken = json::parse(lines[0]), missing = json::parse(lines[1]),
       quad = json::parse(lines[2]);
  // A missing map is the loader's warning (the model still loads and renders), not an error.
  EXPECT_FALSE(broken.contains("error"));
  ASSERT_TRUE(broken.contains("warnings")) << lines[0];
  EXPECT_NE(broken["warnings"][0].get<std::string>().find("skin.png"), std::string::npos);
  EXPECT_EQ(broken["triangles"], 1);
  EXPECT_EQ(broken["materials"][0]["maps"][0]["found"], false);
  EXPECT_TRUE(missing.contains("error"));
  EXPECT_FALSE(quad.contains("error"));
  EXPECT_EQ(quad["triangles"], 2);
  // One error line for the model that failed, one warning line for the missing map.
  std::vector<std::string> err = lines_of(r.err);
  ASSERT_EQ(err.size(), 2u) << r.err;
  EXPECT_EQ(err[0].rfind("softrast: warning: ", 0), 0u) << r.err;
  EXPECT_EQ(err[1].rfind("softrast: error: ", 0), 0u) << r.err;
}

// ---------------------------------------------------------------------------------------------
// render --turntable, --json

std::vector<int> centre(const fs::path& path) {
  Result<Image> image = load_image(path.string());
  EXPECT_TRUE(image.ok()) << path;
  if (!image) return {};
  const uint8_t* p = image->pixel(image->width / 2, image->height / 2);
  return {p[0], p[1], p[2]};
}

TEST_F(ScriptTest, TurntableWritesNFramesAroundTheUpAxis) {
  Outcome r = run("render cube.obj --shader normals --size 64x64 --turntable 4 -o frame_%03d.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(fs::exists(work() / ("frame_00" + std::to_string(i) + ".png"))) << i;
  }
  EXPECT_FALSE(fs::exists(work() / "frame_004.png"));
  // Frame 0 is the plain render, byte for byte.
  ASSERT_EQ(run("render cube.obj --shader normals --size 64x64 -o plain.png").exit_code, 0);
  EXPECT_TRUE(read_file(work() / "frame_000.png") == read_file(work() / "plain.png"));
  // The eye turns counter-clockwise seen from above (+y): +z, +x, -z, -x faces in turn.
  std::vector<int> f0 = centre(work() / "frame_000.png"), f1 = centre(work() / "frame_001.png"),
                   f2 = centre(work() / "frame_002.png"), f3 = centre(work() / "frame_003.png");
  EXPECT_EQ(f0, (std::vector<int>{128, 128, 255}));  // +z
  EXPECT_EQ(f1, (std::vector<int>{255, 128, 128}));  // +x
  EXPECT_EQ(f2, (std::vector<int>{128, 128, 0}));    // -z
  EXPECT_EQ(f3, (std::vector<int>{0, 128, 128}));    // -x
  // Not a terminal: one plain closing line, no bar.
  EXPECT_NE(r.err.find("wrote 4 frames frame_000.png .. frame_003.png (64x64) in "),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
}

// Frame i is the render from the turned eye, lit by the headlight turned with it: half a turn
// from +z equals the plain render from -z (within 2/255: the turned eye is off by 4e-7 in x). A
// light left where frame 0 had it would leave the far face at its ambient level.
TEST_F(ScriptTest, TurntableFramesAreRendersFromTheTurnedEye) {
  Outcome r =
      run("render cube.obj --shader gouraud --size 48x48 --eye 0,0,5 --target 0,0,0 --turntable 2 "
          "-o half_%d.png -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(
      run("render cube.obj --shader gouraud --size 48x48 --eye 0,0,-5 --target 0,0,0 -o back.png")
          .exit_code,
      0);
  Result<Image> turned = load_image((work() / "half_1.png").string());
  Result<Image> back = load_image((work() / "back.png").string());
  ASSERT_TRUE(turned.ok() && back.ok());
  int worst = 0;
  for (size_t i = 0; i < back->rgba.size(); ++i) {
    worst = std::max(worst, std::abs(int(turned->rgba[i]) - int(back->rgba[i])));
  }
  EXPECT_LE(worst, 2);
  std::vector<int> lit = centre(work() / "back.png");
  EXPECT_GT(lit[0], int(0.9 * 0.15 * 255) + 20) << "the face towards the eye is lit";
}

TEST_F(ScriptTest, TurntableIntoAFolderWithJsonSummary) {
  Outcome r = run("render quad.obj --size 32x32 --turntable 12 -o spin/ --json -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  json summary = json::parse(r.out);
  EXPECT_EQ(summary["turntable"], 12);
  EXPECT_EQ(summary["width"], 32);
  EXPECT_EQ(summary["triangles"], 2);
  ASSERT_EQ(summary["files"].size(), 12u);
  for (int i = 0; i < 12; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "spin/frame_%03d.png", i);
    EXPECT_EQ(summary["files"][size_t(i)]["path"], name);
    EXPECT_GE(summary["files"][size_t(i)]["render_ms"].get<double>(), 0.0);
    EXPECT_TRUE(fs::exists(work() / name)) << name;
  }
  EXPECT_EQ(tree(work() / "spin").size(), 12u);
  // --json on a plain render: one file.
  Outcome one = run("render quad.obj --size 32x32 -o one.png --json");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  json single = json::parse(one.out);
  EXPECT_EQ(single["files"].size(), 1u);
  EXPECT_EQ(single["files"][0]["path"], "one.png");
  EXPECT_TRUE(single["turntable"].is_null());
}

TEST_F(ScriptTest, TurntableDrawsABarOnATerminal) {
  int master = -1, slave = -1;
  ASSERT_EQ(openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
  std::string out = (root_ / "logs" / "tty.out").string();
  pid_t pid = fork();
  if (pid == 0) {
    int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (chdir(work().c_str()) != 0 || o < 0) _exit(127);
    dup2(o, 1), dup2(slave, 2);
    execl(SOFTRAST_CLI_PATH, SOFTRAST_CLI_PATH, "render", "quad.obj", "--size", "16x16",
          "--turntable", "5", "-o", "t_%d.png", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(slave);
  std::string err;
  char buffer[4096];
  for (ssize_t n; (n = read(master, buffer, sizeof buffer)) > 0;) err.append(buffer, size_t(n));
  close(master);
  EXPECT_EQ(wait_exit(pid), 0);
  EXPECT_NE(err.find("\r[##############################] 5/5 frames"), std::string::npos) << err;
  EXPECT_NE(err.find("wrote 5 frames t_0.png .. t_4.png"), std::string::npos) << err;
}

TEST_F(ScriptTest, TurntableRefusesBadValues) {
  struct Case {
    const char* args;
    const char* error;
  };
  const Case cases[] = {
      {"quad.obj --turntable 0 -o f_%d.png", "--turntable: must be in 1..100000"},
      {"quad.obj --turntable 3 -o out.png",
       "-o: with --turntable, the output needs one frame number field %d or %0Nd (N = 1..9 "
       "digits; %% for a percent sign), as in frame_%03d.png, or a folder ending in /; got "
       "'out.png'"},
      {"quad.obj --turntable 3 -o f_%d_%d.png", nullptr},
      {"quad.obj --turntable 3 -o f_%s.png", nullptr},
      {"quad.obj --turntable 3 --frames 2", "--turntable and --frames cannot be combined"},
      {"quad.obj --json --frames 2",
       "--json and --frames cannot be combined (--frames prints its own JSON)"},
      {"quad.obj --turntable 3 -o f_%d.gif",
       "f_0.gif: unknown image format (the output must end in .png, .jpg or .tga, or be - for the "
       "standard output)"},
  };
  for (const Case& c : cases) {
    Outcome r = run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    ASSERT_EQ(lines_of(r.err).size(), 1u) << c.args << "\n" << r.err;
    if (c.error) {
      EXPECT_EQ(r.err, "softrast: error: " + std::string(c.error) + "\n") << c.args;
    }
  }
  Outcome missing = run("missing.obj --turntable 3 -o gone/");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_FALSE(fs::exists(work() / "gone"));
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(work())) files.insert(e.path().filename().string());
  EXPECT_EQ(files, (std::set<std::string>{"quad.obj", "cube.obj", "texture.png"}));
}

}  // namespace
}  // namespace softrast

#endif  // SOFTRAST_CLI_PATH
