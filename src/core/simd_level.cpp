// core/simd_level.cpp: CPU feature detection and the process-wide SIMD level cap.
#include "softrast/simd_level.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>

namespace softrast {
namespace {

constexpr const char* kNames[] = {"sse2", "sse4", "avx2", "avx512"};

SimdLevel detect() {
  __builtin_cpu_init();
  // __builtin_cpu_supports also checks that the OS saves the wide registers (XSAVE state).
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl")) {
    return SimdLevel::kAvx512;
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return SimdLevel::kAvx2;
  if (__builtin_cpu_supports("sse4.2")) return SimdLevel::kSse4;
  return SimdLevel::kSse2;  // the x86-64 baseline
}

SimdLevel initial_cap() {
  const char* env = std::getenv("SOFTRAST_SIMD");
  if (env) {
    if (std::optional<SimdLevel> level = parse_simd_level(env)) return *level;
  }
  return SimdLevel::kAvx512;
}

std::atomic<int>& cap() {
  static std::atomic<int> value{int(initial_cap())};
  return value;
}

}  // namespace

SimdLevel cpu_simd_level() {
  static const SimdLevel level = detect();
  return level;
}

SimdLevel simd_level() {
  return SimdLevel(std::min(int(cpu_simd_level()), cap().load(std::memory_order_relaxed)));
}

void set_simd_level(SimdLevel level) {
  cap().store(int(level), std::memory_order_relaxed);
}

const char* simd_level_name(SimdLevel level) {
  return kNames[int(level)];
}

std::optional<SimdLevel> parse_simd_level(std::string_view name) {
  for (int i = 0; i < 4; ++i) {
    if (name == kNames[i]) return SimdLevel(i);
  }
  return std::nullopt;
}

}  // namespace softrast
