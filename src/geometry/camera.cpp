// geometry/camera.cpp
#include "softrast/camera.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace softrast {
namespace {

bool finite3(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

glm::mat4 Camera::view() const {
  return glm::lookAtRH(eye, target, up);
}

glm::mat4 Camera::projection(float aspect) const {
  if (orthographic) {
    return glm::orthoRH_NO(ortho_left, ortho_right, ortho_bottom, ortho_top, near_plane, far_plane);
  }
  return glm::perspectiveRH_NO(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
}

Status Camera::validate() const {
  if (!finite3(eye) || !finite3(target) || !finite3(up) || !std::isfinite(fov_y_degrees) ||
      !std::isfinite(near_plane) || !std::isfinite(far_plane)) {
    return Status::error("camera: every number must be finite");
  }
  if (!(near_plane < far_plane)) return Status::error("camera: near must be less than far");
  glm::vec3 forward = target - eye;
  if (glm::length(forward) == 0.0f) return Status::error("camera: eye and target coincide");
  if (glm::length(glm::cross(forward, up)) <= 1e-6f * glm::length(forward) * glm::length(up)) {
    return Status::error("camera: up is parallel to the view direction (or zero)");
  }
  if (orthographic) {
    if (!(ortho_left != ortho_right && ortho_bottom != ortho_top) || !std::isfinite(ortho_left) ||
        !std::isfinite(ortho_right) || !std::isfinite(ortho_bottom) || !std::isfinite(ortho_top)) {
      return Status::error("camera: orthographic box is empty");
    }
    return Status();
  }
  if (!(near_plane > 0.0f)) return Status::error("camera: near must be > 0 for a perspective");
  if (!(fov_y_degrees > 0.0f && fov_y_degrees < 180.0f)) {
    return Status::error("camera: field of view must be in (0, 180) degrees");
  }
  return Status();
}

}  // namespace softrast
