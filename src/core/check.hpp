// core/check.hpp: contract checks. A failed check is a bug in softrast, not bad input: it prints
// the condition, its operands and where, then aborts. Bad input is reported with Status instead.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace softrast::detail {

[[noreturn]] inline void check_failed(const char* condition, const std::string& operands,
                                      const char* file, int line) {
  std::fprintf(stderr, "softrast: internal check failed at %s:%d: %s (%s)\n", file, line, condition,
               operands.c_str());
  std::abort();
}

template <class A, class B>
std::string describe_operands(const A& a, const B& b) {
  std::ostringstream s;
  s << a << " vs " << b;
  return s.str();
}

}  // namespace softrast::detail

// SOFTRAST_CHECK_LT(a, b): a < b, or abort naming both values. Likewise _LE and _EQ.
#define SOFTRAST_CHECK_OP(a, op, b)                                                                \
  do {                                                                                             \
    if (!((a)op(b))) {                                                                             \
      ::softrast::detail::check_failed(                                                            \
          #a " " #op " " #b, ::softrast::detail::describe_operands((a), (b)), __FILE__, __LINE__); \
    }                                                                                              \
  } while (false)
#define SOFTRAST_CHECK_LT(a, b) SOFTRAST_CHECK_OP(a, <, b)
#define SOFTRAST_CHECK_LE(a, b) SOFTRAST_CHECK_OP(a, <=, b)
#define SOFTRAST_CHECK_EQ(a, b) SOFTRAST_CHECK_OP(a, ==, b)
