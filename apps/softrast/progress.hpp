// apps/softrast/progress.hpp: progress of a long command on stderr: a bar redrawn in place when
// stderr is a terminal, else nothing until one plain closing line (logs stay readable).
#pragma once

#include <chrono>
#include <string>

namespace softrast::cli {

class Progress {
 public:
  // `total` steps of `unit` ("frames"); nothing at all is printed when `quiet`.
  Progress(std::string unit, int total, bool quiet);
  // Whether the bar is drawn (stderr is a terminal and not quiet).
  bool drawing() const { return drawing_; }
  // `done` of the steps are complete: redraws the bar on a terminal.
  void update(int done);
  // Ends the bar's line (on a terminal) and prints `summary` as a line of its own (unless quiet).
  void finish(const std::string& summary);

 private:
  std::string unit_;
  int total_;
  bool quiet_, drawing_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace softrast::cli
