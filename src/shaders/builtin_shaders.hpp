// shaders/builtin_shaders.hpp: the built-in shaders as types for softrast::draw. Each pulls its
// vertex inputs from a Mesh by index. Formulas and constants are those of SCENES.md. Fragment
// shaders are wide (a 4x4 block per call, see softrast/shader.hpp), except the depth view's.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

#include "shaders/shading_math.hpp"
#include "shaders/shadow_map.hpp"
#include "softrast/mesh.hpp"
#include "softrast/shader.hpp"
#include "softrast/texture.hpp"

namespace softrast::detail {

inline constexpr float kAmbient = 0.15f;
inline constexpr float kDiffuse = 0.85f;
inline constexpr float kSpecular = 0.4f;
inline constexpr float kShininess = 32.0f;

// The light of the lit shaders: Lambert diffuse plus (phong) Blinn-Phong specular, with
// ambient + diffuse_scale * max(n.l, 0) as the diffuse factor. SCENES.md's values by default;
// --ambient and --light-intensity change them (diffuse and specular scale with the intensity).
struct Lighting {
  glm::vec3 light{0.0f, 0.0f, 1.0f};  // towards the light, normalised
  float ambient = kAmbient;
  float diffuse = kDiffuse;
  float specular = kSpecular;
  // Back-facing primitives are lit with their normal flipped (two-sided lighting), so a
  // single-sided surface seen from behind looks as it does from the front.
  bool two_sided = false;
  const ShadowMap* shadow = nullptr;  // phong: diffuse and specular times the light's visibility
  // A point light at `position` (world space) instead of the direction `light`.
  bool point = false;
  glm::vec3 position{0.0f};
  // Shaders encode their output with the sRGB transfer function (the linear workflow).
  bool srgb_output = false;
};

// Inputs shared by the built-in shaders.
struct MeshInputs {
  const Mesh* mesh = nullptr;
  glm::mat4 mvp{1.0f};
  // The material's placement of its maps (Material::uv_scale, uv_offset): an affine map of the
  // uvs, so applying it per vertex gives the interpolated uvs it would give per pixel.
  glm::vec2 uv_scale{1.0f};
  glm::vec2 uv_offset{0.0f};
  // The world positions a shader interpolates, times this power of two (shading_scale,
  // pbr_render.hpp): 1 unless the scene is in units far from 1.
  float position_scale = 1.0f;
  glm::vec4 clip(uint32_t i) const { return mvp * glm::vec4(mesh->positions[i], 1.0f); }
  glm::vec2 uv(uint32_t i) const { return mesh->uvs[i] * uv_scale + uv_offset; }
  glm::vec3 position(uint32_t i) const { return mesh->positions[i] * position_scale; }

  // The same for 16 vertices (a wide vertex shader's inputs), each the scalar function's
  // operations in its order, so the same bits: glm's mat4 * vec4 is
  // (m[0] x + m[1] y) + (m[2] z + m[3] 1).
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> clip(const Vertices<N>& v) const {
    return clip<N>(v.vec3(mesh->positions.data()));
  }
  // ... of positions already read (the mesh's, unscaled).
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> clip(const simd::Vec3<N>& p) const {
    using F = simd::Float<N>;
    simd::Vec4<N> c;
    F* out[4] = {&c.x, &c.y, &c.z, &c.w};
    for (int r = 0; r < 4; ++r) {
      *out[r] =
          (F(mvp[0][r]) * p.x + F(mvp[1][r]) * p.y) + (F(mvp[2][r]) * p.z + F(mvp[3][r] * 1.0f));
    }
    return c;
  }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec2<N> uv(const Vertices<N>& v) const {
    using F = simd::Float<N>;
    const simd::Vec2<N> t = v.vec2(mesh->uvs.data());
    return {t.x * F(uv_scale.x) + F(uv_offset.x), t.y * F(uv_scale.y) + F(uv_offset.y)};
  }
  // position(i) of positions already read.
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec3<N> position(const simd::Vec3<N>& p) const {
    using F = simd::Float<N>;
    const F s(position_scale);
    return {p.x * s, p.y * s, p.z * s};
  }
};

// Samples at the uv in varyings (i, i + 1), with their derivatives when the filter needs them.
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_with_derivatives(const SampledTexture& t,
                                                           const Fragments<N>& f, int i) {
  simd::Vec2<N> uv = f.vec2(i);
  if (t.sampler().filter != Filter::kTrilinear) return sample<N>(t, uv);
  return sample<N>(t, uv, {f.ddx(uv.x), f.ddx(uv.y)}, {f.ddy(uv.x), f.ddy(uv.y)});
}

// A map bound to the sampler for a draw; no map samples as opaque white.
inline SampledTexture bind_map(const Texture* map, const Sampler& s) {
  return map != nullptr ? SampledTexture(*map, s) : SampledTexture();
}

// Where a shader takes a vertex's albedo from: the mesh's vertex colours (OBJ, PLY), when it has
// them and `use` is set, else the material's. Vertex colours are display values, as texels are:
// decoded from sRGB in the linear workflow (`decode`), as textures are.
struct ColorSource {
  bool use = false;
  bool decode = false;
  glm::vec3 albedo(const Mesh& mesh, uint32_t i, const glm::vec3& fallback) const {
    if (!use) return fallback;
    glm::vec3 c(mesh.colors[i]);
    if (!decode) return c;
    auto linear = [](float x) {
      return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
    };
    return {linear(c.r), linear(c.g), linear(c.b)};
  }
};

struct FlatShader {
  static constexpr int kVaryings = 0;
  static constexpr bool kCheapToShade = true;  // a constant colour (see GouraudShader)
  MeshInputs in;
  glm::vec4 color;
  bool srgb = false;  // encode the output (the linear workflow)
  glm::vec4 vertex(uint32_t i, float*) const { return in.clip(i); }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& v, simd::Float<N>*) const {
    return in.clip(v);
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    if (f.opaque && !srgb) {  // one scalar pack instead of the fragment stage's 16-lane one
      f.set_rgba8(simd::Int<N>(int32_t(softrast::pack_rgba8(color))));
      return;
    }
    f.color = {color.r, color.g, color.b, color.a};
    if (srgb) f.color = encode_srgb<N>(f.color);
  }
};

// One-sided: the colour lit by the vertex normal. Two-sided: the colours for both faces (by n
// and by -n), the fragment picks by the primitive's facing.
// kVertexAlbedo: the albedo is each vertex's own (the mesh's vertex colours), so the lit colour
// is what is interpolated: 3 varyings (6 two-sided). Otherwise the albedo is the material's, one
// colour for the draw, and the colour is that albedo times the light's intensity: the intensity
// alone is interpolated (1 varying, 2 two-sided) and the fragment multiplies it by the albedo.
// The same colour up to the rounding of one product, which moves a channel by 1 in a few
// pixels in a million (spheres_1m: 20 of 2,073,600), with a third of the planes to set up, store
// and interpolate.
template <bool kTwoSided, bool kVertexAlbedo = false>
struct GouraudShader {
  static constexpr int kPerFace = kVertexAlbedo ? 3 : 1;
  static constexpr int kVaryings = kTwoSided ? 2 * kPerFace : kPerFace;
  // Its fragment stage is a few products: shading several small triangles per call (lanes
  // picking their triangle's planes) costs about what it saves. Below AVX-512 it is slower
  // (spheres_1m gouraud, one thread, AVX2: 50.7 -> 55.5 ms with three varyings, 49.0 -> 52.0 with
  // one), at AVX-512 faster (43.3 -> 42.7 ms with three), which is where shader.hpp takes it for
  // a kCheapToShade shader.
  static constexpr bool kCheapToShade = true;
  bool reads_derivatives() const { return false; }
  MeshInputs in;
  glm::vec3 albedo;
  Lighting lighting;
  float alpha = 1.0f;
  ColorSource colors;  // the mesh's vertex colours as the albedo (kVertexAlbedo only)
  float intensity(const glm::vec3& n) const {
    return lighting.ambient + lighting.diffuse * std::max(glm::dot(n, lighting.light), 0.0f);
  }
  glm::vec4 vertex(uint32_t i, float* v) const {
    glm::vec3 n = glm::normalize(in.mesh->normals[i]);
    if constexpr (kVertexAlbedo) {
      glm::vec3 base = colors.albedo(*in.mesh, i, albedo);
      glm::vec3 c = base * intensity(n);
      v[0] = c.r, v[1] = c.g, v[2] = c.b;
      if constexpr (kTwoSided) {
        glm::vec3 back = base * intensity(-n);
        v[3] = back.r, v[4] = back.g, v[5] = back.b;
      }
    } else {
      v[0] = intensity(n);
      if constexpr (kTwoSided) v[1] = intensity(-n);
    }
    return in.clip(i);
  }
  // vertex() on 16 vertices: glm's normalize (v times 1 / sqrt((x x + y y) + z z)), dot and
  // std::max lane-wise, so the same bits. Vertex colours (decoded through std::pow) take vertex().
  bool wide_vertices() const { return !kVertexAlbedo || !colors.use; }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& vs, simd::Float<N>* v) const {
    using F = simd::Float<N>;
    const simd::Vec3<N> m = vs.vec3(in.mesh->normals.data());
    const F inv = F(1.0f) / simd::sqrt((m.x * m.x + m.y * m.y) + m.z * m.z);
    const simd::Vec3<N> n = {m.x * inv, m.y * inv, m.z * inv};
    lit_wide<N>(n, v);
    if constexpr (kTwoSided) lit_wide<N>({-n.x, -n.y, -n.z}, v + kPerFace);
    return in.clip(vs);
  }
  // intensity() (times the material's albedo, kVertexAlbedo) to kPerFace varyings.
  template <int N>
  SOFTRAST_SIMD_INLINE void lit_wide(const simd::Vec3<N>& n, simd::Float<N>* v) const {
    using F = simd::Float<N>;
    const glm::vec3& l = lighting.light;
    F d = (n.x * F(l.x) + n.y * F(l.y)) + n.z * F(l.z);
    d = simd::select(d < F(0.0f), F(0.0f), d);  // std::max(d, 0.0f)
    const F s = F(lighting.ambient) + F(lighting.diffuse) * d;
    if constexpr (kVertexAlbedo) {
      v[0] = F(albedo.r) * s, v[1] = F(albedo.g) * s, v[2] = F(albedo.b) * s;
    } else {
      v[0] = s;
    }
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    const int first = kTwoSided && !f.front_facing ? kPerFace : 0;
    if constexpr (kVertexAlbedo) {
      f.color = {f.varying(first), f.varying(first + 1), f.varying(first + 2), alpha};
    } else {
      using F = simd::Float<N>;
      const F s = f.varying(first);
      f.color = {F(albedo.r) * s, F(albedo.g) * s, F(albedo.b) * s, alpha};
    }
    if (lighting.srgb_output) f.color = encode_srgb<N>(f.color);
  }
};

struct TextureShader {
  static constexpr int kVaryings = 2;
  MeshInputs in;
  SampledTexture map;  // the texture and its sampler
  float alpha = 1.0f;
  bool srgb = false;  // encode the output (the linear workflow)
  // Opaque pixels take the texel as it is (alpha 1, nothing encoded, no mip levels): decided
  // once for the draw (packed_texel()), not per block, so the fields are set here.
  bool packed = false;
  explicit TextureShader(MeshInputs inputs = {}, SampledTexture m = {}, float a = 1.0f,
                         bool encode = false)
      : in(inputs), map(m), alpha(a), srgb(encode), packed(packed_texel()) {}
  bool packed_texel() const {
    return alpha == 1.0f && !srgb && map.sampler().filter != Filter::kTrilinear;
  }
  bool reads_derivatives() const { return map.sampler().filter == Filter::kTrilinear; }
  glm::vec4 vertex(uint32_t i, float* v) const {
    glm::vec2 uv = in.uv(i);
    v[0] = uv.x, v[1] = uv.y;
    return in.clip(i);
  }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& vs, simd::Float<N>* v) const {
    const simd::Vec2<N> uv = in.uv(vs);
    v[0] = uv.x, v[1] = uv.y;
    return in.clip(vs);
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    // Opaque, alpha 1, nothing encoded, no mip levels: the texel as it is, packed by the sampler
    // (sample_rgba8: the same bytes).
    if (f.opaque && packed) {
      f.set_rgba8(sample_rgba8<N>(map, f.vec2(0)));
      return;
    }
    simd::Vec4<N> t = sample_with_derivatives(map, f, 0);
    f.color = {t.x, t.y, t.z, t.w * alpha};
    if (srgb) f.color = encode_srgb<N>(f.color);
  }
};

// What phong reads of a material (renderer.cpp fills it from Material and RenderOptions).
struct SurfaceMaps {
  const Texture* diffuse = nullptr;     // albedo (and alpha) from here when set
  const Texture* specular = nullptr;    // rgb multiplies specular_color
  const Texture* normal = nullptr;      // the shading normal from here when set
  bool object_space = false;            // the normal map's space (else tangent space)
  float normal_scale = 1.0f;            // scales the map's x and y
  const Texture* alpha = nullptr;       // red multiplies the alpha
  glm::vec3 specular_color{kSpecular};  // Ks times the light intensity
  float shininess = kShininess;
  float opacity = 1.0f;
};

// What a Phong draw interpolates besides world position and normal: nothing (no maps), the
// texture coordinates (maps), those and the tangent frame (a tangent-space normal map), or the
// vertex colours as the albedo (no maps).
enum class PhongInputs { kPlain, kUv, kTangentFrame, kColors };

// Blinn-Phong per pixel with a material's maps: albedo from the diffuse map, specular colour
// times the specular map, the normal from a normal map (object space, or tangent space with
// the tangent frame interpolated: 4 more varyings), one directional or point light.
// Without maps and with SCENES.md's values it computes exactly what it always has. kPlain
// leaves out the texture coordinates that no map reads: two planes less to set up per triangle
// and to interpolate per block, the same image. World positions arrive times in.position_scale,
// and `eye` and `lighting.position` are given so scaled: the directions are the same, and eye - p
// and its squared length stay inside float's range in scenes of units of 1e30 or 1e-30.
template <PhongInputs kInputs>
struct PhongShader {
  static constexpr bool kUv = kInputs == PhongInputs::kUv || kInputs == PhongInputs::kTangentFrame;
  static constexpr bool kTangents = kInputs == PhongInputs::kTangentFrame;
  static constexpr bool kColors = kInputs == PhongInputs::kColors;
  // position, normal (uv, tangent; or colour)
  static constexpr int kVaryings = kTangents ? 12 : kUv ? 8 : kColors ? 9 : 6;
  MeshInputs in;
  glm::vec3 albedo;
  SurfaceMaps maps;
  Sampler sampler;
  Lighting lighting;
  glm::vec3 eye;
  float alpha = 1.0f;
  ColorSource colors;  // kColors: the vertex colours (decoded as textures are)
  // The maps bound to the sampler, worked out when the shader is made (for a draw, not changed
  // after), so that no block tests the texture and sampler again.
  SampledTexture diffuse_map, specular_map, normal_map, alpha_map;
  PhongShader(const MeshInputs& inputs, const glm::vec3& albedo_, const SurfaceMaps& maps_,
              const Sampler& sampler_, const Lighting& lighting_, const glm::vec3& eye_,
              float alpha_, const ColorSource& colors_)
      : in(inputs),
        albedo(albedo_),
        maps(maps_),
        sampler(sampler_),
        lighting(lighting_),
        eye(eye_),
        alpha(alpha_),
        colors(colors_),
        diffuse_map(bind_map(maps_.diffuse, sampler_)),
        specular_map(bind_map(maps_.specular, sampler_)),
        normal_map(bind_map(maps_.normal, sampler_)),
        alpha_map(bind_map(maps_.alpha, sampler_)) {}
  // Only the maps' trilinear lookups read derivatives (shadows and lighting do not).
  bool reads_derivatives() const { return kUv && sampler.filter == Filter::kTrilinear; }
  glm::vec4 vertex(uint32_t i, float* v) const {
    const glm::vec3 p = in.position(i);
    const glm::vec3& n = in.mesh->normals[i];
    v[0] = p.x, v[1] = p.y, v[2] = p.z, v[3] = n.x, v[4] = n.y, v[5] = n.z;
    if constexpr (kUv) {
      glm::vec2 uv = in.uv(i);
      v[6] = uv.x, v[7] = uv.y;
    }
    if constexpr (kTangents) {
      const glm::vec4& t = in.mesh->tangents[i];
      v[8] = t.x, v[9] = t.y, v[10] = t.z, v[11] = t.w;
    }
    if constexpr (kColors) {
      glm::vec3 c = colors.albedo(*in.mesh, i, albedo);
      v[6] = c.r, v[7] = c.g, v[8] = c.b;
    }
    return in.clip(i);
  }
  // vertex() on 16 vertices (copies and in.position's scale: the same bits); vertex colours
  // (decoded through std::pow) take vertex().
  bool wide_vertices() const { return !kColors; }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& vs, simd::Float<N>* v) const {
    // The positions read once, for the varyings and the clip position.
    const simd::Vec3<N> mesh_p = vs.vec3(in.mesh->positions.data());
    if constexpr (!kColors) {
      const simd::Vec3<N> p = in.position(mesh_p);
      const simd::Vec3<N> n = vs.vec3(in.mesh->normals.data());
      v[0] = p.x, v[1] = p.y, v[2] = p.z, v[3] = n.x, v[4] = n.y, v[5] = n.z;
      if constexpr (kUv) {
        const simd::Vec2<N> uv = in.uv(vs);
        v[6] = uv.x, v[7] = uv.y;
      }
      if constexpr (kTangents) {
        const simd::Vec4<N> t = vs.vec4(in.mesh->tangents.data());
        v[8] = t.x, v[9] = t.y, v[10] = t.z, v[11] = t.w;
      }
    }
    return in.clip(mesh_p);
  }
  // The unit shading normal: the interpolated one, or the normal map's; flipped on back faces
  // when lighting is two-sided.
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec3<N> normal(const Fragments<N>& f) const {
    using F = simd::Float<N>;
    simd::Vec3<N> n = simd::normalize_fast(f.vec3(3));
    if constexpr (kUv) {
      if (maps.normal) {
        simd::Vec3<N> m =
            map_normal<N>(sample_with_derivatives(normal_map, f, 6), maps.normal_scale);
        if (maps.object_space) {
          n = simd::normalize_fast(m);
        } else if constexpr (kTangents) {
          n = tangent_to_world<N>(m, n, f.vec3(8), f.varying(11));
        }
      }
    }
    if (lighting.two_sided && !f.front_facing) n = n * F(-1.0f);
    return n;
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    simd::Vec3<N> n = normal(f);
    simd::Vec3<N> p = f.vec3(0);
    simd::Vec3<N> view = simd::normalize_fast(simd::splat3<N>(eye) - p);
    simd::Vec3<N> l = lighting.point ? simd::normalize_fast(simd::splat3<N>(lighting.position) - p)
                                     : simd::splat3<N>(lighting.light);
    LightTerms<N> light = blinn_phong<N>(n, l, view, maps.shininess);
    simd::Vec4<N> base{F(albedo.r), F(albedo.g), F(albedo.b), F(1.0f)};
    if constexpr (kColors) base = {f.varying(6), f.varying(7), f.varying(8), F(1.0f)};
    simd::Vec3<N> ks = simd::splat3<N>(maps.specular_color);
    F a = F(alpha * maps.opacity);
    if constexpr (kUv) {
      if (maps.diffuse) base = sample_with_derivatives(diffuse_map, f, 6);
      if (maps.specular) {
        simd::Vec4<N> k = sample_with_derivatives(specular_map, f, 6);
        ks = ks * simd::Vec3<N>{k.x, k.y, k.z};
      }
      a = base.w * a;
      if (maps.alpha) a = a * sample_with_derivatives(alpha_map, f, 6).x;
    }
    // The shadow map is in world units: p without the position scale (exact: a power of two).
    F visible = lighting.shadow
                    ? shadow_visibility<N>(*lighting.shadow, p * F(1.0f / in.position_scale),
                                           simd::dot(n, l))
                    : F(1.0f);
    F lit = simd::fma(F(lighting.diffuse) * light.diffuse, visible, F(lighting.ambient));
    F spec = light.specular * visible;
    f.color = {simd::fma(base.x, lit, ks.x * spec), simd::fma(base.y, lit, ks.y * spec),
               simd::fma(base.z, lit, ks.z * spec), a};
    if (lighting.srgb_output) f.color = encode_srgb<N>(f.color);
  }
};

struct NormalsShader {
  static constexpr int kVaryings = 3;
  MeshInputs in;
  bool reads_derivatives() const { return false; }
  glm::vec4 vertex(uint32_t i, float* v) const {
    const glm::vec3& n = in.mesh->normals[i];
    v[0] = n.x, v[1] = n.y, v[2] = n.z;
    return in.clip(i);
  }
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& vs, simd::Float<N>* v) const {
    const simd::Vec3<N> n = vs.vec3(in.mesh->normals.data());
    v[0] = n.x, v[1] = n.y, v[2] = n.z;
    return in.clip(vs);
  }
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    simd::Vec3<N> n = simd::normalize_fast(f.vec3(0)) * simd::Float<N>(0.5f) + simd::Float<N>(0.5f);
    f.color = {n.x, n.y, n.z, simd::Float<N>(1.0f)};
  }
};

// Grey = 1 - (g(depth) - g(nearest)) / (g(farthest) - g(nearest)) of the view depth, with
// g = log when the range is positive (equal steps for equal distance ratios; a linear ramp of
// window depth would leave most scenes a uniform white) and g = depth otherwise (orthographic
// views that reach behind the eye): white at `nearest`, black at `farthest`. The renderer sets
// the two to the depth range visible in the image, so the whole ramp is used.
struct DepthShader {
  static constexpr int kVaryings = 1;
  MeshInputs in;
  glm::mat4 view{1.0f};
  bool logarithmic = true;
  float g_nearest = 0.0f;
  float g_scale = 1.0f;   // 1 / (g(farthest) - g(nearest))
  float floor = 1.0e-6f;  // the smallest depth put through the log

  DepthShader(const MeshInputs& inputs, const glm::mat4& view_matrix, float nearest, float farthest)
      : in(inputs), view(view_matrix), logarithmic(nearest > 0.0f) {
    if (logarithmic) floor = nearest * 0.5f;
    float g_far = g(farthest);
    g_nearest = g(nearest);
    g_scale = g_far > g_nearest ? 1.0f / (g_far - g_nearest) : 0.0f;
  }
  float g(float depth) const { return logarithmic ? std::log(std::max(depth, floor)) : depth; }
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = -(view * glm::vec4(in.mesh->positions[i], 1.0f)).z;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    float grey = 1.0f - (g(f.varyings[0]) - g_nearest) * g_scale;
    out = glm::vec4(glm::vec3(std::clamp(grey, 0.0f, 1.0f)), 1.0f);
    return true;
  }
};

}  // namespace softrast::detail
