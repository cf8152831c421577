#!/bin/sh
# Runs the whole test suite under AddressSanitizer + UBSan (the debug preset, build/debug), then
# under ThreadSanitizer in build/tsan (all but one signal test, see below). Any
# sanitizer report fails the run: UBSan halts on its first error instead of printing and going on.
# Both builds are -O1, as the sanitizers' documentation advises, and compile the built-in shaders
# for the SSE2 baseline only (SOFTRAST_SHADERS_BASELINE_ONLY, as the fuzz preset does); the tile
# and vertex kernels and the sampler keep every level. On 2 cores shared with two fuzzers
# (2026-11-25): the debug build 35 minutes, the TSan build 12; the ASan run of every test 3.5
# minutes, the TSan run 3.
#
#   scripts/sanitize.sh            # from the source folder; NICE=0 to run without nice -n 19
set -eu

cd "$(dirname "$0")/.."
nice="nice -n ${NICE:-19}"

export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export ASAN_OPTIONS="detect_leaks=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp"  # libraries softrast does not own
export TSAN_OPTIONS="halt_on_error=1"

echo "== AddressSanitizer + UBSan: every test (build/debug)"
$nice cmake --preset debug
$nice cmake --build --preset debug
$nice ctest --preset debug

# TSan cannot be combined with ASan, hence a build of its own. Only the test binary and the CLI
# (its tests run it) are needed; the reference renderer and the benchmarks
# are left out.
echo "== ThreadSanitizer: every test but one (build/tsan)"
$nice cmake -S . -B build/tsan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
  -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer -DSOFTRAST_SHADERS_BASELINE_ONLY" \
  -DSOFTRAST_BUILD_REFERENCE=OFF -DSOFTRAST_BUILD_BENCHMARKS=OFF -DSOFTRAST_BUILD_EXAMPLES=OFF
$nice cmake --build build/tsan --target softrast_tests softrast_cli -j 2  # the CLI tests run it
# Every test but HostileInput.SignalsEndTheProgramCleanly: TSan holds asynchronous signals back
# until a safe point, so an image write can finish before SIGTERM arrives (exit 0, not 143).
TSAN_OPTIONS="$TSAN_OPTIONS suppressions=$PWD/scripts/tsan.supp" \
  $nice build/tsan/tests/softrast_tests --gtest_filter='-HostileInput.SignalsEndTheProgramCleanly'

echo "sanitize.sh: all passed"
