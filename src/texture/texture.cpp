// texture/texture.cpp: building textures from images (the samplers live in texture.hpp): the
// flip from file order (top row first) to texel order (bottom first), and the mip chain.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "softrast/texture.hpp"
#include "texture/srgb_encode.hpp"

namespace softrast {

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : float(std::pow((double(c) + 0.055) / 1.055, 2.4));
}

float linear_to_srgb(float c) {
  if (!(c > 0.0f)) return 0.0f;
  if (c >= 1.0f) return 1.0f;
  return c <= 0.0031308f ? c * 12.92f : float(1.055 * std::pow(double(c), 1.0 / 2.4) - 0.055);
}

uint8_t linear_to_srgb_byte_exact(float c) {
  return uint8_t(linear_to_srgb(c) * 255.0f + 0.5f);
}

namespace {

uint32_t float_bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}
float bits_float(uint32_t b) {
  float f;
  std::memcpy(&f, &b, sizeof f);
  return f;
}

// linear_to_srgb_byte without pow: the byte is a non-decreasing function of c, so it is the
// number of thresholds at or below c, where threshold k (1..255) is the smallest float in (0, 1]
// whose byte is k or more (found by bisection over the bits of positive floats, which order as
// the floats do). A table over 4096 equal steps of c gives the byte at each step's start, so a
// lookup walks at most a few thresholds. Built once, with about 8,000 pow calls.
struct SrgbEncoder {
  static constexpr int kSteps = 4096;
  std::array<float, 257> threshold{};  // [0] unused; [256] = +inf
  std::array<uint8_t, kSteps + 1> start{};

  SrgbEncoder() {
    const uint32_t one = float_bits(1.0f);
    for (int k = 1; k < 256; ++k) {
      uint32_t lo = 0, hi = one;  // byte(bits lo) < k <= byte(bits hi)
      while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (linear_to_srgb_byte_exact(bits_float(mid)) >= k) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      threshold[size_t(k)] = bits_float(hi);
    }
    threshold[256] = INFINITY;
    for (int s = 0; s <= kSteps; ++s) start[size_t(s)] = slow(float(s) / float(kSteps));
  }
  uint8_t slow(float c) const {
    int k = 0;
    while (k < 255 && c >= threshold[size_t(k) + 1]) ++k;
    return uint8_t(k);
  }
  uint8_t operator()(float c) const {
    if (!(c > 0.0f)) return 0;
    if (c >= 1.0f) return 255;
    // Truncation of c * kSteps cannot pass c: start[s] is the byte at s / kSteps <= c.
    int k = start[size_t(c * float(kSteps))];
    while (k < 255 && c >= threshold[size_t(k) + 1]) ++k;
    return uint8_t(k);
  }
};

// The one table, built on first use (linear_to_srgb_byte and sRGB mip chains share it).
const SrgbEncoder& srgb_encoder() {
  static const SrgbEncoder encoder;
  return encoder;
}

}  // namespace

uint8_t linear_to_srgb_byte(float c) {
  return srgb_encoder()(c);
}

const float* srgb_decode_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int k = 0; k < 256; ++k) t[size_t(k)] = srgb_to_linear(float(k) / 255.0f);
    return t;
  }();
  return table.data();
}

Texture Texture::from_image(const Image& image, ColorSpace space) {
  size_t row_bytes = size_t(image.width) * 4;
  if (image.width < 0 || image.height < 0 ||
      image.rgba.size() != row_bytes * size_t(image.height)) {
    // A contract violation, not a recoverable error: every Image built by the library is valid.
    std::fprintf(stderr, "Texture::from_image: image %dx%d holds %zu bytes, expected %zu\n",
                 image.width, image.height, image.rgba.size(), row_bytes * size_t(image.height));
    std::abort();
  }
  if (image.rgba.empty()) return Texture();  // a 0 x n image: samples as opaque white
  Texture texture;
  texture.space_ = space;
  texture.width_ = image.width;
  texture.height_ = image.height;
  texture.levels_ = mip_levels(image.width, image.height);
  const MipLevel& last = texture.levels_.back();
  texture.texels_.resize((last.offset + size_t(last.width) * size_t(last.height)) * 4);
  for (int j = 0; j < image.height; ++j) {
    const uint8_t* source = image.pixel(0, image.height - 1 - j);
    std::copy(source, source + row_bytes, texture.texels_.begin() + row_bytes * size_t(j));
  }
  texture.mips_ = std::make_unique<MipState>();
  return texture;
}

void Texture::build_mips() const {
  std::lock_guard<std::mutex> lock(mips_->mutex);
  if (mips_->ready.load(std::memory_order_relaxed)) return;
  auto* self = const_cast<Texture*>(this);  // only the levels past the base are written
  for (size_t k = 1; k < levels_.size(); ++k) {
    if (space_ == ColorSpace::kSrgb) {
      self->downsample_srgb(levels_[k - 1], levels_[k]);
    } else {
      self->downsample(levels_[k - 1], levels_[k]);
    }
  }
  mips_->ready.store(true, std::memory_order_release);
}

Texture::Texture(const Texture& other) {
  *this = other;
}

Texture& Texture::operator=(const Texture& other) {
  if (this == &other) return *this;
  other.ensure_mips();
  space_ = other.space_;
  width_ = other.width_;
  height_ = other.height_;
  texels_ = other.texels_;
  levels_ = other.levels_;
  mips_.reset();
  if (other.mips_) {
    mips_ = std::make_unique<MipState>();
    mips_->ready.store(true, std::memory_order_relaxed);
  }
  return *this;
}

Texture Texture::from_mip_levels(const std::vector<Image>& levels, ColorSpace space) {
  if (levels.empty()) return Texture();
  Texture texture = from_image(levels[0], space);
  bool sizes_match = texture.levels_.size() == levels.size();
  for (size_t k = 0; sizes_match && k < levels.size(); ++k) {
    sizes_match = levels[k].width == texture.levels_[k].width &&
                  levels[k].height == texture.levels_[k].height &&
                  levels[k].rgba.size() == size_t(levels[k].width) * levels[k].height * 4;
  }
  if (!sizes_match) {
    std::fprintf(stderr, "Texture::from_mip_levels: %zu levels do not make the chain of %dx%d\n",
                 levels.size(), levels[0].width, levels[0].height);
    std::abort();
  }
  for (size_t k = 1; k < levels.size(); ++k) {
    const MipLevel& l = texture.levels_[k];
    size_t row_bytes = size_t(l.width) * 4;
    for (int j = 0; j < l.height; ++j) {
      const uint8_t* source = levels[k].pixel(0, l.height - 1 - j);
      std::copy(source, source + row_bytes, texture.texels_.begin() + l.offset * 4 + row_bytes * j);
    }
  }
  texture.mips_->ready.store(true, std::memory_order_relaxed);  // given, not built
  return texture;
}

// Whether a texture has texels that are not opaque, judged by squares of its base level: the
// mean alpha of each square of 2^L x 2^L texels, where level L is the smallest level of at least
// 64x64 texels (or the base), so that a translucent area of more than a few texels counts and a
// stray texel does not. Reads only the base level (the mip chain is built when first sampled).
bool Texture::compute_translucent() const {
  const Texture& t = *this;
  const int w = t.width(), h = t.height();
  const auto* texels = reinterpret_cast<const uint32_t*>(t.texels());
  uint32_t lowest = 255;
  for (size_t k = 0; k < size_t(w) * size_t(h); ++k) lowest = std::min(lowest, texels[k] >> 24);
  if (lowest >= 250) return false;  // the usual opaque map: one pass over the alpha
  int level = 0;
  auto side = [](int n, int l) { return std::max(n >> l, 1); };
  while ((side(w, level) > 1 || side(h, level) > 1) &&
         side(w, level + 1) * side(h, level + 1) >= 4096) {
    ++level;
  }
  const int block = 1 << level;
  for (int by = 0; by < h; by += block) {
    for (int bx = 0; bx < w; bx += block) {
      uint64_t sum = 0, count = 0;
      for (int y = by; y < std::min(h, by + block); ++y) {
        for (int x = bx; x < std::min(w, bx + block); ++x) {
          sum += texels[size_t(y) * size_t(w) + size_t(x)] >> 24;
          ++count;
        }
      }
      if (sum < 250 * count) return true;
    }
  }
  return false;
}

void Texture::wrap_lanes(Wrap mode, int32_t* indices, const int32_t* sizes, int count) {
  for (int k = 0; k < count; ++k) indices[k] = wrap(mode, indices[k], sizes[k]);
}

namespace {
std::atomic<bool> g_row_pairs{true};
}  // namespace

void set_texture_row_pairs(bool on) {
  g_row_pairs.store(on, std::memory_order_relaxed);
}
bool texture_row_pairs() {
  return g_row_pairs.load(std::memory_order_relaxed);
}

void Texture::pair_rows(const MipLevel& level, uint64_t* out) const {
  const size_t w = size_t(level.width);
  const int h = level.height;
  const auto* texels = reinterpret_cast<const uint32_t*>(texels_.data()) + level.offset;
  for (int j = -1; j < h; ++j) {
    const uint32_t* lower = texels + size_t(std::max(j, 0)) * w;
    const uint32_t* upper = texels + size_t(std::min(j + 1, h - 1)) * w;
    uint64_t* row = out + size_t(j + 1) * w;
    for (size_t i = 0; i < w; ++i) row[i] = uint64_t(lower[i]) | uint64_t(upper[i]) << 32;
  }
}

const uint64_t* Texture::row_pairs() const {
  if (!pairs_allowed()) return nullptr;
  if (const uint64_t* row0 = mips_->pairs_row0.load(std::memory_order_acquire)) return row0;
  std::lock_guard<std::mutex> lock(mips_->mutex);
  if (const uint64_t* row0 = mips_->pairs_row0.load(std::memory_order_relaxed)) return row0;
  const MipLevel& base = levels_[0];
  mips_->pairs.resize(size_t(base.width) * (size_t(base.height) + 1));
  pair_rows(base, mips_->pairs.data());
  const uint64_t* row0 = mips_->pairs.data() + base.width;
  mips_->pairs_row0.store(row0, std::memory_order_release);
  return row0;
}

Texture::RowPairChain Texture::row_pair_chain() const {
  if (!pairs_allowed()) return {};
  if (!mips_->chain_ready.load(std::memory_order_acquire)) {
    ensure_mips();  // (takes the mutex itself)
    std::lock_guard<std::mutex> lock(mips_->mutex);
    if (!mips_->chain_ready.load(std::memory_order_relaxed)) {
      size_t total = 0;
      for (const MipLevel& l : levels_) total += size_t(l.width) * (size_t(l.height) + 1);
      mips_->chain_pairs.resize(total);
      mips_->chain_row0.resize(levels_.size());
      size_t at = 0;
      for (size_t k = 0; k < levels_.size(); ++k) {
        pair_rows(levels_[k], mips_->chain_pairs.data() + at);
        mips_->chain_row0[k] = int32_t(at + size_t(levels_[k].width));
        at += size_t(levels_[k].width) * (size_t(levels_[k].height) + 1);
      }
      mips_->chain_ready.store(true, std::memory_order_release);
    }
  }
  return {mips_->chain_pairs.data(), mips_->chain_row0.data()};
}

bool Texture::translucent() const {
  if (!mips_) return false;  // empty: samples as opaque white
  int known = mips_->translucent.load(std::memory_order_relaxed);
  if (known < 0) {  // two threads may both compute it: the same answer
    known = compute_translucent() ? 1 : 0;
    mips_->translucent.store(known, std::memory_order_relaxed);
  }
  return known == 1;
}

std::vector<MipLevel> Texture::mip_levels(int width, int height) {
  std::vector<MipLevel> levels{{width, height, 0}};
  while (levels.back().width > 1 || levels.back().height > 1) {
    const MipLevel& l = levels.back();
    levels.push_back({std::max(l.width / 2, 1), std::max(l.height / 2, 1),
                      l.offset + size_t(l.width) * size_t(l.height)});
  }
  return levels;
}

// Level `to` from level `from` by a box filter: each texel averages the 2x2 texels it covers
// (rounded to nearest). For an odd size the last row or column of `from` is not reached, as
// with OpenGL's usual glGenerateMipmap; a side of 1 averages the texel with itself.
void Texture::downsample(const MipLevel& from, const MipLevel& to) {
  for (int j = 0; j < to.height; ++j) {
    int j0 = std::min(2 * j, from.height - 1), j1 = std::min(2 * j + 1, from.height - 1);
    for (int i = 0; i < to.width; ++i) {
      int i0 = std::min(2 * i, from.width - 1), i1 = std::min(2 * i + 1, from.width - 1);
      const uint8_t* a = &texels_[(from.offset + size_t(j0) * from.width + i0) * 4];
      const uint8_t* b = &texels_[(from.offset + size_t(j0) * from.width + i1) * 4];
      const uint8_t* c = &texels_[(from.offset + size_t(j1) * from.width + i0) * 4];
      const uint8_t* d = &texels_[(from.offset + size_t(j1) * from.width + i1) * 4];
      uint8_t* out = &texels_[(to.offset + size_t(j) * to.width + i) * 4];
      for (int ch = 0; ch < 4; ++ch) out[ch] = uint8_t((a[ch] + b[ch] + c[ch] + d[ch] + 2) / 4);
    }
  }
}

// The box filter of downsample on linear values: RGB decoded from sRGB, averaged, encoded again
// (rounded to nearest); alpha as in downsample. Averaging the bytes themselves would darken
// minified colour textures (the mean of 0 and 255 is 128, which decodes to 0.22, not 0.5).
void Texture::downsample_srgb(const MipLevel& from, const MipLevel& to) {
  const float* decode = srgb_decode_table();
  const SrgbEncoder& encode = srgb_encoder();
  for (int j = 0; j < to.height; ++j) {
    int j0 = std::min(2 * j, from.height - 1), j1 = std::min(2 * j + 1, from.height - 1);
    for (int i = 0; i < to.width; ++i) {
      int i0 = std::min(2 * i, from.width - 1), i1 = std::min(2 * i + 1, from.width - 1);
      const uint8_t* a = &texels_[(from.offset + size_t(j0) * from.width + i0) * 4];
      const uint8_t* b = &texels_[(from.offset + size_t(j0) * from.width + i1) * 4];
      const uint8_t* c = &texels_[(from.offset + size_t(j1) * from.width + i0) * 4];
      const uint8_t* d = &texels_[(from.offset + size_t(j1) * from.width + i1) * 4];
      uint8_t* out = &texels_[(to.offset + size_t(j) * to.width + i) * 4];
      for (int ch = 0; ch < 3; ++ch) {
        float mean = 0.25f * (decode[a[ch]] + decode[b[ch]] + decode[c[ch]] + decode[d[ch]]);
        out[ch] = encode(mean);  // linear_to_srgb_byte(mean), without the call
      }
      out[3] = uint8_t((a[3] + b[3] + c[3] + d[3] + 2) / 4);
    }
  }
}

}  // namespace softrast
