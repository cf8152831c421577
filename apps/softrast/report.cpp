// apps/softrast/report.cpp: error lines, stdout records and times.

#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace softrast::cli {

void print_error(std::string message) {
  std::replace_if(
      message.begin(), message.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!message.empty() && message.back() == ' ') message.pop_back();
  std::fprintf(stderr, "softrast: error: %s\n", message.c_str());
}

bool print_line(const std::string& line) {
  return std::fputs(line.c_str(), stdout) != EOF && std::fputc('\n', stdout) != EOF &&
         std::fflush(stdout) == 0;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

double rounded(double value, int decimals) {
  double scale = std::pow(10.0, decimals);
  double r = std::round(value * scale) / scale;
  return std::isfinite(r) ? r : value;
}

}  // namespace softrast::cli
