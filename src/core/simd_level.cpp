// core/simd_level.cpp: CPU feature detection, the process-wide SIMD level cap, the choice
// between the gather instruction and per-lane loads, and that between masked stores and blends.
// Also whether PREFETCHW is there (core/prefetch.hpp).
#include "softrast/simd_level.hpp"

#include <cpuid.h>
#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>
#include <vector>

#include "core/prefetch.hpp"
#include "core/store_mode.hpp"
#include "softrast/simd.hpp"

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

// ---- Gathers: the instruction or one load per lane, whichever this CPU runs faster. ----

// A table of 16 KiB (it stays in the L1 cache, so the times compare the instructions, not
// memory), and the rounds of one timing: 256 gathers of 8 or 16 pairs, microseconds in all.
constexpr int kTableSize = 4096;
constexpr int kRounds = 256;

// The register type of the pairs' halves at each width.
template <int N>
struct PairRegister;
template <>
struct PairRegister<8> {
  using T = __m256i;
};
template <>
struct PairRegister<16> {
  using T = __m512i;
};

// Reads kRounds * N pairs from `table` with the instruction or with loads (the two forms
// gather_pair chooses between) and returns the nanoseconds taken; `sink` keeps the reads.
// Inlined into a function compiled for the width's level (below).
template <int N>
SOFTRAST_SIMD_INLINE double time_pairs(const int32_t* table, bool loads, uint32_t& sink) {
  using V = typename simd::Native<N>::I;
  V index, acc = {};
  for (int i = 0; i < N; ++i) index[i] = i * (kTableSize / N) + i;  // spread over the table
  auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < kRounds; ++r) {
    typename PairRegister<N>::T a, c;
    if (loads) {
      simd::isa::pairs_loads(table, index, a, c);
    } else {
      simd::isa::pairs_instruction(table, index, a, c);
    }
    acc ^= V(a) ^ V(c);
    index = (index + 129) & (kTableSize - 1);
  }
  auto end = std::chrono::steady_clock::now();
  for (int i = 0; i < N; ++i) sink += uint32_t(acc[i]);
  return std::chrono::duration<double, std::nano>(end - start).count();
}
[[gnu::target("avx2")]] double time_pairs8(const int32_t* table, bool loads, uint32_t& sink) {
  return time_pairs<8>(table, loads, sink);
}
[[gnu::target("avx512f")]] double time_pairs16(const int32_t* table, bool loads, uint32_t& sink) {
  return time_pairs<16>(table, loads, sink);
}

// Whether the alternative way beats the usual one: `time(alternative)` times one way in
// nanoseconds; the fastest of seven timings of each, taken in turn (so that a change of clock
// speed or a busy moment falls on both), the alternative chosen only when at least a fifth
// faster. For the gather instruction and for the depth resolve's blends.
template <class Time>
bool alternative_is_faster(Time time) {
  double usual = 1e300, alternative = 1e300;
  for (int trial = 0; trial < 7; ++trial) {
    usual = std::min(usual, time(false));
    alternative = std::min(alternative, time(true));
  }
  return alternative < 0.8 * usual;
}

// Whether gathers are to be loads: unless the instruction is clearly faster. (It was the other
// way round, the instruction unless loads were clearly faster, until an AMD Zen 3 showed loads
// 5 to 39 % faster in this timing, mostly under the fifth, so that the instruction was kept in 7
// of 10 starts; yet loads were faster in every draw of quad_grid texture: 8.3 against 9.0 ms at
// two threads, 14.7 against 16.0 at one.)
template <class Time>
bool gathers_by_loads(Time time) {
  std::vector<int32_t> table(kTableSize + 1);  // + 1: the last lane's pair may start at the end
  for (int i = 0; i <= kTableSize; ++i) table[size_t(i)] = i * 2654435761u;
  uint32_t sink = 0;
  const bool instruction = alternative_is_faster(
      [&](bool instruction) { return time(table.data(), !instruction, sink); });
  volatile uint32_t keep = sink;  // the reads must happen
  (void)keep;
  return !instruction;
}

std::optional<GatherMode> gather_mode_from_env() {
  const char* env = std::getenv("SOFTRAST_GATHER");
  if (!env) return std::nullopt;
  for (GatherMode mode : {GatherMode::kInstruction, GatherMode::kLoads}) {
    if (std::string_view(env) == gather_mode_name(mode)) return mode;
  }
  return std::nullopt;
}

// Settles simd::g_loads_for_gathers once, before the first draw reads it.
void settle_gathers() {
  static const bool settled = [] {
    const SimdLevel cpu = cpu_simd_level();
    if (std::optional<GatherMode> mode = gather_mode_from_env()) {
      simd::g_loads_for_gathers[0] = simd::g_loads_for_gathers[1] = *mode == GatherMode::kLoads;
      return true;
    }
    if (cpu >= SimdLevel::kAvx2) simd::g_loads_for_gathers[0] = gathers_by_loads(time_pairs8);
    if (cpu >= SimdLevel::kAvx512) simd::g_loads_for_gathers[1] = gathers_by_loads(time_pairs16);
    return true;
  }();
  (void)settled;
}

// ---- Winners of the AVX2 depth resolve: masked stores or blends (core/store_mode.hpp). ----

// kRounds groups of 8 depths and ids tested and written the two ways tile_kernel.inl's
// test_and_write writes them, over a table that stays in the L1 cache; the nanoseconds taken.
[[gnu::target("avx2")]] double time_stores8(float* depth, int32_t* ids, bool masked) {
  constexpr int kGroups = 256;  // 8 KiB of depths, 8 KiB of ids
  __m256 z = _mm256_setr_ps(0.5f, 0.25f, 0.75f, 0.125f, 0.625f, 0.375f, 0.875f, 0.0625f);
  const __m256 step = _mm256_set1_ps(0.0078125f);
  auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < kRounds; ++r) {
    float* d = depth + 8 * ((r * 37) & (kGroups - 1));
    int32_t* i = ids + 8 * ((r * 37) & (kGroups - 1));
    const __m256 stored = _mm256_loadu_ps(d);
    const __m256i pass = _mm256_castps_si256(_mm256_cmp_ps(z, stored, _CMP_LT_OQ));
    const __m256i id = _mm256_set1_epi32(r);
    if (masked) {
      _mm256_maskstore_ps(d, pass, z);
      _mm256_maskstore_epi32(i, pass, id);
    } else {
      const __m256i old = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i));
      _mm256_storeu_ps(d, _mm256_blendv_ps(stored, z, _mm256_castsi256_ps(pass)));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(i), _mm256_blendv_epi8(old, id, pass));
    }
    z = _mm256_sub_ps(z, step);
    z = _mm256_blendv_ps(z, _mm256_add_ps(z, _mm256_set1_ps(1.0f)),
                         _mm256_cmp_ps(z, _mm256_setzero_ps(), _CMP_LT_OQ));
  }
  auto end = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(end - start).count();
}

// Masked stores unless blends are at least a fifth faster (alternative_is_faster).
bool masked_stores_settle() {
  if (const char* env = std::getenv("SOFTRAST_MASKED_STORES")) return std::string_view(env) != "0";
  if (cpu_simd_level() < SimdLevel::kAvx2) return true;  // (no AVX2 kernel runs)
  std::vector<float> depth(8 * 256, 1.0f);
  std::vector<int32_t> ids(8 * 256, 0);
  return !alternative_is_faster(
      [&](bool blends) { return time_stores8(depth.data(), ids.data(), !blends); });
}

std::atomic<bool>& masked_stores_flag() {
  static std::atomic<bool> flag{masked_stores_settle()};
  return flag;
}

}  // namespace

namespace detail {
bool avx2_masked_stores() {
  return masked_stores_flag().load(std::memory_order_relaxed);
}
void set_avx2_masked_stores(bool masked) {
  masked_stores_flag().store(masked, std::memory_order_relaxed);
}
bool prefetch_for_write_supported() {
  static const bool supported = [] {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    return __get_cpuid(0x80000001u, &eax, &ebx, &ecx, &edx) != 0 && (ecx & bit_PRFCHW) != 0;
  }();
  return supported;
}
}  // namespace detail

namespace simd {
bool g_loads_for_gathers[2] = {false, false};
}  // namespace simd

SimdLevel cpu_simd_level() {
  static const SimdLevel level = detect();
  return level;
}

SimdLevel simd_level() {
  settle_gathers();
  return SimdLevel(std::min(int(cpu_simd_level()), cap().load(std::memory_order_relaxed)));
}

GatherMode gather_mode(SimdLevel level) {
  settle_gathers();
  if (level < SimdLevel::kAvx2) return GatherMode::kLoads;
  return simd::g_loads_for_gathers[level == SimdLevel::kAvx512] ? GatherMode::kLoads
                                                                : GatherMode::kInstruction;
}

void set_gather_mode(GatherMode mode) {
  settle_gathers();
  simd::g_loads_for_gathers[0] = simd::g_loads_for_gathers[1] = mode == GatherMode::kLoads;
}

const char* gather_mode_name(GatherMode mode) {
  return mode == GatherMode::kLoads ? "loads" : "instruction";
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
