// apps/softrast/progress.cpp: the terminal progress bar.

#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace softrast::cli {
namespace {

constexpr int kBarWidth = 30;

}  // namespace

Progress::Progress(std::string unit, int total, bool quiet)
    : unit_(std::move(unit)),
      total_(std::max(total, 1)),
      quiet_(quiet),
      drawing_(!quiet && isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

void Progress::update(int done) {
  if (!drawing_) return;
  int filled = int(int64_t(kBarWidth) * std::clamp(done, 0, total_) / total_);
  std::string bar = std::string(size_t(filled), '#') + std::string(size_t(kBarWidth - filled), '.');
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // "\r" returns to the start of the line; "\033[K" clears what a longer previous draw left.
  std::fprintf(stderr, "\r[%s] %d/%d %s  %.1f s\033[K", bar.c_str(), done, total_, unit_.c_str(),
               seconds);
  std::fflush(stderr);
}

void Progress::finish(const std::string& summary) {
  if (drawing_) std::fputc('\n', stderr);
  if (!quiet_) std::fprintf(stderr, "%s\n", summary.c_str());
}

}  // namespace softrast::cli
