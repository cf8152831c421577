// softrast/camera.hpp: view and projection, with OpenGL's conventions (gluLookAt,
// gluPerspective, glOrtho): right-handed, camera looking down -z, clip z in [-w, w].
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "softrast/status.hpp"

namespace softrast {

struct Camera {
  glm::vec3 eye{0.0f, 0.0f, 3.0f};
  glm::vec3 target{0.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y_degrees = 45.0f;  // vertical field of view (perspective)
  float near_plane = 0.1f;
  float far_plane = 100.0f;
  bool orthographic = false;  // use the box below instead of the field of view
  float ortho_left = -1.0f, ortho_right = 1.0f, ortho_bottom = -1.0f, ortho_top = 1.0f;

  // gluLookAt(eye, target, up).
  glm::mat4 view() const;
  // gluPerspective(fov_y, aspect, near, far), or glOrtho(l, r, b, t, near, far).
  glm::mat4 projection(float aspect) const;
  glm::mat4 view_projection(float aspect) const { return projection(aspect) * view(); }
  // An error naming the problem for unusable settings: near >= far, near <= 0 with a perspective
  // projection, fov outside (0, 180), eye == target, up parallel to the view direction, an empty
  // orthographic box, or any non-finite number.
  Status validate() const;
};

}  // namespace softrast
