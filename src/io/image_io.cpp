// io/image_io.cpp: image files in and out. Reading picks PNG, JPEG or TGA by the file's contents
// and hands it to that format's decoder (io/*_decode.cpp); writing encodes in memory (PNG and JPEG
// in io/image_encode.cpp, TGA through stb_image_write) and goes through a temporary file that is
// renamed over the target.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <stb_image_write.h>

#include "io/image_decode.hpp"
#include "io/image_encode.hpp"
#include "softrast/image.hpp"

namespace softrast {
namespace {

Status fail(const std::string& path, const std::string& reason) {
  return Status::error(path + ": " + reason);
}

std::string errno_text() {
  return std::strerror(errno);
}

bool valid_size(int width, int height) {
  return width > 0 && height > 0 && width <= kMaxImageSize && height <= kMaxImageSize;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Bytes read before the format is decided: enough for every signature and the TGA header, so a
// file that is not an image (or an endless device such as /dev/zero) is refused at once.
constexpr size_t kSniffBytes = 64;
constexpr size_t kReadBlock = size_t(1) << 16;

std::string mib_text(int64_t bytes) {
  return std::to_string(bytes >> 20) + " MiB";
}

Status too_large(const std::string& path) {
  return fail(path,
              "file is larger than " + mib_text(kMaxImageFileBytes) + ", the limit for images");
}

// Appends up to `limit` bytes more from f; false on a read error (errno says why).
bool read_some(std::FILE* f, std::vector<uint8_t>& bytes, size_t limit) {
  uint8_t buffer[kReadBlock];
  while (limit > 0) {
    size_t n = std::fread(buffer, 1, std::min(limit, sizeof buffer), f);
    if (n == 0) break;
    bytes.insert(bytes.end(), buffer, buffer + n);
    limit -= n;
  }
  return !std::ferror(f);
}

Status unsupported(const std::string& name) {
  return fail(name, "unsupported image format (PNG, TGA and JPG are supported)");
}

// Reads the whole file, at most kMaxImageFileBytes of it: a regular file's size is checked before
// reading, anything else (pipes, devices) is cut off one byte past the limit. The first bytes
// must look like a supported image before the rest is read. Fails on open or read errors
// (including "is a directory").
Status read_file(const std::string& path, std::vector<uint8_t>& bytes) {
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) return fail(path, "cannot open: " + errno_text());
  struct stat info {};
  if (fstat(fileno(f.get()), &info) == 0 && S_ISREG(info.st_mode)) {
    if (info.st_size > kMaxImageFileBytes) return too_large(path);
    bytes.reserve(size_t(info.st_size));
  }
  if (!read_some(f.get(), bytes, kSniffBytes)) return fail(path, "cannot read: " + errno_text());
  if (!bytes.empty() && !detail::is_png(bytes.data(), bytes.size()) &&
      !detail::is_jpeg(bytes.data(), bytes.size()) && !detail::is_tga(bytes.data(), bytes.size())) {
    return unsupported(path);
  }
  if (!read_some(f.get(), bytes, size_t(kMaxImageFileBytes) + 1 - bytes.size())) {
    return fail(path, "cannot read: " + errno_text());
  }
  if (bytes.size() > size_t(kMaxImageFileBytes)) return too_large(path);
  return {};
}

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* bytes = static_cast<const uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

// TGA through stb_image_write, which reports failure (e.g. out of memory) by returning 0.
Result<std::vector<uint8_t>> encode_tga(const Image& image) {
  std::vector<uint8_t> out;
  if (stbi_write_tga_to_func(append_bytes, &out, image.width, image.height, 4, image.rgba.data()) ==
      0) {
    return Status::error("cannot encode TGA");
  }
  return out;
}

// A name no other writer uses: the pid separates processes, the counter threads of this one.
std::string temporary_name(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp." + std::to_string(getpid()) + "." + std::to_string(counter++);
}

// The temporary file being written, for remove_pending_temporary_file() in a signal handler: a
// fixed buffer, so the handler neither allocates nor locks, claimed by one save_image at a time.
// `pending_ready` is set only while the buffer holds a whole path; lock-free atomics are
// async-signal-safe.
char pending_path[4096];
std::atomic<bool> pending_claimed{false};
std::atomic<bool> pending_ready{false};
static_assert(std::atomic<bool>::is_always_lock_free);

// Publishes `path` for the signal handler while it lives. The path is published before the file
// is created and withdrawn after it is renamed or removed, so a signal in between unlinks at worst
// a name that no longer exists (the pid in it makes it no other process's file). A path too long
// for the buffer, or a second concurrent save, is simply not covered.
class PendingTemporary {
 public:
  explicit PendingTemporary(const std::string& path) {
    if (path.size() >= sizeof pending_path || pending_claimed.exchange(true)) return;
    std::memcpy(pending_path, path.c_str(), path.size() + 1);
    pending_ready.store(true);
    owner_ = true;
  }
  ~PendingTemporary() {
    if (!owner_) return;
    pending_ready.store(false);
    pending_claimed.store(false);
  }
  PendingTemporary(const PendingTemporary&) = delete;
  PendingTemporary& operator=(const PendingTemporary&) = delete;

 private:
  bool owner_ = false;
};

constexpr size_t kWriteChunk = size_t(1) << 16;

// Test hook: SOFTRAST_TEST_SLOW_WRITE_MS=N sleeps N ms after each 64 KiB written, so that a test
// can interrupt the program while the temporary file exists (tests/cli_test.cpp). Not for users.
std::chrono::milliseconds write_delay() {
  const char* text = std::getenv("SOFTRAST_TEST_SLOW_WRITE_MS");
  return std::chrono::milliseconds(text ? std::clamp(std::atoll(text), 0LL, 10000LL) : 0);
}

bool write_chunks(std::FILE* f, const std::vector<uint8_t>& bytes) {
  std::chrono::milliseconds delay = write_delay();
  for (size_t at = 0; at < bytes.size(); at += kWriteChunk) {
    size_t n = std::min(kWriteChunk, bytes.size() - at);
    if (std::fwrite(bytes.data() + at, 1, n, f) != n) return false;
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
  }
  return true;
}

// Writes all of `bytes` to a new file, flushed to the disk before it is closed; on failure removes
// it and says why. "x" refuses an existing file, so a stale temporary is never reused.
bool write_new_file(const std::string& path, const std::vector<uint8_t>& bytes,
                    std::string& reason) {
  std::FILE* f = std::fopen(path.c_str(), "wbx");
  if (!f) {
    reason = errno_text();
    return false;
  }
  bool ok = write_chunks(f, bytes);
  ok = ok && std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  if (!ok) reason = errno_text();
  if (std::fclose(f) != 0 && ok) {
    ok = false;
    reason = errno_text();
  }
  if (!ok) std::remove(path.c_str());
  return ok;
}

}  // namespace

namespace detail {

Status image_error(const std::string& name, const std::string& reason) {
  return fail(name, reason);
}

Status check_image_size(const std::string& name, int64_t width, int64_t height) {
  std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (width < 1 || height < 1 || width > kMaxImageSize || height > kMaxImageSize) {
    return fail(name, "image size " + size + " is outside 1.." + std::to_string(kMaxImageSize));
  }
  if (width * height > kMaxImagePixels) {
    return fail(name, "image size " + size + " has more than " + std::to_string(kMaxImagePixels) +
                          " pixels, the limit for images");
  }
  return {};
}

}  // namespace detail

Result<Image> decode_image(const uint8_t* data, size_t size, const std::string& name) {
  if (size == 0) return fail(name, "empty file");
  if (size > size_t(kMaxImageFileBytes)) return too_large(name);
  // Signatures first; TGA has none, so it is last and only on a strictly valid header.
  if (detail::is_png(data, size)) return detail::decode_png(data, size, name);
  if (detail::is_jpeg(data, size)) return detail::decode_jpeg(data, size, name);
  if (detail::is_tga(data, size)) return detail::decode_tga(data, size, name);
  return unsupported(name);
}

Result<Image> load_image(const std::string& path) {
  std::vector<uint8_t> bytes;
  if (Status s = read_file(path, bytes); !s.ok()) return s;
  return decode_image(bytes.data(), bytes.size(), path);
}

std::optional<ImageFormat> image_format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return ImageFormat::kPng;
  if (ext == ".tga") return ImageFormat::kTga;
  if (ext == ".jpg" || ext == ".jpeg") return ImageFormat::kJpeg;
  return std::nullopt;
}

Result<std::vector<uint8_t>> encode_image(const Image& image, ImageFormat format,
                                          int jpeg_quality) {
  if (!valid_size(image.width, image.height) ||
      image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
    return Status::error("invalid image " + size_text(image.width, image.height) + " with " +
                         std::to_string(image.rgba.size()) + " bytes");
  }
  switch (format) {
    case ImageFormat::kPng:
      return detail::encode_png(image);
    case ImageFormat::kJpeg:
      if (jpeg_quality < 1 || jpeg_quality > 100) {
        return Status::error("JPEG quality " + std::to_string(jpeg_quality) + " is outside 1..100");
      }
      return detail::encode_jpeg(image, jpeg_quality);
    case ImageFormat::kTga:
      break;
  }
  return encode_tga(image);
}

Status save_image(const std::string& path, const Image& image, int jpeg_quality) {
  std::optional<ImageFormat> format = image_format_of(path);
  if (!format) return fail(path, "unknown image extension (use .png, .jpg or .tga)");
  Result<std::vector<uint8_t>> encoded = encode_image(image, *format, jpeg_quality);
  if (!encoded) return fail(path, encoded.status().message());
  const std::vector<uint8_t>& bytes = *encoded;
  std::string temporary = temporary_name(path);
  PendingTemporary pending(temporary);
  if (std::string reason; !write_new_file(temporary, bytes, reason)) {
    return fail(path, "cannot write: " + reason);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::string reason = errno_text();
    std::remove(temporary.c_str());
    return fail(path, "cannot replace file: " + reason);
  }
  return {};
}

void remove_pending_temporary_file() noexcept {
  if (pending_ready.load()) unlink(pending_path);
}

}  // namespace softrast
