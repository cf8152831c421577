// shaders/pbr_shader.hpp: glTF 2.0's metallic-roughness material as a wide fragment shader.
// Light: an analytic environment (a sky and a ground hemisphere of constant radiance) plus one
// directional key light. The key light is Cook-Torrance (GGX distribution, height-correlated Smith
// visibility, Schlick Fresnel) over Lambert; the environment's diffuse part is the hemisphere
// light's exact irradiance, its specular part the radiance around the reflected direction
// (blurred by roughness) times Karis' analytic fit of the split-sum BRDF integral. Then
// exposure, the Khronos PBR Neutral tone map and the sRGB encoding.
#pragma once

#include <cmath>

#include <glm/mat4x4.hpp>

#include "shaders/builtin_shaders.hpp"
#include "softrast/pbr_material.hpp"

namespace softrast::detail {

// ---- Colour maths, 16 lanes at a time ----------------------------------------------------

// fast_exp2, fast_pow and cross are shading_math.hpp's (through builtin_shaders.hpp).

// The sRGB transfer functions (IEC 61966-2-1) per channel. Decoding (textures) is a cubic fit,
// within 0.0017 of the exact curve (0.43 of an 8-bit step), cheap enough for every map sample;
// encoding (the output) is the exact formula.
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> srgb_to_linear(const simd::Float<N>& c) {
  using F = simd::Float<N>;
  return c * (c * (c * F(0.305306011f) + F(0.682171111f)) + F(0.012522878f));
}
template <int N>
SOFTRAST_SIMD_INLINE simd::Float<N> linear_to_srgb(const simd::Float<N>& c) {
  using F = simd::Float<N>;
  F x = simd::clamp(c, F(0.0f), F(1.0f));
  F curve = F(1.055f) * fast_pow<N>(x, 1.0f / 2.4f) - F(0.055f);
  return simd::select(x <= F(0.0031308f), x * F(12.92f), curve);
}

// Khronos PBR Neutral tone mapping (keeps base colours under a white light of intensity 1 as they
// are up to 0.76, then compresses highlights towards white, desaturating them slightly).
template <int N>
SOFTRAST_SIMD_INLINE simd::Vec3<N> tone_map_neutral(const simd::Vec3<N>& in) {
  using F = simd::Float<N>;
  const float kStart = 0.8f - 0.04f, kDesaturation = 0.15f;
  F lowest = simd::min(in.x, simd::min(in.y, in.z));
  F offset = simd::select(lowest < F(0.08f), lowest - F(6.25f) * lowest * lowest, F(0.04f));
  simd::Vec3<N> c{in.x - offset, in.y - offset, in.z - offset};
  F peak = simd::max(c.x, simd::max(c.y, c.z));
  const float d = 1.0f - kStart;
  F safe_peak = simd::max(peak, F(1.0e-6f));
  F new_peak = F(1.0f) - F(d * d) / (peak + F(d - kStart));
  F scale = new_peak / safe_peak;
  simd::Vec3<N> compressed = c * scale;
  F g = F(1.0f) - F(1.0f) / (F(kDesaturation) * (peak - new_peak) + F(1.0f));
  F keep = F(1.0f) - g;
  simd::Vec3<N> out{compressed.x * keep + new_peak * g, compressed.y * keep + new_peak * g,
                    compressed.z * keep + new_peak * g};
  simd::Int<N> low = peak < F(kStart);
  return {simd::select(low, c.x, out.x), simd::select(low, c.y, out.y),
          simd::select(low, c.z, out.z)};
}

template <int N>
SOFTRAST_SIMD_INLINE simd::Vec3<N> mix3(const simd::Vec3<N>& a, const simd::Vec3<N>& b,
                                        const simd::Float<N>& t) {
  simd::Float<N> s = simd::Float<N>(1.0f) - t;
  return {a.x * s + b.x * t, a.y * s + b.y * t, a.z * s + b.z * t};
}

// ---- The light ------------------------------------------------------------------------------

// Linear radiances and the key light's irradiance; the CLI's defaults are in pbr_render.cpp.
struct PbrLight {
  glm::vec3 sky{0.0f};                        // radiance of the upper hemisphere (world +y)
  glm::vec3 ground{0.0f};                     // radiance of the lower hemisphere
  glm::vec3 key_direction{0.0f, 0.0f, 1.0f};  // towards the key light, normalised
  glm::vec3 key{0.0f};                        // its irradiance on a surface facing it
  float exposure_scale = 1.0f;                // 2^exposure
};

// ---- The shader -----------------------------------------------------------------------------

// kMask: alpha below the material's cutoff discards (glTF MASK); otherwise alpha is 1 (OPAQUE) or
// the material's (BLEND, drawn with alpha blending by the caller).
template <bool kMask>
struct PbrShader {
  static constexpr bool kDiscards = kMask;
  // Varyings: normal 0-2, tangent 3-6, uv0 7-8, uv1 9-10, vertex colour 11-14. The view direction
  // is rebuilt from the pixel's position (inverse view-projection), which keeps this under 16.
  static constexpr int kVaryings = 15;
  MeshInputs in;
  const PbrMaterial* material = nullptr;
  PbrLight light;
  glm::mat4 inverse_mvp{1.0f};  // window -> world, with the viewport below
  float width = 1.0f, height = 1.0f;
  float alpha = 1.0f;  // RenderOptions::alpha, times the material's in BLEND mode
  bool blend = false;

  // Only trilinear lookups read derivatives: the five maps are the only textures sampled.
  bool reads_derivatives() const {
    const PbrMaterial& m = *material;
    for (const TextureSlot* slot : {&m.base_color_map, &m.metallic_roughness_map, &m.normal_map,
                                    &m.occlusion_map, &m.emissive_map}) {
      if (*slot && slot->sampler.filter == Filter::kTrilinear) return true;
    }
    return false;
  }

  glm::vec4 vertex(uint32_t i, float* v) const {
    const Mesh& m = *in.mesh;
    const glm::vec3& n = m.normals[i];
    glm::vec4 t = m.tangents.empty() ? glm::vec4(1.0f, 0.0f, 0.0f, 1.0f) : m.tangents[i];
    const glm::vec2& uv = m.uvs[i];
    glm::vec2 uv1 = m.uvs1.empty() ? uv : m.uvs1[i];
    glm::vec4 c = m.colors.empty() ? glm::vec4(1.0f) : m.colors[i];
    const float values[kVaryings] = {n.x,  n.y,   n.z,   t.x, t.y, t.z, t.w, uv.x,
                                     uv.y, uv1.x, uv1.y, c.r, c.g, c.b, c.a};
    for (int k = 0; k < kVaryings; ++k) v[k] = values[k];
    return in.clip(i);
  }

  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec2<N> slot_uv(const TextureSlot& slot, const Fragments<N>& f) const {
    simd::Vec2<N> uv = f.vec2(slot.uv_set == 1 ? 9 : 7);
    if (!slot.transformed) return uv;
    using F = simd::Float<N>;
    return {F(slot.u_row.x) * uv.x + F(slot.u_row.y) * uv.y + F(slot.u_row.z),
            F(slot.v_row.x) * uv.x + F(slot.v_row.y) * uv.y + F(slot.v_row.z)};
  }

  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> sample_slot(const TextureSlot& slot,
                                                 const Fragments<N>& f) const {
    simd::Vec2<N> uv = slot_uv(slot, f);
    if (slot.sampler.filter != Filter::kTrilinear)
      return sample<N>(*slot.texture, slot.sampler, uv);
    return sample<N>(*slot.texture, slot.sampler, uv, {f.ddx(uv.x), f.ddx(uv.y)},
                     {f.ddy(uv.x), f.ddy(uv.y)});
  }

  // The world position where the pixel's ray meets window depth ndc_z (-1 near, +1 far).
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec3<N> unproject(const simd::Float<N>& nx, const simd::Float<N>& ny,
                                               float z) const {
    using F = simd::Float<N>;
    const glm::mat4& m = inverse_mvp;
    F inv = F(1.0f) / (F(m[0][3]) * nx + F(m[1][3]) * ny + F(m[2][3] * z + m[3][3]));
    return {(F(m[0][0]) * nx + F(m[1][0]) * ny + F(m[2][0] * z + m[3][0])) * inv,
            (F(m[0][1]) * nx + F(m[1][1]) * ny + F(m[2][1] * z + m[3][1])) * inv,
            (F(m[0][2]) * nx + F(m[1][2]) * ny + F(m[2][2] * z + m[3][2])) * inv};
  }

  // The direction from the surface towards the eye, per pixel: from the points where the pixel's
  // ray meets the far and the near plane (right for perspective and orthographic cameras).
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec3<N> view_direction(const Fragments<N>& f) const {
    using F = simd::Float<N>;
    F nx = f.x * F(2.0f / width) - F(1.0f);
    F ny = F(1.0f) - f.y * F(2.0f / height);
    return simd::normalize_fast(unproject<N>(nx, ny, -1.0f) - unproject<N>(nx, ny, 1.0f));
  }

  // The shading normal: the interpolated normal, perturbed by the normal map in the tangent frame
  // (Gram-Schmidt against the normal, bitangent = w * cross(n, t)), flipped on back faces.
  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec3<N> shading_normal(const Fragments<N>& f) const {
    using F = simd::Float<N>;
    simd::Vec3<N> n = simd::normalize_fast(f.vec3(0));
    if (material->normal_map) {
      simd::Vec4<N> t4 = f.vec4(3);
      simd::Vec3<N> t{t4.x, t4.y, t4.z};
      t = simd::normalize_fast(t - n * simd::dot(n, t));
      F sign = simd::select(t4.w < F(0.0f), F(-1.0f), F(1.0f));
      simd::Vec3<N> b = cross<N>(n, t) * sign;
      simd::Vec4<N> texel = sample_slot(material->normal_map, f);
      F scale(material->normal_scale);
      F tx = (texel.x * F(2.0f) - F(1.0f)) * scale, ty = (texel.y * F(2.0f) - F(1.0f)) * scale;
      F tz = texel.z * F(2.0f) - F(1.0f);
      simd::Vec3<N> perturbed = t * tx + b * ty + n * tz;
      // A degenerate frame (zero tangent from the interpolation, NaN) keeps the plain normal.
      F len2 = simd::dot(perturbed, perturbed);
      simd::Int<N> ok = len2 > F(1.0e-12f);
      simd::Vec3<N> p = perturbed * (F(1.0f) / simd::sqrt(simd::select(ok, len2, F(1.0f))));
      n = {simd::select(ok, p.x, n.x), simd::select(ok, p.y, n.y), simd::select(ok, p.z, n.z)};
    }
    if (!f.front_facing) n = n * F(-1.0f);
    return n;
  }

  template <int N>
  SOFTRAST_SIMD_INLINE simd::Vec4<N> base_color(const Fragments<N>& f) const {
    using F = simd::Float<N>;
    const glm::vec4& k = material->base_color;
    simd::Vec4<N> c = f.vec4(11);  // the vertex colour
    c = {c.x * F(k.r), c.y * F(k.g), c.z * F(k.b), c.w * F(k.a)};
    if (material->base_color_map) {
      simd::Vec4<N> t = sample_slot(material->base_color_map, f);
      c = {c.x * srgb_to_linear<N>(t.x), c.y * srgb_to_linear<N>(t.y), c.z * srgb_to_linear<N>(t.z),
           c.w * t.w};
    }
    return c;
  }

  template <int N>
  SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const {
    using F = simd::Float<N>;
    using V3 = simd::Vec3<N>;
    const PbrMaterial& mat = *material;
    simd::Vec4<N> base = base_color(f);
    F opacity = F(alpha);
    if constexpr (kMask) {
      f.discard(base.w < F(mat.alpha_cutoff));
    } else if (blend) {
      opacity = simd::clamp(base.w, F(0.0f), F(1.0f)) * F(alpha);
    }
    F metallic(mat.metallic), roughness(mat.roughness);
    if (mat.metallic_roughness_map) {
      simd::Vec4<N> t = sample_slot(mat.metallic_roughness_map, f);
      metallic = metallic * t.z;
      roughness = roughness * t.y;
    }
    metallic = simd::clamp(metallic, F(0.0f), F(1.0f));
    roughness = simd::clamp(roughness, F(0.03f), F(1.0f));  // no infinitely sharp highlight
    F a = roughness * roughness, a2 = a * a;
    V3 albedo{base.x, base.y, base.z};
    V3 diffuse_color = albedo * (F(1.0f) - metallic);
    V3 f0 = mix3<N>(V3{F(0.04f), F(0.04f), F(0.04f)}, albedo, metallic);

    V3 n = shading_normal(f);
    V3 v = view_direction(f);
    F n_v = simd::max(simd::dot(n, v), F(1.0e-4f));

    // Key light: Cook-Torrance over Lambert.
    V3 l = simd::splat3<N>(light.key_direction);
    V3 h = simd::normalize_fast(l + v);
    F n_l = simd::max(simd::dot(n, l), F(0.0f));
    F n_h = simd::max(simd::dot(n, h), F(0.0f));
    F v_h = simd::max(simd::dot(v, h), F(0.0f));
    F d_denominator = n_h * n_h * (a2 - F(1.0f)) + F(1.0f);
    F d = a2 / (F(3.14159265f) * d_denominator * d_denominator);
    F vis = F(0.5f) / (n_l * simd::sqrt(n_v * n_v * (F(1.0f) - a2) + a2) +
                       n_v * simd::sqrt(n_l * n_l * (F(1.0f) - a2) + a2) + F(1.0e-7f));
    F m = F(1.0f) - v_h;
    F m5 = m * m * m * m * m;
    V3 fresnel = f0 + (V3{F(1.0f), F(1.0f), F(1.0f)} - f0) * m5;
    V3 one_minus_f = V3{F(1.0f), F(1.0f), F(1.0f)} - fresnel;
    V3 key_brdf = one_minus_f * diffuse_color * F(1.0f / 3.14159265f) + fresnel * (d * vis);
    V3 color = key_brdf * simd::splat3<N>(light.key) * n_l;

    // Environment: the hemisphere light's irradiance for the diffuse part; for the specular part
    // the sky or ground around the reflected direction, the horizon blurred by roughness.
    V3 sky = simd::splat3<N>(light.sky), ground = simd::splat3<N>(light.ground);
    V3 env_diffuse = mix3<N>(ground, sky, F(0.5f) + F(0.5f) * n.y);
    F r_y = F(2.0f) * n_v * n.y - v.y;  // reflect(-v, n).y
    F width = simd::max(a, F(0.02f));
    V3 env_specular =
        mix3<N>(ground, sky, simd::clamp(F(0.5f) + r_y / (F(2.0f) * width), F(0.0f), F(1.0f)));
    // Karis' fit of the split-sum integral: F0 * scale + bias.
    F rx = roughness * F(-1.0f) + F(1.0f), ry = roughness * F(-0.0275f) + F(0.0425f);
    F rz = roughness * F(-0.572f) + F(1.04f), rw = roughness * F(0.022f) + F(-0.04f);
    F a004 = simd::min(rx * rx, fast_exp2<N>(F(-9.28f) * n_v)) * rx + ry;
    F env_scale = a004 * F(-1.04f) + rz, env_bias = a004 * F(1.04f) + rw;
    V3 env = env_diffuse * diffuse_color + env_specular * (f0 * env_scale + env_bias);
    F occlusion(1.0f);
    if (mat.occlusion_map) {
      F ao = sample_slot(mat.occlusion_map, f).x;
      occlusion = F(1.0f) + F(mat.occlusion_strength) * (ao - F(1.0f));
    }
    color = color + env * occlusion;

    V3 emissive = simd::splat3<N>(mat.emissive);
    if (mat.emissive_map) {
      simd::Vec4<N> t = sample_slot(mat.emissive_map, f);
      emissive =
          emissive * V3{srgb_to_linear<N>(t.x), srgb_to_linear<N>(t.y), srgb_to_linear<N>(t.z)};
    }
    color = (color + emissive) * F(light.exposure_scale);
    V3 mapped = tone_map_neutral<N>(color);
    f.color = {linear_to_srgb<N>(mapped.x), linear_to_srgb<N>(mapped.y),
               linear_to_srgb<N>(mapped.z), opacity};
  }
};

}  // namespace softrast::detail
