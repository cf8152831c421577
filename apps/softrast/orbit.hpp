// apps/softrast/orbit.hpp: the viewer's camera: orbit around a target point (yaw and pitch about
// the world's y axis, up fixed to +y), pan the target in the view plane, zoom by distance. Near
// and far follow the distance so the scene's bounding sphere stays between them.
#pragma once

#include <glm/vec3.hpp>

#include "framing.hpp"
#include "softrast/camera.hpp"

namespace softrast::cli {

class Orbit {
 public:
  // Starts at `camera` (eye, target and fov kept; up becomes +y). `bounds` sets the depth range
  // and how far zoom goes; with `fixed_depth` near and far keep the camera's own ratio to the
  // distance instead (the demo scene, whose floor reaches far beyond what it is looked at for).
  Orbit(const Camera& camera, const Bounds& bounds, bool fixed_depth);

  // Mouse motions in pixels, in a window `height` pixels high.
  void rotate(float dx_pixels, float dy_pixels);
  void pan(float dx_pixels, float dy_pixels, int height);
  void zoom(float wheel_steps);  // > 0: closer
  void reset() { state_ = initial_; }

  Camera camera() const;

 private:
  struct State {
    glm::vec3 target{0.0f};
    float distance = 1.0f;
    float yaw = 0.0f;    // radians about +y; 0 puts the eye on +z of the target
    float pitch = 0.0f;  // radians of the eye above the target's horizon, within +-89 degrees
  };

  Camera base_;  // fov, projection, and the near/far of the start
  Bounds bounds_;
  bool fixed_depth_;
  float start_distance_;
  State state_;
  State initial_;
};

}  // namespace softrast::cli
