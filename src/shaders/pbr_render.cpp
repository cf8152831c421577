// shaders/pbr_render.cpp: render_pbr, the draw order and render states of glTF's alpha modes and
// double-sided materials around the pbr shader.

#include "shaders/pbr_render.hpp"

#include "core/unit_scale.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/matrix.hpp>

#include "shaders/pbr_shader.hpp"

namespace softrast::detail {
namespace {

// The light every glTF scene gets (linear radiance and irradiance; tuned by eye so that a white
// diffuse surface facing the key light is just below the tone map's compression): a pale blue
// sky over a warm grey ground, and a slightly warm key light of irradiance 2.6.
constexpr glm::vec3 kSky{0.50f, 0.55f, 0.65f};
constexpr glm::vec3 kGround{0.18f, 0.16f, 0.14f};
constexpr glm::vec3 kKey{2.6f, 2.5f, 2.35f};

PbrMaterial fallback_material(const Mesh& mesh, int index, const RenderOptions& opt) {
  PbrMaterial p;
  p.base_color = glm::vec4(opt.color, 1.0f);
  p.metallic = 0.0f;
  p.roughness = 0.5f;
  p.double_sided = true;
  // The filter and wrap asked for (--filter, --wrap), as the other shaders use them; a glTF
  // material (below) has its file's samplers.
  p.base_color_map.sampler.filter = opt.sampler.filter;
  p.base_color_map.sampler.wrap_u = opt.sampler.wrap_u;
  p.base_color_map.sampler.wrap_v = opt.sampler.wrap_v;
  if (index >= 0 && size_t(index) < mesh.materials.size()) {
    const Material& m = mesh.materials[size_t(index)];
    if (m.pbr) return *m.pbr;
    p.base_color = glm::vec4(m.diffuse, 1.0f);
    p.base_color_map.texture = m.diffuse_map;
    // The material's placement of its maps (MTL -s, -o, -clamp) as a texture transform.
    if (m.uv_scale != glm::vec2(1.0f) || m.uv_offset != glm::vec2(0.0f)) {
      p.base_color_map.u_row = {m.uv_scale.x, 0.0f, m.uv_offset.x};
      p.base_color_map.v_row = {0.0f, m.uv_scale.y, m.uv_offset.y};
      p.base_color_map.transformed = true;
    }
    if (m.clamp_maps) {
      p.base_color_map.sampler.wrap_u = p.base_color_map.sampler.wrap_v = Wrap::kClampToEdge;
    }
  }
  return p;
}

struct BlendTriangle {
  float depth;     // view depth of the centroid: larger is farther
  uint32_t run;    // into the runs
  uint32_t first;  // into mesh.indices
};

}  // namespace

float shading_scale(const Camera& camera, const RenderOptions& opt) {
  float largest = std::max({std::abs(camera.eye.x), std::abs(camera.eye.y), std::abs(camera.eye.z),
                            std::abs(camera.far_plane)});
  if (opt.light_position) {
    const glm::vec3& l = *opt.light_position;
    largest = std::max({largest, std::abs(l.x), std::abs(l.y), std::abs(l.z)});
  }
  float nearest = std::abs(camera.near_plane);
  if (!std::isfinite(largest) || largest == 0.0f) return 1.0f;
  if (largest <= 0x1p32f && nearest >= 0x1p-32f) return 1.0f;
  return unit_scale(largest);
}

void render_pbr(Framebuffer& fb, const Mesh& mesh, const Camera& camera, const glm::mat4& mvp,
                std::span<const SubMesh> runs, const RenderState& state, const RenderOptions& opt) {
  std::vector<PbrMaterial> materials;
  materials.reserve(runs.size());
  for (const SubMesh& run : runs) {
    materials.push_back(fallback_material(mesh, run.material, opt));
    if (opt.texture) materials.back().base_color_map.texture = opt.texture;
  }
  PbrLight light;
  light.sky = kSky;
  light.ground = kGround;
  light.key_direction = glm::normalize(opt.light_direction);
  light.key = kKey * opt.light_intensity;
  light.exposure_scale = std::exp2(opt.exposure);
  glm::mat4 inverse_mvp = glm::inverse(mvp);
  // View rays in units scaled by shading_scale (rows x, y, z of the unprojection; w is the
  // divisor): the same directions.
  const float scale = shading_scale(camera, opt);
  for (int column = 0; column < 4; ++column) {
    for (int row = 0; row < 3; ++row) inverse_mvp[column][row] *= scale;
  }
  uint32_t vertex_count = uint32_t(mesh.positions.size());

  auto draw_indices = [&](size_t r, std::span<const uint32_t> indices, bool blended) {
    const PbrMaterial& mat = materials[r];
    RenderState s = state;
    s.cull = mat.double_sided ? CullMode::kNone : CullMode::kBack;
    if (blended) {
      s.blend = BlendMode::kAlpha;
      s.depth_write = false;
    }
    auto setup = [&](auto& shader) {
      shader.in = MeshInputs{&mesh, mvp};
      shader.material = &mat;
      shader.light = light;
      shader.inverse_mvp = inverse_mvp;
      shader.width = float(fb.width());
      shader.height = float(fb.height());
      shader.alpha = opt.alpha;
      shader.blend = blended;
    };
    if (mat.alpha_mode == AlphaMode::kMask) {
      PbrShader<true> shader;
      setup(shader);
      draw(fb, s, shader, indices, vertex_count);
    } else {
      PbrShader<false> shader;
      setup(shader);
      draw(fb, s, shader, indices, vertex_count);
    }
  };

  // Opaque and masked runs, in order.
  std::vector<BlendTriangle> blended;
  glm::mat4 view = camera.view();
  for (size_t r = 0; r < runs.size(); ++r) {
    const SubMesh& run = runs[r];
    if (materials[r].alpha_mode != AlphaMode::kBlend) {
      draw_indices(r, {mesh.indices.data() + run.first_index, run.index_count}, false);
      continue;
    }
    for (uint32_t t = 0; t + 2 < run.index_count; t += 3) {
      uint32_t first = run.first_index + t;
      glm::vec3 centroid(0.0f);
      for (int k = 0; k < 3; ++k) {
        uint32_t i = mesh.indices[first + uint32_t(k)];
        if (i < vertex_count) centroid += mesh.positions[i];
      }
      float depth = -(view * glm::vec4(centroid / 3.0f, 1.0f)).z;
      blended.push_back({std::isfinite(depth) ? depth : 0.0f, uint32_t(r), first});
    }
  }
  // Blended triangles, farthest first; consecutive triangles of one run drawn together.
  std::stable_sort(
      blended.begin(), blended.end(),
      [](const BlendTriangle& a, const BlendTriangle& b) { return a.depth > b.depth; });
  std::vector<uint32_t> batch;
  for (size_t i = 0; i < blended.size();) {
    uint32_t run = blended[i].run;
    batch.clear();
    for (; i < blended.size() && blended[i].run == run; ++i) {
      const uint32_t* tri = mesh.indices.data() + blended[i].first;
      batch.insert(batch.end(), tri, tri + 3);
    }
    draw_indices(run, batch, true);
  }
}

}  // namespace softrast::detail
