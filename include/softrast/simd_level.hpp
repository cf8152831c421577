// softrast/simd_level.hpp: which SIMD instruction set the fragment stage and the rasterizer run
// with. One binary holds every level; the widest one the CPU has is picked at the first draw.
// The environment variable SOFTRAST_SIMD=sse2|sse4|avx2|avx512, or set_simd_level(), caps it
// lower (for tests, and to compare levels); neither can raise it past what the CPU has.
#pragma once

#include <optional>
#include <string_view>

namespace softrast {

// In increasing order: each level is a superset of the ones before it. Lanes per native vector:
// 4 (SSE2, SSE4.2), 8 (AVX2) and 16 (AVX-512 F/BW/DQ/VL).
enum class SimdLevel { kSse2, kSse4, kAvx2, kAvx512 };

// The widest level this CPU (and its operating system) supports.
SimdLevel cpu_simd_level();

// The level draws use now: min(cpu_simd_level(), the cap from set_simd_level or SOFTRAST_SIMD).
SimdLevel simd_level();

// Caps the level for draws started after this call; pass cpu_simd_level() to remove the cap.
// Not to be called while a draw is running on another thread.
void set_simd_level(SimdLevel cap);

// How the AVX2 and AVX-512 levels read memory at an address per lane (texels, above all): with
// the CPU's gather instruction, or with one scalar load per lane. Both read the same values, so
// images do not depend on it; the speed does, and which is faster depends on the CPU (Intel's
// microcode against Gather Data Sampling, "Downfall", 2023, made the instruction several times
// slower on the cores from Skylake to Tiger Lake). By default the first draw times both on a
// small table, per vector width, and keeps the faster one (loads unless the instruction is
// clearly faster). SOFTRAST_GATHER=instruction|loads or set_gather_mode() fixes the choice. SSE2
// and SSE4.2, which have no gather instruction, always load per lane.
enum class GatherMode { kInstruction, kLoads };

// The mode the given level's gathers use.
GatherMode gather_mode(SimdLevel level);

// Fixes the mode of every level for draws started after this call. Not to be called while a
// draw is running on another thread.
void set_gather_mode(GatherMode mode);

const char* gather_mode_name(GatherMode mode);

const char* simd_level_name(SimdLevel level);
std::optional<SimdLevel> parse_simd_level(std::string_view name);

}  // namespace softrast
