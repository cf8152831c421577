// io/text_lines.cpp: capped, line-by-line reading of text files (see text_lines.hpp).

#include "io/text_lines.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace softrast::detail {
namespace {

constexpr size_t kReadBlock = size_t(1) << 16;

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

}  // namespace

Status text_too_large(const std::string& path, TextLimit limit) {
  return fail(path, "file is larger than " + byte_limit_text(limit.max_bytes) + ", the limit for " +
                        limit.kind);
}

Status open_text_file(const std::string& path, TextLimit limit, FilePtr& f) {
  f.reset(std::fopen(path.c_str(), "rb"));
  if (!f) return fail(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat info {};
  if (fstat(fileno(f.get()), &info) != 0) return {};  // found out while reading, if at all
  if (S_ISDIR(info.st_mode)) return fail(path, "is a directory");
  if (S_ISREG(info.st_mode) && info.st_size > limit.max_bytes) return text_too_large(path, limit);
  return {};
}

namespace {

// Splits blocks into lines; a line split across blocks is gathered in `pending_`.
class LineSplitter {
 public:
  LineSplitter(const std::string& path, const LineFn& fn) : path_(path), fn_(fn) {}

  Status feed(const char* data, size_t size) {
    if (const void* nul = std::memchr(data, '\0', size)) {
      auto before = static_cast<const char*>(nul) - data;
      size_t line = number_ + 1 + size_t(std::count(data, data + before, '\n'));
      return fail_at(line, "NUL byte: not a text file");
    }
    while (size > 0) {
      const char* newline = static_cast<const char*>(std::memchr(data, '\n', size));
      size_t length = newline ? size_t(newline - data) : size;
      if (pending_.size() + length > kMaxTextLineBytes) {
        return fail_at(number_ + 1,
                       "line longer than " + byte_limit_text(int64_t(kMaxTextLineBytes)));
      }
      if (!newline) {
        pending_.append(data, size);
        return {};
      }
      Status s = pending_.empty() ? emit({data, length}) : emit_pending(data, length);
      if (!s.ok()) return s;
      data += length + 1;
      size -= length + 1;
    }
    return {};
  }

  Status finish() { return pending_.empty() ? Status() : emit_pending(nullptr, 0); }

 private:
  Status fail_at(size_t line, const std::string& reason) const {
    return Status::error(path_ + ":" + std::to_string(line) + ": " + reason);
  }

  Status emit_pending(const char* data, size_t length) {
    pending_.append(data, length);
    Status s = emit(pending_);
    pending_.clear();
    return s;
  }

  Status emit(std::string_view line) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return fn_(line, ++number_);
  }

  const std::string& path_;
  const LineFn& fn_;
  std::string pending_;
  size_t number_ = 0;
};

}  // namespace

std::string byte_limit_text(int64_t bytes) {
  if (bytes >= (int64_t(1) << 30) && bytes % (int64_t(1) << 30) == 0) {
    return std::to_string(bytes >> 30) + " GiB";
  }
  if (bytes >= (int64_t(1) << 20) && bytes % (int64_t(1) << 20) == 0) {
    return std::to_string(bytes >> 20) + " MiB";
  }
  return std::to_string(bytes) + " bytes";
}

Status read_lines(const std::string& path, TextLimit limit, const LineFn& fn) {
  FilePtr f;
  if (Status s = open_text_file(path, limit, f); !s.ok()) return s;
  LineSplitter lines(path, fn);
  std::vector<char> block(kReadBlock);
  int64_t total = 0;
  for (;;) {
    size_t n = std::fread(block.data(), 1, block.size(), f.get());
    if (n == 0) break;
    total += int64_t(n);
    // Checked per block, so a pipe or device costs at most one block past the limit.
    if (total > limit.max_bytes) return text_too_large(path, limit);
    if (Status s = lines.feed(block.data(), n); !s.ok()) return s;
  }
  if (std::ferror(f.get())) return fail(path, std::string("cannot read: ") + std::strerror(errno));
  return lines.finish();
}

}  // namespace softrast::detail
