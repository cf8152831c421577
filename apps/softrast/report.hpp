// apps/softrast/report.hpp: what the script-facing commands (batch, info, turntable) print: error
// lines in the program's one format, JSON lines on stdout, and times in milliseconds.
#pragma once

#include <chrono>
#include <string>

namespace softrast::cli {

// The exit codes of main.cpp: 1 runtime error (files, failed jobs), 2 usage error (flags).
inline constexpr int kExitRuntime = 1;
inline constexpr int kExitUsage = 2;

// "softrast: error: MESSAGE" on stderr, the message kept on one line.
void print_error(std::string message);

// `line` and a newline on stdout, flushed at once (a script reading a pipe sees each record as it
// is done); false when stdout cannot be written.
bool print_line(const std::string& line);

double milliseconds_since(std::chrono::steady_clock::time_point start);

// `value` rounded to `decimals` places, for JSON numbers that read as the human output does
// (a float converted to double would print 0.30000001192092896).
double rounded(double value, int decimals);

}  // namespace softrast::cli
