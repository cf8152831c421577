// fuzz/libfuzzer_main.cpp: libFuzzer's entry point for one target, chosen at compile time by
// SOFTRAST_FUZZ_ENTRY (see fuzz/CMakeLists.txt). A FuzzFailure is not caught: it ends the run
// through std::terminate, which prints its message, and libFuzzer saves the input as a crash.
#include <cstddef>
#include <cstdint>

#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return softrast::fuzz::SOFTRAST_FUZZ_ENTRY(data, size);
}
