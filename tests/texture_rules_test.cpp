// Texture sampling held to the D3D / Vulkan definitions, written out here in double precision
// independently of texture.hpp: nearest at texel centres +-0.49 texel, bilinear at and between
// texel centres, the three wrap modes for coordinates in [-3, 3] and around +-1e6, sizes that
// are not powers of two, constant textures at every level (sRGB chains too), the sRGB transfer
// functions, the mip level chosen on a plane receding in perspective (Vulkan's LOD bounds), and
// the moire of the demo scene's far floor with and without mipmaps.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"
#include "test_util.hpp"
#include "texture/srgb_encode.hpp"
#include "texture_oracle.hpp"

namespace softrast {
namespace {

Image noise_image(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  Image image(width, height);
  for (uint8_t& b : image.rgba) b = uint8_t(rng());
  return image;
}

// Texel (i, j) as stored: j counted from the bottom row of the image (OpenGL's upload order).
glm::dvec4 texel_of(const Image& image, int i, int j) {
  const uint8_t* p = image.pixel(i, image.height - 1 - j);
  return glm::dvec4(p[0], p[1], p[2], p[3]) / 255.0;
}

using test::spec_wrap;

// The specification's GL_NEAREST and GL_LINEAR (texture_oracle.hpp) over an image.
glm::dvec4 spec_nearest(const Image& image, const Sampler& s, double u, double v) {
  auto texel = [&](int i, int j) { return texel_of(image, i, j); };
  return test::spec_nearest(texel, image.width, image.height, s, u, v);
}
glm::dvec4 spec_linear(const Image& image, const Sampler& s, double u, double v) {
  auto texel = [&](int i, int j) { return texel_of(image, i, j); };
  return test::spec_linear(texel, image.width, image.height, s, u, v);
}

// The wide sampler at 16 coordinates (4-lane vectors, the baseline ISA) against the scalar one.
std::array<glm::vec4, 16> wide_sample(const Texture& t, const Sampler& s,
                                      const std::array<glm::vec2, 16>& uv) {
  float u[16], v[16];
  for (int k = 0; k < 16; ++k) u[k] = uv[size_t(k)].x, v[k] = uv[size_t(k)].y;
  simd::Vec4<4> c =
      sample<4>(t, s, simd::Vec2<4>{simd::Float<4>::load(u), simd::Float<4>::load(v)});
  float r[16], g[16], b[16], a[16];
  c.x.store(r), c.y.store(g), c.z.store(b), c.w.store(a);
  std::array<glm::vec4, 16> out;
  for (int k = 0; k < 16; ++k) out[size_t(k)] = {r[k], g[k], b[k], a[k]};
  return out;
}

const std::vector<std::pair<int, int>> kSizes = {{8, 4}, {7, 5}, {1, 3}, {13, 16}, {64, 1}};
constexpr Wrap kWraps[] = {Wrap::kRepeat, Wrap::kClampToEdge, Wrap::kMirroredRepeat};

std::string name_of(int w, int h, Wrap wrap) {
  return std::to_string(w) + "x" + std::to_string(h) + " wrap " + std::to_string(int(wrap));
}

// Nearest: every coordinate within 0.49 texel of a texel centre, in [-3, 3] of (u, v) and for
// every wrap mode, returns that texel's wrapped value exactly, scalar and wide.
TEST(TextureRules, NearestAtTexelCentresPlusMinus049IsExact) {
  for (auto [w, h] : kSizes) {
    Image image = noise_image(w, h, unsigned(w * 31 + h));
    Texture t = Texture::from_image(image);
    for (Wrap wrap : kWraps) {
      SCOPED_TRACE(name_of(w, h, wrap));
      Sampler s{Filter::kNearest, wrap, wrap};
      std::array<glm::vec2, 16> batch;
      std::array<glm::vec4, 16> want;
      int filled = 0, checked = 0;
      for (int i = -3 * w; i < 3 * w; ++i) {
        for (double du : {-0.49, 0.0, 0.49}) {
          int j = ((i * 7 + 3) % (6 * h) + 6 * h) % (6 * h) - 3 * h;  // rows in [-3h, 3h)
          double u = (i + 0.5 + du) / w, v = (j + 0.5 - du) / h;
          int wi = spec_wrap(wrap, i, w), wj = spec_wrap(wrap, j, h);
          // The texel's own value, unfiltered (which is the image's byte / 255).
          glm::vec4 expect = t.texel(wi, wj);
          ASSERT_LT(glm::length(glm::dvec4(expect) - texel_of(image, wi, wj)), 1e-6);
          ASSERT_EQ(t.sample(s, glm::vec2(u, v)), expect)
              << "texel " << i << "," << j << " offset " << du;
          batch[size_t(filled)] = glm::vec2(u, v);
          want[size_t(filled)] = expect;
          if (++filled == 16) {
            std::array<glm::vec4, 16> got = wide_sample(t, s, batch);
            for (int k = 0; k < 16; ++k) {
              ASSERT_EQ(got[size_t(k)], want[size_t(k)]) << "wide lane " << k;
            }
            filled = 0;
          }
          ++checked;
        }
      }
      EXPECT_GT(checked, 0);
    }
  }
}

// Bilinear: exactly the texel at its centre, and within 1/255 of the double-precision GL_LINEAR
// everywhere else (random points in [-3, 3]^2), every wrap mode, scalar and wide the same bits.
TEST(TextureRules, BilinearExactAtCentresAndWithinOneLevelOfTheDoubleReference) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
  double worst = 0.0;
  int exact_centres = 0;
  for (auto [w, h] : kSizes) {
    Image image = noise_image(w, h, unsigned(w * 17 + h));
    Texture t = Texture::from_image(image);
    for (Wrap wrap : kWraps) {
      SCOPED_TRACE(name_of(w, h, wrap));
      Sampler s{Filter::kBilinear, wrap, wrap};
      for (int i = -w; i < 2 * w; ++i) {
        for (int j = -h; j < 2 * h; ++j) {
          glm::vec2 centre(float((i + 0.5) / w), float((j + 0.5) / h));
          glm::vec4 expect = t.texel(spec_wrap(wrap, i, w), spec_wrap(wrap, j, h));
          // Exact where the centre is exactly representable (u * w - 0.5 an integer in float,
          // always for powers of two); elsewhere the float coordinate is a hair off the centre.
          bool exact =
              centre.x * float(w) - 0.5f == float(i) && centre.y * float(h) - 0.5f == float(j);
          if (exact) {
            ++exact_centres;
            ASSERT_EQ(t.sample(s, centre), expect) << "centre of texel " << i << "," << j;
          } else {
            ASSERT_LT(glm::length(t.sample(s, centre) - expect), 1e-5f)
                << "texel " << i << "," << j;
          }
        }
      }
      for (int n = 0; n < 64; ++n) {
        std::array<glm::vec2, 16> batch;
        for (glm::vec2& uv : batch) uv = glm::vec2(float(coordinate(rng)), float(coordinate(rng)));
        std::array<glm::vec4, 16> wide = wide_sample(t, s, batch);
        for (size_t k = 0; k < 16; ++k) {
          glm::vec4 got = t.sample(s, batch[k]);
          ASSERT_EQ(wide[k], got) << "wide and scalar differ at " << batch[k].x << ","
                                  << batch[k].y;
          glm::dvec4 expect = spec_linear(image, s, batch[k].x, batch[k].y);
          for (int c = 0; c < 4; ++c) {
            double e = std::abs(double(got[c]) - expect[c]);
            worst = std::max(worst, e);
            ASSERT_LE(e, 1.0 / 255.0) << "at " << batch[k].x << "," << batch[k].y;
          }
        }
      }
    }
  }
  EXPECT_GT(exact_centres, 500);
  RecordProperty("worst_bilinear_error", std::to_string(worst));
  // The fixed-point filter (Texture::filter_rgba8): each of the two blends is off by at most
  // 255 / 32768 of a level through its 15-bit weight and 1/256 through its rounding to 1/128,
  // so 0.024 of a level at most, far inside the 1/255 allowed.
  EXPECT_LT(worst, 0.024 / 255.0);
}

// Around +-1e6 (coordinates whose products with the sizes are exact in float, so that the
// double reference sees the same point): nearest and bilinear follow the wrap rules there too.
TEST(TextureRules, WrapModesHoldAtPlusMinusOneMillion) {
  for (auto [w, h] : {std::pair{8, 4}, std::pair{7, 5}, std::pair{3, 5}}) {
    Image image = noise_image(w, h, unsigned(w + 5 * h));
    Texture t = Texture::from_image(image);
    for (Wrap wrap : kWraps) {
      for (Filter filter : {Filter::kNearest, Filter::kBilinear}) {
        SCOPED_TRACE(name_of(w, h, wrap) + " filter " + std::to_string(int(filter)));
        Sampler s{filter, wrap, wrap};
        for (double sign : {1.0, -1.0}) {
          for (int m = -6; m <= 6; ++m) {
            double u = sign * 1.0e6 + m * 0.5, v = sign * 1.0e6 - m * 0.5;
            ASSERT_EQ(double(float(u)), u);
            ASSERT_EQ(double(float(v)), v);
            // The scaling and the half-texel shift are exact in float.
            ASSERT_EQ(double(float(u) * float(w) - 0.5f), u * w - 0.5);
            ASSERT_EQ(double(float(v) * float(h) - 0.5f), v * h - 0.5);
            glm::dvec4 expect = filter == Filter::kNearest ? spec_nearest(image, s, u, v)
                                                           : spec_linear(image, s, u, v);
            glm::vec4 got = t.sample(s, glm::vec2(float(u), float(v)));
            for (int c = 0; c < 4; ++c) {
              ASSERT_NEAR(got[c], expect[c], 1e-6) << "at " << u << "," << v;
            }
          }
        }
      }
    }
  }
}

// A constant texture of any size is the constant at every level of detail with every filter;
// an sRGB texture's chain (built in linear space) keeps every one of the 256 values exactly.
TEST(TextureRules, ConstantTextureIsTheConstantAtEveryLevelLinearAndSrgb) {
  for (ColorSpace space : {ColorSpace::kLinear, ColorSpace::kSrgb}) {
    for (int value = 0; value < 256; value += (space == ColorSpace::kSrgb ? 1 : 15)) {
      Image image(23, 11);
      for (size_t k = 0; k < image.rgba.size(); ++k)
        image.rgba[k] = uint8_t(k % 4 == 3 ? 77 : value);
      Texture t = Texture::from_image(image, space);
      for (int level = 0; level < t.levels(); ++level) {
        const uint8_t* texels = t.texels() + t.level(level).offset * 4;
        for (int k = 0; k < t.level(level).width * t.level(level).height * 4; ++k) {
          ASSERT_EQ(texels[k], k % 4 == 3 ? 77 : value) << "level " << level << " value " << value;
        }
      }
      for (bool decode : {false, true}) {
        Sampler s{Filter::kTrilinear, Wrap::kMirroredRepeat, Wrap::kRepeat, decode};
        float expect = decode && space == ColorSpace::kSrgb ? srgb_to_linear(value / 255.0f)
                                                            : float(value) / 255.0f;
        for (float lod = -1.0f; lod < 7.0f; lod += 0.45f) {
          float step = std::exp2(lod) / 23.0f;
          glm::vec4 c = t.sample(s, {0.37f, -1.3f}, {step, 0.0f}, {0.0f, step});
          ASSERT_FLOAT_EQ(c.r, expect) << "lod " << lod << " value " << value;
          ASSERT_FLOAT_EQ(c.a, 77.0f / 255.0f);
        }
      }
    }
  }
}

// The sRGB transfer functions: the standard's breakpoints and values, and the decode table is
// the curve. The chain of an sRGB black-and-white checker is sRGB(0.5) = 188, not 128.
TEST(TextureRules, SrgbCurvesAndTheChainBuiltInLinearSpace) {
  EXPECT_FLOAT_EQ(srgb_to_linear(0.0f), 0.0f);
  EXPECT_FLOAT_EQ(srgb_to_linear(1.0f), 1.0f);
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041, 1e-6);
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.735357, 1e-6);
  EXPECT_NEAR(srgb_to_linear(0.04045f), 0.04045 / 12.92, 1e-7);
  for (int k = 0; k < 256; ++k) {
    EXPECT_EQ(int(linear_to_srgb(srgb_decode_table()[k]) * 255.0f + 0.5f), k);
  }
  Image checker(2, 2);
  for (size_t p = 0; p < 4; ++p) {
    uint8_t v = (p == 0 || p == 3) ? 255 : 0;
    checker.rgba[p * 4] = checker.rgba[p * 4 + 1] = checker.rgba[p * 4 + 2] = v;
    checker.rgba[p * 4 + 3] = 255;
  }
  Texture linear = Texture::from_image(checker, ColorSpace::kLinear);
  Texture srgb = Texture::from_image(checker, ColorSpace::kSrgb);
  EXPECT_EQ(linear.texels()[linear.level(1).offset * 4], 128);
  EXPECT_EQ(srgb.texels()[srgb.level(1).offset * 4], 188);  // 0.7354 * 255 rounded
}

// ------------------------------------------------------------------------------------------
// Mip selection on a receding plane.

// Each level of a 256x256 texture a solid colour whose red is 16 * level: trilinear filtering
// then writes red = 16 * (the level of detail, clamped to the chain), so every pixel tells the
// level of detail the sampler used.
Texture level_coded_texture() {
  std::vector<Image> levels;
  for (int k = 0, size = 256; size >= 1; ++k, size /= 2) {
    Image level(size, size);
    for (size_t p = 0; p < level.rgba.size(); p += 4) {
      level.rgba[p] = uint8_t(16 * k);
      level.rgba[p + 1] = 255;
      level.rgba[p + 2] = uint8_t(255 - 16 * k);
      level.rgba[p + 3] = 255;
    }
    levels.push_back(std::move(level));
  }
  return Texture::from_mip_levels(levels);
}

// Vulkan 1.3, 16.5.7 (scale factor and level of detail): rho_x may be anything from
// max(|du/dx|, |dv/dx|) to |du/dx| + |dv/dx| (in texels), likewise rho_y, and the derivatives
// may be fine (per row or column of the 2x2 quad) or coarse (one per quad); lambda = log2 of
// max(rho_x, rho_y). The bounds are the smallest and largest lambda over all of these, from the
// plane's exact uv at the four pixel centres of each quad.
struct LodBounds {
  double lo, hi;
};

// The table-driven encoder that builds sRGB mip chains (no pow per texel) gives the formula's byte
// for every float in [0, 1] tried: a dense sweep over the float bits (every 251st float, about
// 4.2 million values, denser than any threshold gap) and the floats on both sides of every point
// where the formula's byte changes.
TEST(TextureRules, SrgbByteTableEqualsTheFormula) {
  auto bits_float = [](uint32_t b) {
    float f;
    std::memcpy(&f, &b, sizeof f);
    return f;
  };
  uint32_t one;
  float f1 = 1.0f;
  std::memcpy(&one, &f1, sizeof one);
  int mismatches = 0, changes = 0;
  uint8_t previous = linear_to_srgb_byte_exact(0.0f);
  for (uint32_t b = 0; b <= one; b += 251) {
    float c = bits_float(b);
    uint8_t exact = linear_to_srgb_byte_exact(c);
    if (linear_to_srgb_byte(c) != exact) ++mismatches;
    if (exact != previous) {
      // The change happened in (b - 251, b]: check every float there.
      ++changes;
      for (uint32_t k = b - 251; k <= b; ++k) {
        float d = bits_float(k);
        if (linear_to_srgb_byte(d) != linear_to_srgb_byte_exact(d)) ++mismatches;
      }
      previous = exact;
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(changes, 255);  // every byte value is reached, in order
  for (float c : {-1.0f, -0.0f, 1.5f, INFINITY, NAN}) {
    EXPECT_EQ(linear_to_srgb_byte(c), linear_to_srgb_byte_exact(c)) << c;
  }
}

TEST(TextureRules, MipLevelOnARecedingPlaneIsWithinTheLodBounds) {
  constexpr int kW = 256, kH = 192;
  const double kTexels = 256.0, kUvPerUnit = 0.25;  // uv per world unit
  Mesh plane;
  plane.positions = {{-100, 0, 10}, {100, 0, 10}, {100, 0, -400}, {-100, 0, -400}};
  plane.normals.assign(4, glm::vec3(0, 1, 0));
  for (const glm::vec3& p : plane.positions) {
    plane.uvs.push_back(glm::vec2(p.x, -p.z) * float(kUvPerUnit));
  }
  plane.indices = {0, 1, 2, 0, 2, 3};
  Camera camera;
  camera.eye = {0, 2, 5};
  camera.target = {3, 0, -10};
  camera.near_plane = 0.5f;
  camera.far_plane = 1000.0f;
  RenderOptions options;
  options.shader = ShaderKind::kTexture;
  options.texture = std::make_shared<Texture>(level_coded_texture());
  options.sampler.filter = Filter::kTrilinear;
  options.state.cull = CullMode::kNone;
  Framebuffer fb(kW, kH);
  fb.clear(glm::vec4(0.0f), 1.0f, 0);
  render_mesh(fb, plane, camera, options);

  // The plane's uv at a pixel centre: the view ray through it met with y = 0, in double.
  glm::dmat4 inverse = glm::inverse(glm::dmat4(camera.view_projection(float(kW) / kH)));
  auto uv_at = [&](double x, double y) {
    glm::dvec4 ndc(2.0 * x / kW - 1.0, 1.0 - 2.0 * y / kH, -1.0, 1.0);
    glm::dvec4 near = inverse * ndc;
    ndc.z = 1.0;
    glm::dvec4 far = inverse * ndc;
    glm::dvec3 a = glm::dvec3(near) / near.w, b = glm::dvec3(far) / far.w;
    double t = a.y / (a.y - b.y);
    glm::dvec3 p = a + (b - a) * t;
    return glm::dvec2(p.x, -p.z) * kUvPerUnit * kTexels;  // in texels of level 0
  };
  auto bounds_of_quad = [&](int qx, int qy) {
    glm::dvec2 c[2][2];
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) c[j][i] = uv_at(qx + i + 0.5, qy + j + 0.5);
    }
    double lo = 1e30, hi = -1e30;
    for (int row = 0; row < 2; ++row) {
      for (int col = 0; col < 2; ++col) {
        glm::dvec2 dx = c[row][1] - c[row][0], dy = c[1][col] - c[0][col];
        double min_rho = std::max(std::max(std::abs(dx.x), std::abs(dx.y)),
                                  std::max(std::abs(dy.x), std::abs(dy.y)));
        double max_rho = std::max(std::abs(dx.x) + std::abs(dx.y), std::abs(dy.x) + std::abs(dy.y));
        lo = std::min(lo, std::log2(min_rho));
        hi = std::max(hi, std::log2(max_rho));
      }
    }
    return LodBounds{lo, hi};
  };
  const double top = 8.0;  // the 1x1 level
  // Red is 16 * lambda rounded to 8 bits: half a step of 1/16 either way.
  const double kQuantum = 0.5 / 16.0 + 1e-3;
  int checked = 0;
  std::array<int, 9> seen{};
  for (int qy = 0; qy < kH; qy += 2) {
    for (int qx = 0; qx < kW; qx += 2) {
      bool covered = true;
      for (int k = 0; k < 4; ++k) covered = covered && fb.depth_at(qx + k % 2, qy + k / 2) < 1.0f;
      if (!covered) continue;  // the horizon's quads: some of their pixels show no plane
      LodBounds b = bounds_of_quad(qx, qy);
      double lo = std::clamp(b.lo, 0.0, top), hi = std::clamp(b.hi, 0.0, top);
      for (int k = 0; k < 4; ++k) {
        int x = qx + k % 2, y = qy + k / 2;
        double lambda = double(fb.color_at(x, y) & 0xff) / 16.0;
        ASSERT_GE(lambda, lo - kQuantum)
            << "pixel " << x << "," << y << " bounds " << lo << ".." << hi;
        ASSERT_LE(lambda, hi + kQuantum)
            << "pixel " << x << "," << y << " bounds " << lo << ".." << hi;
        seen[size_t(std::lround(std::floor(lambda)))]++;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, kW * kH / 3);
  int levels_seen = 0;
  for (int n : seen) levels_seen += n > 0;
  EXPECT_GE(levels_seen, 6) << "the plane should span most of the chain";
}

// ------------------------------------------------------------------------------------------
// The demo scene's far floor.

// High-frequency energy: the mean squared discrete Laplacian of the luminance over the pixels
// of rows [y0, y1) that, with their four neighbours, lie deeper than `min_depth` in `depth_of`.
double laplacian_energy(const Framebuffer& fb, const Framebuffer& depth_of, int y0, int y1,
                        float min_depth) {
  auto lum = [&](int x, int y) {
    uint32_t c = fb.color_at(x, y);
    return 0.299 * (c & 0xff) + 0.587 * ((c >> 8) & 0xff) + 0.114 * ((c >> 16) & 0xff);
  };
  auto deep = [&](int x, int y) {
    float z = depth_of.depth_at(x, y);
    return z > min_depth && z < 1.0f;
  };
  double sum = 0.0;
  int n = 0;
  for (int y = std::max(y0, 1); y < std::min(y1, fb.height() - 1); ++y) {
    for (int x = 1; x < fb.width() - 1; ++x) {
      if (!deep(x, y) || !deep(x - 1, y) || !deep(x + 1, y) || !deep(x, y - 1) || !deep(x, y + 1)) {
        continue;
      }
      double l = 4 * lum(x, y) - lum(x - 1, y) - lum(x + 1, y) - lum(x, y - 1) - lum(x, y + 1);
      sum += l * l;
      ++n;
    }
  }
  EXPECT_GT(n, 2000) << "too few far floor pixels";
  return n ? sum / n : 0.0;
}

// The far floor of the demo scene (its checker squares smaller than a pixel) aliases into moire
// with bilinear filtering; trilinear filtering removes most of its high-frequency energy. The
// far floor: the 40 rows from the floor's far edge (the first row the floor covers from side to
// side) down, where the depth is beyond 0.955 (the floor farther than about 10 units; the
// objects in front are nearer).
TEST(TextureRules, DemoFarFloorMoireEnergyFallsWithMipmaps) {
  DemoScene demo = make_demo_scene();
  auto render = [&](Filter filter) {
    RenderOptions options;
    options.shader = ShaderKind::kTexture;
    options.sampler.filter = filter;
    auto fb = std::make_unique<Framebuffer>(640, 480);
    fb->clear();
    render_mesh(*fb, demo.mesh, demo.camera, options);
    return fb;
  };
  auto bilinear = render(Filter::kBilinear);
  auto trilinear = render(Filter::kTrilinear);
  int far_top = -1;
  for (int y = 0; y < 480 && far_top < 0; ++y) {
    int covered = 0;
    for (int x = 0; x < 640; ++x) covered += bilinear->depth_at(x, y) < 1.0f;
    if (covered == 640) far_top = y;
  }
  ASSERT_GE(far_top, 0) << "no floor edge found";
  double e_bilinear = laplacian_energy(*bilinear, *bilinear, far_top, far_top + 40, 0.955f);
  double e_trilinear = laplacian_energy(*trilinear, *bilinear, far_top, far_top + 40, 0.955f);
  RecordProperty("energy_bilinear", std::to_string(e_bilinear));
  RecordProperty("energy_trilinear", std::to_string(e_trilinear));
  std::printf("far floor rows %d..%d: Laplacian energy bilinear %.1f, trilinear %.1f (x%.3f)\n",
              far_top, far_top + 40, e_bilinear, e_trilinear, e_trilinear / e_bilinear);
  EXPECT_LT(e_trilinear, 0.25 * e_bilinear);
}

// Texture::translucent, which sends a textured surface to the second (blended) pass: a stray
// transparent texel does not make a picture translucent, a transparent area of one square (16x16
// texels of a 1024x1024 picture, which has 64x64 such squares) does, and so does an alpha of
// 200/255 everywhere. The answer is kept, and a copy gives the same.
TEST(TextureRules, TranslucentCountsAreasNotStrayTexels) {
  EXPECT_FALSE(Texture().translucent());
  auto picture = [](int area, uint8_t alpha) {
    Image image(1024, 1024);
    for (size_t k = 0; k < image.rgba.size(); k += 4) {
      image.rgba[k] = 90, image.rgba[k + 1] = 120, image.rgba[k + 2] = 200;
      image.rgba[k + 3] = 255;
    }
    for (int y = 0; y < area; ++y) {
      for (int x = 0; x < area; ++x) image.pixel(320 + x, 480 + y)[3] = alpha;
    }
    return Texture::from_image(image);
  };
  EXPECT_FALSE(picture(0, 0).translucent());
  EXPECT_FALSE(picture(1, 0).translucent());            // one texel: its square's mean is 254
  EXPECT_TRUE(picture(16, 0).translucent());            // a whole square
  EXPECT_TRUE(picture(1024 - 480, 200).translucent());  // alpha 200 over the lower rows
  Texture t = picture(16, 0);
  EXPECT_TRUE(t.translucent());
  EXPECT_TRUE(t.translucent());  // the kept answer
  Texture copy = t;
  EXPECT_TRUE(copy.translucent());
}

// The AVX-512 sampler's row pairs: element (i, j) holds texel (i, j) and the one above it, each
// row clamped to the texture, for j from -1 to the last row, of the base level and of every level
// of the chain; built once, for copies too; none for an empty texture or above kMaxRowPairTexels
// texels.
TEST(TextureRules, RowPairsHoldEachTexelAndTheOneAboveClampedAtBothEdges) {
  EXPECT_EQ(Texture().row_pairs(), nullptr);
  const Image image = noise_image(5, 3, 17);
  const Texture t = Texture::from_image(image);
  // None until the texture is bound for a draw, or while the copies are off.
  const Sampler bilinear{Filter::kBilinear, Wrap::kRepeat, Wrap::kRepeat, false};
  EXPECT_EQ(t.row_pairs(), nullptr);
  EXPECT_EQ(t.row_pair_chain().pairs, nullptr);
  (void)sample<4>(t, bilinear, simd::Vec2<4>{});  // one call's binding does not count
  EXPECT_EQ(t.draw_bindings(), 0);
  set_texture_row_pairs(false);
  SampledTexture first(t, bilinear);
  EXPECT_EQ(t.draw_bindings(), 1);
  EXPECT_EQ(t.row_pairs(), nullptr);
  set_texture_row_pairs(true);
  auto stored = [&](int i, int j) {  // texel (i, j) as the image holds it, red in the low byte
    const uint8_t* p = image.pixel(i, image.height - 1 - j);
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
  };
  const Texture copy = t;
  EXPECT_EQ(copy.row_pairs(), nullptr);  // not bound yet: the copy's own count
  SampledTexture(copy, bilinear);
  for (const Texture* texture : {&t, &copy}) {
    const uint64_t* pairs = texture->row_pairs();
    ASSERT_NE(pairs, nullptr);
    EXPECT_EQ(texture->row_pairs(), pairs);  // kept
    for (int j = -1; j < 3; ++j) {
      for (int i = 0; i < 5; ++i) {
        const uint64_t want = stored(i, std::max(j, 0)) | uint64_t(stored(i, std::min(j + 1, 2)))
                                                              << 32;
        EXPECT_EQ(pairs[j * 5 + i], want) << "pair " << i << "," << j;
      }
    }
  }
  EXPECT_NE(copy.row_pairs(), t.row_pairs());  // the copy's own
  // The chain's pairs, level by level (5x3, 2x1, 1x1), from the levels' own texels.
  const Texture::RowPairChain chain = t.row_pair_chain();
  ASSERT_NE(chain.pairs, nullptr);
  ASSERT_EQ(t.levels(), 3);
  for (int k = 0; k < t.levels(); ++k) {
    const MipLevel& level = t.level(k);
    auto texel = [&](int i, int j) {
      uint32_t v;
      std::memcpy(&v, t.texels() + (level.offset + size_t(j) * level.width + size_t(i)) * 4, 4);
      return v;
    };
    for (int j = -1; j < level.height; ++j) {
      for (int i = 0; i < level.width; ++i) {
        const uint64_t want =
            texel(i, std::max(j, 0)) | uint64_t(texel(i, std::min(j + 1, level.height - 1))) << 32;
        EXPECT_EQ(chain.pairs[chain.level_row0[k] + j * level.width + i], want)
            << "level " << k << " pair " << i << "," << j;
      }
    }
  }
  EXPECT_EQ(t.row_pair_chain().pairs, chain.pairs);  // kept
  const Texture over = Texture::from_image(Image(2049, 2048));
  const Texture largest = Texture::from_image(Image(2048, 2048));
  for (const Texture* texture : {&over, &largest}) {
    SampledTexture(*texture, bilinear);
  }
  EXPECT_EQ(over.row_pairs(), nullptr);
  EXPECT_EQ(over.row_pair_chain().pairs, nullptr);
  EXPECT_NE(largest.row_pairs(), nullptr);
}

}  // namespace
}  // namespace softrast
