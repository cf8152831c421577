// io/text_lines.hpp: reading a text file line by line with a cap on the bytes read.
// Used by the OBJ and MTL loaders so that a huge file, a pipe or a device cannot grow memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "softrast/status.hpp"

namespace softrast::detail {

// Longest line accepted (1 MiB): a face of some 30000 corners. Bounds the line buffer, so a
// stream without newlines is refused long before the byte cap.
inline constexpr size_t kMaxTextLineBytes = size_t(1) << 20;

// Called per line (without its "\n" or "\r\n") with its 1-based number; an error stops reading.
using LineFn = std::function<Status(std::string_view line, size_t number)>;

// A cap on the bytes read and what it is for messages ("OBJ files").
struct TextLimit {
  int64_t max_bytes;
  const char* kind;
};

// Reads `path` and calls `fn` for each line. Refuses, naming the file: one that cannot be opened
// or read, a folder, more than limit.max_bytes (a regular file's size is checked before reading;
// pipes and devices are cut off while reading), a NUL byte (not a text file: /dev/zero fails in
// the first block) and a line longer than kMaxTextLineBytes.
Status read_lines(const std::string& path, TextLimit limit, const LineFn& fn);

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Opens `path` for reading; refuses (naming the file) one that cannot be opened, a folder and a
// regular file over limit.max_bytes. Pipes and devices must be cut off by the reader.
Status open_text_file(const std::string& path, TextLimit limit, FilePtr& f);

// "path: file is larger than 2 GiB, the limit for OBJ files".
Status text_too_large(const std::string& path, TextLimit limit);

// "64 MiB", "2 GiB": a byte limit for messages.
std::string byte_limit_text(int64_t bytes);

}  // namespace softrast::detail
