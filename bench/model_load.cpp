// bench/model_load.cpp: how fast load_model reads a file, and how much memory it takes.
//
//   build/release/bench/softrast_model_load MODEL [RUNS]
//
// Prints one line per run (ms, MB/s of file), then the median, the final mesh's bytes, and the
// process's peak resident memory (getrusage), which for this program is the loader's peak plus
// the few MiB every process has. Runs one at a time: the peak is that of one load.

#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "softrast/mesh.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: softrast_model_load MODEL [RUNS]\n");
    return 2;
  }
  int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  struct stat info {};
  double mb = stat(argv[1], &info) == 0 ? double(info.st_size) / 1e6 : 0.0;
  std::vector<double> ms;
  size_t mesh_bytes = 0;
  for (int i = 0; i < runs; ++i) {
    auto start = std::chrono::steady_clock::now();
    softrast::Result<softrast::Mesh> mesh = softrast::load_model(argv[1]);
    double t =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!mesh) {
      std::fprintf(stderr, "%s\n", mesh.status().message().c_str());
      return 1;
    }
    mesh_bytes = mesh->positions.size() * 12 + mesh->normals.size() * 12 + mesh->uvs.size() * 8 +
                 mesh->indices.size() * 4;
    ms.push_back(t);
    std::printf("run %d: %.1f ms, %.0f MB/s\n", i + 1, t, mb / (t / 1000.0));
  }
  std::sort(ms.begin(), ms.end());
  double median = ms[ms.size() / 2];
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("median %.1f ms, %.0f MB/s for %.1f MB; mesh %.1f MiB; peak RSS %.1f MiB\n", median,
              mb / (median / 1000.0), mb, double(mesh_bytes) / 1048576.0,
              double(usage.ru_maxrss) / 1024.0);
  return 0;
}
