// io/model_formats.hpp: the PLY and STL parsers behind load_ply, load_stl and load_model, and the
// whole-file reading they share. Each parser takes the file in memory, checks every count against
// the bytes present before allocating for it, and reports errors as one line naming the file and
// the line (text) or element and byte offset (binary).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "softrast/mesh.hpp"

namespace softrast::detail {

// Reads all of `path`, at most `max_bytes` (a regular file's size is checked first; pipes and
// devices are cut off one read past it). `kind` names the limit in messages ("PLY files").
Status read_whole_file(const std::string& path, int64_t max_bytes, const char* kind,
                       std::vector<char>& bytes);

// PLY: ASCII, binary little and big endian. `name` goes into messages.
Result<Mesh> parse_ply(const char* data, size_t size, const std::string& name);

// STL: binary (80-byte header, a triangle count and 50 bytes per triangle) or ASCII (solid ...
// endsolid). `binary` chooses; load_model tells them apart by content.
Result<Mesh> parse_stl(const char* data, size_t size, bool binary, const std::string& name);

// True if a file of `size` bytes starting with `data` (at least 84 of them when size >= 84) is a
// binary STL: exactly 84 + 50 * the count at byte 80.
bool is_binary_stl(const char* data, size_t size);

}  // namespace softrast::detail
