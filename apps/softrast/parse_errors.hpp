// apps/softrast/parse_errors.hpp: CLI11's parse errors in the program's own words: one line that
// names the flag and says what it takes ("--threads: expected a whole number, got '1.5'").
#pragma once

#include <span>
#include <string>

#include <CLI/CLI.hpp>

namespace softrast::cli {

// The message for `e`, thrown while parsing flags defined on one of `commands`: a value that does
// not convert says what the flag expects, a value given to a flag without one says that it takes
// none; other errors keep CLI11's text.
std::string parse_error_message(std::span<const CLI::App* const> commands,
                                const CLI::ParseError& e);

}  // namespace softrast::cli
