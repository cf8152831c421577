// apps/softrast/orbit.cpp: orbit, pan and zoom.

#include "orbit.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace softrast::cli {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kRadiansPerPixel = 0.01f;          // a 1280-pixel drag turns about two revolutions
constexpr float kMaxPitch = 89.0f * kPi / 180.0f;  // short of the pole, where up = +y breaks
constexpr float kZoomPerStep = 0.9f;               // one wheel notch: 10% closer
// Zoom limits as multiples of the bounding radius.
constexpr float kMinDistance = 1.0e-3f, kMaxDistance = 1.0e3f;

}  // namespace

Orbit::Orbit(const Camera& camera, const Bounds& bounds, bool fixed_depth)
    : base_(camera), bounds_(bounds), fixed_depth_(fixed_depth) {
  glm::vec3 offset = camera.eye - camera.target;
  state_.target = camera.target;
  state_.distance = std::max(float(glm::length(glm::dvec3(offset))), 1.0e-6f);  // no overflow
  state_.yaw = std::atan2(offset.x, offset.z);
  state_.pitch = std::clamp(std::asin(std::clamp(offset.y / state_.distance, -1.0f, 1.0f)),
                            -kMaxPitch, kMaxPitch);
  start_distance_ = state_.distance;
  initial_ = state_;
}

void Orbit::rotate(float dx_pixels, float dy_pixels) {
  state_.yaw -= dx_pixels * kRadiansPerPixel;
  state_.pitch = std::clamp(state_.pitch + dy_pixels * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

// The point under the cursor at the target's depth moves with the cursor.
void Orbit::pan(float dx_pixels, float dy_pixels, int height) {
  Camera c = camera();
  // In double: squares of coordinates past 1.8e19 overflow float.
  glm::vec3 forward = glm::vec3(glm::normalize(glm::dvec3(c.target) - glm::dvec3(c.eye)));
  glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  glm::vec3 up = glm::cross(right, forward);
  float view_height = c.orthographic
                          ? c.ortho_top - c.ortho_bottom
                          : 2.0f * state_.distance * std::tan(c.fov_y_degrees * kPi / 360.0f);
  float world_per_pixel = view_height / float(std::max(height, 1));
  state_.target += (-right * dx_pixels + up * dy_pixels) * world_per_pixel;
}

void Orbit::zoom(float wheel_steps) {
  float d = state_.distance * std::pow(kZoomPerStep, wheel_steps);
  state_.distance = std::clamp(d, kMinDistance * bounds_.radius, kMaxDistance * bounds_.radius);
}

Camera Orbit::camera() const {
  Camera c = base_;
  glm::vec3 direction(std::cos(state_.pitch) * std::sin(state_.yaw), std::sin(state_.pitch),
                      std::cos(state_.pitch) * std::cos(state_.yaw));
  c.target = state_.target;
  c.eye = state_.target + direction * state_.distance;
  c.up = {0.0f, 1.0f, 0.0f};
  if (fixed_depth_) {
    float scale = state_.distance / start_distance_;
    c.near_plane = base_.near_plane * scale;
    c.far_plane = base_.far_plane * scale;
  } else {
    CameraFlags given;
    given.eye = c.eye;
    given.target = c.target;
    given.up = c.up;
    given.fov = c.fov_y_degrees;
    Camera framed = frame_model(bounds_, given, 1.0f);  // eye and target given: only depth
    c.near_plane = framed.near_plane;
    c.far_plane = framed.far_plane;
  }
  return c;
}

}  // namespace softrast::cli
