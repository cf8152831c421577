// softrast/texture.hpp: textures and samplers used by fragment shaders.
// Texel rows are stored bottom-up, as after an OpenGL upload: v = 0 is the last row of the file.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "softrast/image.hpp"
#include "softrast/simd_level.hpp"

namespace softrast {

// kTrilinear is GL_LINEAR_MIPMAP_LINEAR: bilinear in the two mip levels around the level of
// detail, blended; the level of detail comes from the texture coordinates' screen derivatives.
enum class Filter { kNearest, kBilinear, kTrilinear };
enum class Wrap { kRepeat, kClampToEdge, kMirroredRepeat };

// How a texture's bytes encode its values: kLinear reads byte / 255; kSrgb is colour data
// stored with the sRGB transfer function (as images usually are), whose mip chain is built in
// linear space and which samplers with srgb_decode read as linear (GL_SRGB8_ALPHA8: alpha is
// always linear).
enum class ColorSpace { kLinear, kSrgb };

struct Sampler {
  Filter filter = Filter::kBilinear;
  Wrap wrap_u = Wrap::kRepeat;
  Wrap wrap_v = Wrap::kRepeat;
  // Decode kSrgb textures to linear before filtering (GL_DECODE_EXT). Off: their bytes read as
  // byte / 255, as a kLinear texture's do (GL_SKIP_DECODE_EXT; the default, today's look).
  bool srgb_decode = false;
};

// The sRGB transfer function and its inverse (IEC 61966-2-1), exact (std::pow).
float srgb_to_linear(float c);
float linear_to_srgb(float c);
// srgb_to_linear(k / 255) for k = 0..255, as floats (the decode table of kSrgb textures).
const float* srgb_decode_table();

// One level of a mip chain: its size and where its texels start (in texels).
struct MipLevel {
  int width = 0;
  int height = 0;
  size_t offset = 0;
};

// log2(x) for x > 0 to within 3e-5, with float operations only (so that the scalar and the wide
// samplers compute the same level of detail bit for bit): exponent plus a degree-5 polynomial
// (least-squares fit of log2(1 + t) on [0, 1]) of the mantissa.
inline float fast_log2(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  float exponent = float(int32_t(bits >> 23) - 127);
  bits = (bits & 0x007fffffu) | 0x3f800000u;
  float m;
  std::memcpy(&m, &bits, sizeof m);
  float t = m - 1.0f;
  float p = t * (1.44182512f + t * (-0.708674935f +
                                    t * (0.415397767f + t * (-0.194390433f + t * 0.0458707517f))));
  return exponent + p;
}

// An RGBA8 texture with its mip chain. Texel (i, j) has its centre at ((i + 0.5) / width,
// (j + 0.5) / height) in (u, v); j = 0 is the bottom row of the picture. Channels are read as
// linear values in [0, 1].
// Whether textures bound for a draw keep a copy of their texels in row pairs (Texture::row_pairs,
// row_pair_chain) for the AVX2 and AVX-512 samplers: bilinear and trilinear sampling faster
// (quad_grid texture about 13 % at AVX-512, 4 % at AVX2), for twice the texture's memory (three
// times with its mip chain), built at its first draw. On by default. A program that draws each
// texture once (one image) saves that time and memory by turning it off: the command line's
// `render` does when it draws one image. Not to be changed while a draw is running on another
// thread.
void set_texture_row_pairs(bool on);
bool texture_row_pairs();

class Texture {
 public:
  Texture() = default;
  Texture(const Texture& other);
  Texture& operator=(const Texture& other);
  Texture(Texture&&) noexcept = default;
  Texture& operator=(Texture&&) noexcept = default;
  // Takes an image as stored in a file (top row first) and flips it so that v = 0 is its bottom.
  // `space` says how the bytes encode colour; kSrgb builds the mip chain in linear space. The
  // levels past the base are built when first read (level(k) for k > 0, or trilinear sampling),
  // so a texture that is only ever sampled at its base level never pays for them.
  static Texture from_image(const Image& image, ColorSpace space = ColorSpace::kLinear);
  // A texture whose mip chain is given, not built: levels[k] is level k as stored in a file and
  // must be max(width >> k, 1) x max(height >> k, 1), down to 1x1 (else it aborts: a contract).
  // For pre-filtered chains, and for tests that tell the levels apart.
  static Texture from_mip_levels(const std::vector<Image>& levels,
                                 ColorSpace space = ColorSpace::kLinear);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return texels_.empty(); }
  ColorSpace color_space() const { return space_; }
  // Whether sampler `s` reads this texture through the sRGB decode.
  bool decodes(const Sampler& s) const { return s.srgb_decode && space_ == ColorSpace::kSrgb; }
  // The texels, rows bottom-up, RGBA8 (width * height * 4 bytes).
  const uint8_t* texels() const { return texels_.data(); }
  // Texel (i, j), j counted from the bottom row; precondition: in range.
  glm::vec4 texel(int i, int j) const {
    const uint8_t* t = &texels_[(size_t(j) * size_t(width_) + size_t(i)) * 4];
    constexpr float k = 1.0f / 255.0f;
    return {t[0] * k, t[1] * k, t[2] * k, t[3] * k};
  }

  // Samples at (u, v) with the sampler's filter and wrap modes. An empty texture samples as
  // opaque white, so a shader never has to test for a missing map. Without derivatives,
  // kTrilinear samples the base level (bilinear).
  glm::vec4 sample(const Sampler& s, glm::vec2 uv) const {
    if (texels_.empty()) return glm::vec4(1.0f);
    if (s.filter == Filter::kNearest) return sample_nearest(s, uv, 0);
    return sample_bilinear(s, uv, 0);
  }
  // The same with the change of (u, v) to the next pixel right (duv_dx) and down (duv_dy), which
  // choose the mip level for kTrilinear (OpenGL's level of detail: log2 of the longer of the two
  // derivative vectors in texels of the base level).
  glm::vec4 sample(const Sampler& s, glm::vec2 uv, glm::vec2 duv_dx, glm::vec2 duv_dy) const {
    if (texels_.empty() || s.filter != Filter::kTrilinear) return sample(s, uv);
    ensure_mips();
    float lod = level_of_detail(duv_dx, duv_dy);
    if (!(lod > 0.0f)) return sample_bilinear(s, uv, 0);  // magnification (and NaN)
    float top = float(levels() - 1);
    float d = lod < top ? lod : top;
    int l0 = int(d);
    float t = d - float(l0);
    glm::vec4 a = sample_bilinear(s, uv, l0);
    if (l0 + 1 >= levels()) return a;
    glm::vec4 b = sample_bilinear(s, uv, l0 + 1);
    return a * (1.0f - t) + b * t;
  }
  float level_of_detail(glm::vec2 duv_dx, glm::vec2 duv_dy) const {
    float w = float(width_), h = float(height_);
    float xx = duv_dx.x * w, xy = duv_dx.y * h, yx = duv_dy.x * w, yy = duv_dy.y * h;
    float rho2 = std::max(xx * xx + xy * xy, yx * yx + yy * yy);
    return 0.5f * fast_log2(rho2);  // log2(sqrt(rho2)) without the root
  }

  // The mip chain: level 0 is the image, each next level half the size (rounded down, at least
  // 1), down to 1x1; built once by 2x2 box filtering, on first use.
  int levels() const { return int(levels_.size()); }
  const MipLevel& level(int k) const {
    if (k > 0) ensure_mips();
    return levels_[size_t(k)];
  }
  // Builds levels 1 and up unless they are built (safe to call from several threads at once).
  void ensure_mips() const {
    if (mips_ && !mips_->ready.load(std::memory_order_acquire)) build_mips();
  }

  // Whether the picture lets what is behind it show: the base level is cut into squares, as
  // small as leaves at least 64x64 of them, and some square's mean alpha is below 250/255 (so a
  // translucent area of more than a few texels counts and a stray texel does not). Computed on
  // first use and kept: the built-in shaders ask it in every frame.
  bool translucent() const;

  // The base level's texels in vertical pairs, for the AVX2 and AVX-512 samplers' bilinear loads:
  // element (i, j) is the 64-bit pair of texels (i, clamp(j)) and (i, clamp(j + 1)), rows clamped
  // to the edge, for j from -1 (the returned pointer's row 0 is j = 0; row -1 lies before it). So
  // one 128-bit load at (i, j) holds all four texels a bilinear sample of rows j and j + 1 and
  // columns i and i + 1 reads. Built once (safe from several threads at once) when the texture
  // is first bound for a draw (SampledTexture), so draws after the first allocate nothing. Null
  // before that, with set_texture_row_pairs(false), for an empty texture and above
  // kMaxRowPairTexels texels.
  const uint64_t* row_pairs() const;
  static constexpr size_t kMaxRowPairTexels = size_t(1) << 22;
  // The same for every level of the mip chain (built first if it is not), for the AVX-512
  // trilinear sampler: level k's pair (i, j) is pairs[level_row0[k] + j * width_k + i], j from -1
  // as above. Null pointers where row_pairs() is null.
  struct RowPairChain {
    const uint64_t* pairs = nullptr;
    const int32_t* level_row0 = nullptr;
  };
  RowPairChain row_pair_chain() const;
  // How many times the texture was bound for a draw (SampledTexture's constructor counts, up to
  // 2^30).
  int draw_bindings() const { return mips_ ? mips_->bindings.load(std::memory_order_relaxed) : 0; }

  // Wraps texel index i into [0, size) by the OpenGL rules for each mode.
  static int wrap(Wrap mode, int i, int size);
  // wrap() of `count` indices in place, index k within sizes[k] (out of line: the wide samplers'
  // path for sizes that are not powers of two and for mirrored repeat).
  static void wrap_lanes(Wrap mode, int32_t* indices, const int32_t* sizes, int count);

 private:
  // GL_LINEAR of four RGBA8 texels (b0, b1: the lower row, t0, t1: the upper one) at fractions
  // fx, fy in [0, 1), in fixed point as the wide samplers compute it with 16-bit lanes (so every
  // path gives the same bits): levels with 7 fraction bits (255 * 128 at most), weights with 15
  // (filter_weight), each blend a + (b - a) * w rounded to the nearest 1/128 of a level
  // (mul_round15): each blend is off by at most 255 / 32768 + 1 / 256 of a level (0.024 for the
  // two), and where a weight is 0 a texel comes back as texel() gives it, bit for bit.
  static int filter_weight(float f) {
    int w = int(f * 32768.0f + 0.5f);
    return w < 32767 ? w : 32767;
  }
  static int mul_round15(int d, int w) { return (d * w + 16384) >> 15; }
  static glm::vec4 filter_rgba8(const uint8_t* b0, const uint8_t* b1, const uint8_t* t0,
                                const uint8_t* t1, float fx, float fy) {
    const int x = filter_weight(fx), y = filter_weight(fy);
    glm::vec4 out;
    for (int c = 0; c < 4; ++c) {
      int bottom = b0[c] * 128 + mul_round15((b1[c] - b0[c]) * 128, x);
      int top = t0[c] * 128 + mul_round15((t1[c] - t0[c]) * 128, x);
      int v = bottom + mul_round15(top - bottom, y);
      out[c] = (float(v) * (1.0f / 128.0f)) * (1.0f / 255.0f);
    }
    return out;
  }

  glm::vec4 sample_nearest(const Sampler& s, glm::vec2 uv, int level) const;
  glm::vec4 sample_bilinear(const Sampler& s, glm::vec2 uv, int level) const;
  glm::vec4 level_texel(const MipLevel& l, int i, int j, bool decode) const {
    const uint8_t* t = &texels_[(l.offset + size_t(j) * size_t(l.width) + size_t(i)) * 4];
    constexpr float k = 1.0f / 255.0f;
    if (decode) {
      const float* d = srgb_decode_table();
      return {d[t[0]], d[t[1]], d[t[2]], t[3] * k};
    }
    return {t[0] * k, t[1] * k, t[2] * k, t[3] * k};
  }

  // Leaves new elements uninitialised: the levels past the base are written when built, and
  // until then their pages are never touched (no zero-filling of memory that may never be used).
  template <class T>
  struct NoInitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
      using other = NoInitAllocator<U>;
    };
    NoInitAllocator() = default;
    template <class U>
    NoInitAllocator(const NoInitAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
      ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  };
  struct MipState {
    std::mutex mutex;
    std::atomic<bool> ready{false};
    std::atomic<int> translucent{-1};  // translucent(): -1 until computed
    std::vector<uint64_t> pairs;       // row_pairs(): written once, under `mutex`
    std::atomic<const uint64_t*> pairs_row0{nullptr};
    std::vector<uint64_t> chain_pairs;  // row_pair_chain(): written once, under `mutex`
    std::vector<int32_t> chain_row0;
    std::atomic<bool> chain_ready{false};
    std::atomic<int> bindings{0};  // draw_bindings()
  };
  friend class SampledTexture;  // counts the bindings
  // Whether the row pairs may be built: the base level is small enough, bound for a draw, and
  // the copies are on.
  bool pairs_allowed() const {
    return mips_ && size_t(width_) * size_t(height_) <= kMaxRowPairTexels && draw_bindings() >= 1 &&
           texture_row_pairs();
  }
  // Level `level`'s texels as row pairs, rows -1 to height - 1, into `out`.
  void pair_rows(const MipLevel& level, uint64_t* out) const;
  void build_mips() const;
  bool compute_translucent() const;
  static std::vector<MipLevel> mip_levels(int width, int height);
  void downsample(const MipLevel& from, const MipLevel& to);
  void downsample_srgb(const MipLevel& from, const MipLevel& to);

  ColorSpace space_ = ColorSpace::kLinear;
  int width_ = 0;
  int height_ = 0;
  // Every level, rows bottom-up, RGBA8; sized for the whole chain from the start (levels past
  // the base are written once, by build_mips, under mips_->mutex).
  mutable std::vector<uint8_t, NoInitAllocator<uint8_t>> texels_;
  std::vector<MipLevel> levels_;
  std::unique_ptr<MipState> mips_;  // null for an empty or moved-from texture
};

namespace detail {
// What the AVX2 and AVX-512 samplers' common case needs of a texture and its sampler: the base
// level of an RGBA8 texture without sRGB decode, filtered bilinearly, each axis clamped to the edge
// or repeated over a power-of-two size. `texels` is null where the case does not apply.
struct BilinearPlan {
  const int32_t* texels = nullptr;
  float width = 0.0f, height = 0.0f;  // the base level's size, as floats
  int32_t last_u = 0, last_v = 0;     // the size minus one: the largest index, the repeat mask
  bool repeat_u = false, repeat_v = false;  // else clamped to the edge
  int32_t row_width = 0;                    // texels per row
  int row_shift = -1;                       // log2(row_width) for a power of two, else -1
  // Texture::row_pairs(), set by SampledTexture's constructor where the sampler reads texels by
  // loads (gather_mode kLoads) at AVX2 or AVX-512; else null: of() leaves it so, and the gather
  // instruction reads the rows as they are.
  const int64_t* pairs = nullptr;

  static BilinearPlan of(const Texture& t, const Sampler& s) {
    BilinearPlan p;
    const int w = t.width(), h = t.height();
    const bool pow2_u = (w & (w - 1)) == 0, pow2_v = (h & (h - 1)) == 0;
    const bool u_ok = s.wrap_u == Wrap::kClampToEdge || (s.wrap_u == Wrap::kRepeat && pow2_u);
    const bool v_ok = s.wrap_v == Wrap::kClampToEdge || (s.wrap_v == Wrap::kRepeat && pow2_v);
    if (s.filter != Filter::kBilinear || t.decodes(s) || !u_ok || !v_ok || t.empty()) return p;
    p.texels = reinterpret_cast<const int32_t*>(t.texels());
    p.width = float(w);
    p.height = float(h);
    p.last_u = w - 1;
    p.last_v = h - 1;
    p.repeat_u = s.wrap_u == Wrap::kRepeat;
    p.repeat_v = s.wrap_v == Wrap::kRepeat;
    p.row_width = w;
    p.row_shift = pow2_u ? __builtin_ctz(unsigned(w)) : -1;
    return p;
  }
};
}  // namespace detail

// A texture and the sampler it is read through, bound for a draw (a shader holds one per map):
// what a wide sample would otherwise work out again for every block of 16 pixels (whether the
// texture is empty, which filter and wrap modes apply, the base level's size) is worked out once
// here. softrast::sample and sample_rgba8 take it in place of the pair, with the same results.
// It points into the texture, which must outlive it unchanged: build one per draw.
class SampledTexture {
 public:
  SampledTexture() : texture_(&no_texture()) {}  // samples as opaque white, as an empty texture
  // Binds `texture` for a draw (counted: Texture::row_pairs).
  SampledTexture(const Texture& texture, const Sampler& sampler)
      : texture_(&texture),
        sampler_(sampler),
        bilinear_(detail::BilinearPlan::of(texture, sampler)) {
    // (Counted up to 2^30: a program that binds a texture per block cannot wrap the count.)
    if (texture.mips_ && texture.mips_->bindings.load(std::memory_order_relaxed) < (1 << 30)) {
      texture.mips_->bindings.fetch_add(1, std::memory_order_relaxed);
    }
    if (bilinear_.texels != nullptr &&
        (simd_level() == SimdLevel::kAvx512 || simd_level() == SimdLevel::kAvx2) &&
        gather_mode(simd_level()) == GatherMode::kLoads) {
      bilinear_.pairs = reinterpret_cast<const int64_t*>(texture.row_pairs());
    }
  }
  // The same for one sample call (sample(texture, sampler, uv)): not a draw's binding, so neither
  // counted nor reading the row pairs.
  static SampledTexture for_one_call(const Texture& texture, const Sampler& sampler) {
    SampledTexture bound;
    bound.texture_ = &texture;
    bound.sampler_ = sampler;
    bound.bilinear_ = detail::BilinearPlan::of(texture, sampler);
    return bound;
  }
  const Texture& texture() const { return *texture_; }
  const Sampler& sampler() const { return sampler_; }
  // The common case's plan, or null where another path samples.
  const detail::BilinearPlan* bilinear() const {
    return bilinear_.texels != nullptr ? &bilinear_ : nullptr;
  }

 private:
  static const Texture& no_texture() {
    static const Texture empty;
    return empty;
  }
  const Texture* texture_;
  Sampler sampler_;
  detail::BilinearPlan bilinear_;
};

// Wraps texel index i into [0, size) by the OpenGL rules for each mode.
inline int Texture::wrap(Wrap mode, int i, int size) {
  switch (mode) {
    case Wrap::kRepeat: {
      if ((size & (size - 1)) == 0) return i & (size - 1);  // power of two: no division
      int m = i % size;
      return m < 0 ? m + size : m;
    }
    case Wrap::kClampToEdge:
      return i < 0 ? 0 : (i >= size ? size - 1 : i);
    case Wrap::kMirroredRepeat: {
      int period = 2 * size;
      int m = i % period;
      if (m < 0) m += period;
      return m < size ? m : period - 1 - m;
    }
  }
  return 0;
}

// Splits a texture coordinate scaled to texels into floor(x) and the fraction x - floor(x),
// without a library call, and without undefined behaviour for NaN or huge values (they land on
// texel 0 with fraction 0, then wrap like any other index).
inline int texel_floor(float x, float& fraction) {
  if (!(x > -1.0e9f && x < 1.0e9f)) {
    fraction = 0.0f;
    return 0;
  }
  int i = static_cast<int>(x);  // truncates towards zero
  if (float(i) > x) --i;
  fraction = x - float(i);
  return i;
}

inline glm::vec4 Texture::sample_nearest(const Sampler& s, glm::vec2 uv, int level) const {
  const MipLevel& l = levels_[size_t(level)];
  float unused;
  int i = wrap(s.wrap_u, texel_floor(uv.x * float(l.width), unused), l.width);
  int j = wrap(s.wrap_v, texel_floor(uv.y * float(l.height), unused), l.height);
  return level_texel(l, i, j, decodes(s));
}

inline glm::vec4 Texture::sample_bilinear(const Sampler& s, glm::vec2 uv, int level) const {
  // Texel centres sit at half-integers, so shift by half a texel before splitting into the
  // integer texel and the fractional weight (GL_LINEAR).
  const MipLevel& l = levels_[size_t(level)];
  float fx, fy;
  int x0 = texel_floor(uv.x * float(l.width) - 0.5f, fx);
  int y0 = texel_floor(uv.y * float(l.height) - 0.5f, fy);
  int i0 = wrap(s.wrap_u, x0, l.width), i1 = wrap(s.wrap_u, x0 + 1, l.width);
  int j0 = wrap(s.wrap_v, y0, l.height), j1 = wrap(s.wrap_v, y0 + 1, l.height);
  bool d = decodes(s);
  if (!d) {
    auto at = [&](int i, int j) {
      return &texels_[(l.offset + size_t(j) * size_t(l.width) + size_t(i)) * 4];
    };
    return filter_rgba8(at(i0, j0), at(i1, j0), at(i0, j1), at(i1, j1), fx, fy);
  }
  glm::vec4 bottom = level_texel(l, i0, j0, d) * (1.0f - fx) + level_texel(l, i1, j0, d) * fx;
  glm::vec4 top = level_texel(l, i0, j1, d) * (1.0f - fx) + level_texel(l, i1, j1, d) * fx;
  return bottom * (1.0f - fy) + top * fy;
}

}  // namespace softrast
