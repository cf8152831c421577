// tools/reference/imgdiff.cpp: compares two images of the same size (softrast's and the
// reference's) and prints one JSON line: how many pixels differ, the largest channel
// difference, how many have no pixel within `--threshold` in the other image's 3x3
// neighbourhood (dEQP's position-deviation compare, both directions), and how many are the
// clear colour in one image only. `--diff PATH` writes a picture of the differences (red:
// no close neighbour, yellow: coverage differs, grey: differs within the threshold).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

namespace {

constexpr int kClear = 26;  // the clear colour 0.1 as unorm8

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  const uint8_t* at(int x, int y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

bool load(const char* path, Picture& p) {
  int channels = 0;
  uint8_t* data = stbi_load(path, &p.width, &p.height, &channels, 4);
  if (!data) return false;
  p.rgba.assign(data, data + size_t(p.width) * p.height * 4);
  stbi_image_free(data);
  return true;
}

int difference(const uint8_t* a, const uint8_t* b) {
  int worst = 0;
  for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(int(a[c]) - int(b[c])));
  return worst;
}

bool close_neighbour(const Picture& a, const Picture& b, int x, int y, int threshold) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      int bx = x + dx, by = y + dy;
      if (bx < 0 || by < 0 || bx >= b.width || by >= b.height) continue;
      if (difference(a.at(x, y), b.at(bx, by)) <= threshold) return true;
    }
  }
  return false;
}

bool background(const uint8_t* p) {
  return p[0] == kClear && p[1] == kClear && p[2] == kClear && p[3] == 255;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: imgdiff A.png B.png [--threshold N] [--diff OUT.png]\n");
    return 2;
  }
  int threshold = 3;
  const char* diff_path = nullptr;
  for (int i = 3; i + 1 < argc; i += 2) {
    std::string flag = argv[i];
    if (flag == "--threshold") {
      threshold = std::atoi(argv[i + 1]);
    } else if (flag == "--diff") {
      diff_path = argv[i + 1];
    } else {
      std::fprintf(stderr, "imgdiff: error: unknown flag '%s'\n", argv[i]);
      return 2;
    }
  }
  Picture a, b;
  if (!load(argv[1], a) || !load(argv[2], b)) {
    std::fprintf(stderr, "imgdiff: error: cannot read %s or %s\n", argv[1], argv[2]);
    return 1;
  }
  if (a.width != b.width || a.height != b.height) {
    std::fprintf(stderr, "imgdiff: error: sizes differ\n");
    return 1;
  }
  long differing = 0, mismatches = 0, coverage = 0;
  int max_diff = 0;
  std::vector<uint8_t> picture(a.rgba.size());
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const uint8_t *p = a.at(x, y), *q = b.at(x, y);
      int d = difference(p, q);
      bool mismatch = d > threshold && (!close_neighbour(a, b, x, y, threshold) ||
                                        !close_neighbour(b, a, x, y, threshold));
      bool cover = background(p) != background(q);
      max_diff = std::max(max_diff, d);
      differing += d > 0;
      mismatches += mismatch;
      coverage += cover;
      uint8_t* out = &picture[(size_t(y) * a.width + x) * 4];
      uint8_t grey = d > 0 ? 96 : uint8_t(p[0] / 4);
      out[0] = mismatch || cover ? 255 : grey;
      out[1] = mismatch ? 0 : cover ? 255 : d > 0 ? 96 : uint8_t(p[1] / 4);
      out[2] = mismatch || cover ? 0 : d > 0 ? 96 : uint8_t(p[2] / 4);
      out[3] = 255;
    }
  }
  double pixels = double(a.width) * a.height;
  std::printf(
      "{\"pixels\":%.0f,\"differing\":%ld,\"differing_fraction\":%.6f,\"max_channel_diff\":%d,"
      "\"threshold\":%d,\"mismatches_3x3\":%ld,\"mismatch_fraction\":%.6f,\"coverage_diffs\":%ld}"
      "\n",
      pixels, differing, differing / pixels, max_diff, threshold, mismatches, mismatches / pixels,
      coverage);
  if (diff_path && !stbi_write_png(diff_path, a.width, a.height, 4, picture.data(), a.width * 4)) {
    std::fprintf(stderr, "imgdiff: error: cannot write %s\n", diff_path);
    return 1;
  }
  return 0;
}
