// shaders/builtin_shaders.hpp: the built-in shaders as types for softrast::draw. Each pulls its
// vertex inputs from a Mesh by index. Formulas and constants are those of SCENES.md.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

#include "softrast/mesh.hpp"
#include "softrast/shader.hpp"
#include "softrast/texture.hpp"

namespace softrast::detail {

inline constexpr float kAmbient = 0.15f;
inline constexpr float kDiffuse = 0.85f;
inline constexpr float kSpecular = 0.4f;
inline constexpr float kShininess = 32.0f;

// Inputs shared by the built-in shaders.
struct MeshInputs {
  const Mesh* mesh = nullptr;
  glm::mat4 mvp{1.0f};
  glm::vec4 clip(uint32_t i) const { return mvp * glm::vec4(mesh->positions[i], 1.0f); }
};

struct FlatShader {
  static constexpr int kVaryings = 0;
  MeshInputs in;
  glm::vec4 color;
  glm::vec4 vertex(uint32_t i, float*) const { return in.clip(i); }
  bool fragment(FragmentInput&, glm::vec4& out) const {
    out = color;
    return true;
  }
};

struct GouraudShader {
  static constexpr int kVaryings = 3;
  MeshInputs in;
  glm::vec3 albedo;
  glm::vec3 light;  // normalised
  float alpha = 1.0f;
  glm::vec4 vertex(uint32_t i, float* v) const {
    float d = std::max(glm::dot(glm::normalize(in.mesh->normals[i]), light), 0.0f);
    glm::vec3 c = albedo * (kAmbient + kDiffuse * d);
    v[0] = c.r, v[1] = c.g, v[2] = c.b;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    out = glm::vec4(f.vec3(0), alpha);
    return true;
  }
};

struct TextureShader {
  static constexpr int kVaryings = 2;
  MeshInputs in;
  const Texture* texture;
  Sampler sampler;
  float alpha = 1.0f;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = in.mesh->uvs[i].x, v[1] = in.mesh->uvs[i].y;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    glm::vec4 t = texture->sample(sampler, f.vec2(0));
    out = glm::vec4(glm::vec3(t), t.a * alpha);
    return true;
  }
};

struct PhongShader {
  static constexpr int kVaryings = 8;  // world position, normal, uv
  MeshInputs in;
  glm::vec3 albedo;
  const Texture* texture = nullptr;  // albedo from here when set
  Sampler sampler;
  glm::vec3 light;
  glm::vec3 eye;
  float alpha = 1.0f;
  glm::vec4 vertex(uint32_t i, float* v) const {
    const glm::vec3& p = in.mesh->positions[i];
    const glm::vec3& n = in.mesh->normals[i];
    const glm::vec2& uv = in.mesh->uvs[i];
    v[0] = p.x, v[1] = p.y, v[2] = p.z, v[3] = n.x, v[4] = n.y, v[5] = n.z, v[6] = uv.x,
    v[7] = uv.y;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    glm::vec3 n = glm::normalize(f.vec3(3));
    glm::vec3 view = glm::normalize(eye - f.vec3(0));
    glm::vec3 h = glm::normalize(light + view);
    float d = std::max(glm::dot(n, light), 0.0f);
    float s = d > 0.0f ? std::pow(std::max(glm::dot(n, h), 0.0f), kShininess) : 0.0f;
    glm::vec4 base(albedo, 1.0f);
    if (texture) base = texture->sample(sampler, f.vec2(6));
    out = glm::vec4(glm::vec3(base) * (kAmbient + kDiffuse * d) + kSpecular * s, base.a * alpha);
    return true;
  }
};

struct NormalsShader {
  static constexpr int kVaryings = 3;
  MeshInputs in;
  glm::vec4 vertex(uint32_t i, float* v) const {
    const glm::vec3& n = in.mesh->normals[i];
    v[0] = n.x, v[1] = n.y, v[2] = n.z;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    out = glm::vec4(glm::normalize(f.vec3(0)) * 0.5f + 0.5f, 1.0f);
    return true;
  }
};

// Grey = 1 - log(depth / near) / log(far / near) of the view depth: white at the near plane,
// black at the far plane, equal steps for equal distance ratios (a linear ramp would leave most
// scenes a uniform white, as window depth does).
struct DepthShader {
  static constexpr int kVaryings = 1;
  MeshInputs in;
  glm::mat4 view{1.0f};
  float near_plane = 0.1f;
  float log_range = 1.0f;  // log(far / near)
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = -(view * glm::vec4(in.mesh->positions[i], 1.0f)).z;
    return in.clip(i);
  }
  bool fragment(FragmentInput& f, glm::vec4& out) const {
    float g = 1.0f - std::log(std::max(f.varyings[0], near_plane) / near_plane) / log_range;
    out = glm::vec4(glm::vec3(std::clamp(g, 0.0f, 1.0f)), 1.0f);
    return true;
  }
};

}  // namespace softrast::detail
