// fuzz/fuzz_entries.hpp: the fuzz targets' entry functions, one per input the program accepts.
// Each takes arbitrary bytes, drives the code under test through its public entry point, and
// checks what it promises on every input; a broken promise throws FuzzFailure (libFuzzer then
// reports a crash with the message, and tests/fuzz_replay_test.cpp a failed test). Crashes,
// sanitizer reports and hangs are found by the harness around them: libFuzzer in build/fuzz
// (fuzz/libfuzzer_main.cpp), the corpus replay in the normal test pass.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace softrast::fuzz {

struct FuzzFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace softrast::fuzz

// Throws FuzzFailure(message) when `ok` is false; the message is built only then (the checks run
// per pixel on every input).
#define SOFTRAST_FUZZ_REQUIRE(ok, message)                                \
  do {                                                                    \
    if (!(ok)) throw ::softrast::fuzz::FuzzFailure(std::string(message)); \
  } while (0)

namespace softrast::fuzz {

// OBJ, with an MTL and a texture after separator lines (see obj_fuzz.cpp): load_obj through
// files in a private temporary folder; a loaded mesh must be valid (indices in range, finite
// positions, submeshes inside the index array).
int fuzz_obj(const uint8_t* data, size_t size);

// decode_image from memory (PNG, TGA, JPEG by content): an error, or an image within the caps
// whose pixel buffer has exactly width * height * 4 bytes.
int fuzz_image(const uint8_t* data, size_t size);

// The render command's flags: the input split at newlines into an argument vector, parsed by
// CLI11 with the CLI's own flag definitions and checked by interpret() (no file is touched and
// nothing is rendered). Either a usage error with a one-line message or a job within the limits.
int fuzz_cli_args(const uint8_t* data, size_t size);

// A jobs file of `softrast batch` (one JSON object per line): split into lines, the first taken as
// the --defaults object when it is a valid one, every line (up to 32) turned into a job by
// interpret_job (nothing is loaded or rendered). Each line is an error with a message or a job
// within the limits that names its output image.
int fuzz_batch(const uint8_t* data, size_t size);

// Raw clip-space geometry (NaN, Inf, huge, denormal, w of either sign) through clipping, setup,
// rasterization and shading at 32x32 (see geometry_fuzz.cpp for the layout and the checks: no
// pixel outside the scissor, each triangle's coverage equal to the fill rule's brute-force
// oracle, both rasterizers and both draw paths identical).
int fuzz_geometry(const uint8_t* data, size_t size);

// glTF or GLB from memory (see gltf_fuzz.cpp): parse and validate, read every accessor, flatten
// into a mesh and check it (indices in range, finite positions, attribute counts), render it with
// the pbr shader at 16x16; an error must be one line starting with the file name.
int fuzz_gltf(const uint8_t* data, size_t size);

// PLY (ASCII, binary little and big endian) and STL (binary and ASCII, both parsers on every
// input) from memory (see model_formats.hpp): a mesh ready to draw with finite normals and
// vertex colours in [0, 1], or an error of one line naming the file.
int fuzz_ply(const uint8_t* data, size_t size);
int fuzz_stl(const uint8_t* data, size_t size);

}  // namespace softrast::fuzz
