// apps/softrast/framing.cpp: automatic camera placement for a model.

#include "framing.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace softrast::cli {
namespace {

constexpr float kPi = 3.14159265358979f;
// Slack around the bounding sphere so that no vertex lands exactly on the near or far plane.
constexpr float kDepthMargin = 1.01f;
// The smallest near / far ratio chosen automatically: keeps float depth well resolved.
constexpr float kMinNearRatio = 1.0e-3f;

// Distance from the centre at which a sphere of `radius` fits the narrower of the two
// fields of view. Any distance suits an orthographic camera; twice the radius keeps it outside.
float fit_distance(float radius, const Camera& camera, float aspect) {
  if (camera.orthographic) return 2.0f * radius;
  float half_y = camera.fov_y_degrees * kPi / 360.0f;
  float half_x = std::atan(std::tan(half_y) * aspect);
  return radius / std::sin(std::min(half_y, half_x));
}

// Near and far planes that enclose the bounding sphere seen from `eye`.
std::pair<float, float> depth_range(const Bounds& bounds, glm::vec3 eye) {
  float distance = glm::length(eye - bounds.center);
  float far_plane = distance + kDepthMargin * bounds.radius;
  float near_plane = std::max(distance - kDepthMargin * bounds.radius, far_plane * kMinNearRatio);
  return {near_plane, far_plane};
}

// Near and far from the flags where given; an automatic value that contradicts a given one
// gives way to it.
void set_depth_range(Camera& camera, const Bounds& bounds, const CameraFlags& flags) {
  auto [near_plane, far_plane] = depth_range(bounds, camera.eye);
  if (flags.far_plane && !flags.near_plane && near_plane >= *flags.far_plane) {
    near_plane = *flags.far_plane * kMinNearRatio;
  }
  if (flags.near_plane && !flags.far_plane && far_plane <= *flags.near_plane) {
    far_plane = *flags.near_plane / kMinNearRatio;
  }
  camera.near_plane = flags.near_plane.value_or(near_plane);
  camera.far_plane = flags.far_plane.value_or(far_plane);
}

}  // namespace

Bounds bounds_of(const Mesh& mesh) {
  if (mesh.positions.empty()) return {};
  glm::vec3 lo = mesh.positions.front(), hi = lo;
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  glm::vec3 size = hi - lo;
  Bounds bounds{(lo + hi) * 0.5f, glm::length(size) * 0.5f};
  bounds.flat_in_y = size.y < 0.1f * std::min(size.x, size.z);
  if (!(bounds.radius > 0.0f && std::isfinite(bounds.radius))) bounds.radius = 1.0f;
  return bounds;
}

Camera frame_model(const Bounds& bounds, const CameraFlags& flags, float aspect) {
  Camera camera;
  apply_flags(camera, flags);
  camera.target = flags.target.value_or(bounds.center);
  float distance = fit_distance(bounds.radius, camera, aspect);
  // Look along -z; a model flat in y (a floor, a terrain) is seen from 45 degrees above instead
  // of edge-on.
  glm::vec3 direction =
      bounds.flat_in_y ? glm::normalize(glm::vec3(0.0f, 1.0f, 1.0f)) : glm::vec3(0.0f, 0.0f, 1.0f);
  camera.eye = flags.eye.value_or(camera.target + direction * distance);
  set_depth_range(camera, bounds, flags);
  return camera;
}

void apply_flags(Camera& camera, const CameraFlags& flags) {
  if (flags.eye) camera.eye = *flags.eye;
  if (flags.target) camera.target = *flags.target;
  if (flags.up) camera.up = *flags.up;
  if (flags.fov) camera.fov_y_degrees = *flags.fov;
  if (flags.near_plane) camera.near_plane = *flags.near_plane;
  if (flags.far_plane) camera.far_plane = *flags.far_plane;
  if (flags.ortho) {
    camera.orthographic = true;
    camera.ortho_left = flags.ortho->x;
    camera.ortho_right = flags.ortho->y;
    camera.ortho_bottom = flags.ortho->z;
    camera.ortho_top = flags.ortho->w;
  }
}

}  // namespace softrast::cli
