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

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c) {
    if (!finite3(glm::vec3(m[c])) || !std::isfinite(m[c].w)) return false;
  }
  return true;
}

// Within float's comfortable range: squares and products of such numbers neither overflow nor
// lose bits to underflow.
bool moderate(double square) {
  return square >= 1.0e-30 && square <= 1.0e30;
}

}  // namespace

// lookAt normalises by lengths that square the coordinates: in float they overflow past about
// 1.8e19 (a model in units of 1e30 would get a zero view direction) and underflow near 1e-19.
// There the matrix is computed in double and rounded once; elsewhere in float, as glm computes it.
glm::mat4 Camera::view() const {
  glm::dvec3 forward = glm::dvec3(target) - glm::dvec3(eye);
  glm::mat4 m = glm::lookAtRH(eye, target, up);
  if (moderate(glm::dot(forward, forward)) && finite(m)) return m;
  return glm::mat4(glm::lookAtRH(glm::dvec3(eye), glm::dvec3(target), glm::dvec3(up)));
}

// The same for 2 far near / (near - far), which overflows float for planes past about 1.3e19.
glm::mat4 Camera::projection(float aspect) const {
  const double n = near_plane, f = far_plane;
  if (orthographic) {
    glm::mat4 m =
        glm::orthoRH_NO(ortho_left, ortho_right, ortho_bottom, ortho_top, near_plane, far_plane);
    if (finite(m)) return m;
    return glm::mat4(glm::orthoRH_NO(double(ortho_left), double(ortho_right), double(ortho_bottom),
                                     double(ortho_top), n, f));
  }
  glm::mat4 m = glm::perspectiveRH_NO(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
  if (moderate(n * f) && finite(m)) return m;
  return glm::mat4(
      glm::perspectiveRH_NO(glm::radians(double(fov_y_degrees)), double(aspect), n, f));
}

Status Camera::validate() const {
  if (!finite3(eye) || !finite3(target) || !finite3(up) || !std::isfinite(fov_y_degrees) ||
      !std::isfinite(near_plane) || !std::isfinite(far_plane)) {
    return Status::error("camera: every number must be finite");
  }
  // In double, as view(): squared lengths of float coordinates cannot overflow it.
  glm::dvec3 forward = glm::dvec3(target) - glm::dvec3(eye);
  if (glm::length(forward) == 0.0) return Status::error("camera: eye and target coincide");
  if (!(near_plane < far_plane)) return Status::error("camera: near must be less than far");
  if (glm::length(glm::cross(forward, glm::dvec3(up))) <=
      1e-6 * glm::length(forward) * glm::length(glm::dvec3(up))) {
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
