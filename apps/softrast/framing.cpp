// apps/softrast/framing.cpp: automatic camera placement for a model.
//
// Fitting a perspective camera to the vertices. In the camera's frame (r right, u up, d from the
// model towards the viewer) vertex i is at (x_i, y_i, z_i) and a camera at (c_x, c_y, c_z)
// sees it at the slope (x_i - c_x) / (c_z - z_i) horizontally. The vertex lies inside a view of
// half-slope k (k = tan(half field of view) * fill) when
//     x_i + k z_i <= c_x + k c_z   and   -x_i + k z_i <= -c_x + k c_z.
// With A = max(x_i + k z_i) and B = max(-x_i + k z_i), the closest camera that keeps every vertex
// inside has both constraints tight: c_z = (A + B) / 2k, c_x = (A - B) / 2. The same for y; the
// larger of the two c_z is the axis that limits, and there the extreme vertices touch the frame
// of `fill`. Triangles project inside the hull of their projected corners, so the image of the
// model has exactly the extent of its vertices'.

#include "framing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace softrast::cli {
namespace {

constexpr float kPi = 3.14159265358979f;
// Slack around the model's depth so that no vertex lands exactly on the near or far plane.
constexpr float kDepthMargin = 0.01f;
// The smallest near / far ratio chosen automatically: keeps float depth well resolved.
constexpr float kMinNearRatio = 1.0e-3f;
// Flat along the up axis: its extent under a tenth of the other two (a floor, a terrain).
constexpr float kFlatRatio = 0.1f;
// The iso view: the direction (1, 1, 1) of the model's frame.
constexpr float kIsoElevation = 35.2643897f;  // atan(1 / sqrt(2)) in degrees

struct NamedView {
  std::string_view name;
  Orientation orientation;
};
constexpr std::array<NamedView, 7> kViews = {{
    {"front", {0.0f, 0.0f}},
    {"back", {180.0f, 0.0f}},
    {"left", {-90.0f, 0.0f}},
    {"right", {90.0f, 0.0f}},
    {"top", {0.0f, 90.0f}},
    {"bottom", {0.0f, -90.0f}},
    {"iso", {45.0f, kIsoElevation}},
}};

float radians(float degrees) {
  return degrees * kPi / 180.0f;
}

// The model's frame: `up` as given, `front` the side a front view looks from (+z for a Y-up
// model, -y for a Z-up one, as modelling tools show them), `right` completing it.
struct ModelFrame {
  glm::vec3 up, front, right;
};
ModelFrame model_frame(glm::vec3 up) {
  glm::vec3 front(0.0f, 0.0f, 1.0f);
  if (std::abs(up.z) > 0.5f) front = glm::vec3(0.0f, -up.z, 0.0f);
  return {up, front, glm::cross(up, front)};
}

// The camera's frame: `back` from the target towards the eye, `up` the image's up direction.
struct ViewFrame {
  glm::vec3 right, up, back;
};
ViewFrame view_frame(const ModelFrame& m, Orientation o) {
  float az = radians(o.azimuth), el = radians(o.elevation);
  glm::vec3 horizontal = std::cos(az) * m.front + std::sin(az) * m.right;
  glm::vec3 back = glm::normalize(std::cos(el) * horizontal + std::sin(el) * m.up);
  // The derivative of `back` by elevation: perpendicular to it and well defined even straight
  // above (top view: the model's front at the bottom of the image).
  glm::vec3 up = glm::normalize(-std::sin(el) * horizontal + std::cos(el) * m.up);
  return {glm::cross(up, back), up, back};
}

// The image's up direction for a camera whose --up was not given: `preferred` (the view's), unless
// the camera looks along it (an --eye straight above or below the --target), where it names no
// direction in the image; then the model's front, as the top and bottom views take it: from
// above the front is at the image's bottom, from below at its top. The parallel test is
// Camera::validate's, which would refuse `preferred` there.
glm::vec3 default_up(const Camera& camera, glm::vec3 preferred, const ModelFrame& m) {
  glm::dvec3 back = glm::dvec3(camera.eye) - glm::dvec3(camera.target);
  glm::dvec3 up(preferred);
  if (glm::length(glm::cross(back, up)) > 1e-6 * glm::length(back) * glm::length(up)) {
    return preferred;
  }
  return glm::dot(back, glm::dvec3(m.up)) > 0.0 ? -m.front : m.front;
}

bool flat_along(const Mesh& mesh, glm::vec3 axis) {
  glm::vec3 lo = mesh.positions.front(), hi = lo;
  for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  glm::vec3 size = hi - lo;
  int a = std::abs(axis.x) > 0.5f ? 0 : std::abs(axis.y) > 0.5f ? 1 : 2;
  return size[a] < kFlatRatio * std::min(size[(a + 1) % 3], size[(a + 2) % 3]);
}

// The orientation to frame from: the flags' angles, else the front; from 45 degrees above for a
// model flat along its up axis, and from the right for one flat along its right axis (a sign, a
// polygon standing across the view): either would be seen edge-on from the front, as a line.
Orientation orientation_for(const Mesh& mesh, const CameraFlags& flags) {
  Orientation o;
  if (!flags.azimuth && !flags.elevation) {
    const ModelFrame m = model_frame(flags.up_axis);
    if (flat_along(mesh, m.up)) {
      o.elevation = 45.0f;
    } else if (flat_along(mesh, m.right)) {
      o.azimuth = 90.0f;
    }
  }
  if (flags.azimuth) o.azimuth = *flags.azimuth;
  if (flags.elevation) o.elevation = *flags.elevation;
  return o;
}

glm::vec3 center_of(const Mesh& mesh) {
  glm::vec3 lo = mesh.positions.front(), hi = lo;
  for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return (lo + hi) * 0.5f;
}

float radius_of(const Mesh& mesh, glm::vec3 center) {
  double r2 = 0.0;  // in double: squares of coordinates past 1.8e19 overflow float
  for (const glm::vec3& p : mesh.positions) {
    glm::dvec3 d = glm::dvec3(p) - glm::dvec3(center);
    r2 = std::max(r2, glm::dot(d, d));
  }
  float r = float(std::sqrt(r2));
  return r > 0.0f && std::isfinite(r) ? r : 1.0f;
}

// The camera position along one image axis (`axis`, with half-slope k) and its distance c_z, as
// the header derives; both constraints tight.
std::pair<float, float> fit_axis(const Mesh& mesh, glm::vec3 axis, glm::vec3 back, float k) {
  float a = -std::numeric_limits<float>::max(), b = a;
  for (const glm::vec3& p : mesh.positions) {
    float x = glm::dot(p, axis), z = glm::dot(p, back);
    a = std::max(a, x + k * z);
    b = std::max(b, -x + k * z);
  }
  return {(a - b) * 0.5f, (a + b) / (2.0f * k)};
}

// For the axis that does not limit: the camera position that centres the model's projected
// extent at distance c_z (bisection; the sum of the two extreme slopes falls as c moves right).
float centre_axis(const Mesh& mesh, glm::vec3 axis, glm::vec3 back, float cz, float c) {
  // Depths are kept above a millionth of the largest (relative, so that a model in tiny units is
  // centred as the same model in units of 1).
  float deepest = 0.0f;
  for (const glm::vec3& p : mesh.positions) deepest = std::max(deepest, cz - glm::dot(p, back));
  const float min_depth = std::max(1.0e-6f * deepest, std::numeric_limits<float>::min());
  auto imbalance = [&](float cx) {
    float hi = -std::numeric_limits<float>::max(), lo = std::numeric_limits<float>::max();
    for (const glm::vec3& p : mesh.positions) {
      float depth = std::max(cz - glm::dot(p, back), min_depth);
      float slope = (glm::dot(p, axis) - cx) / depth;
      hi = std::max(hi, slope), lo = std::min(lo, slope);
    }
    return hi + lo;
  };
  // The extent at distance c_z spans at most the width of the whole model seen at its nearest.
  float span = 0.0f;
  for (const glm::vec3& p : mesh.positions) span = std::max(span, std::abs(glm::dot(p, axis) - c));
  float lo = c - span, hi = c + span;
  for (int i = 0; i < 24; ++i) {
    float mid = 0.5f * (lo + hi);
    (imbalance(mid) > 0.0f ? lo : hi) = mid;
  }
  return 0.5f * (lo + hi);
}

// The eye of a perspective camera looking along -view.back that fits the model with the given
// half-slopes; with a target given, the eye stays on the line through it.
glm::vec3 fit_eye(const Mesh& mesh, const ViewFrame& view, float kx, float ky,
                  const std::optional<glm::vec3>& target) {
  if (target) {
    float cx = glm::dot(*target, view.right), cy = glm::dot(*target, view.up);
    float cz = -std::numeric_limits<float>::max();
    for (const glm::vec3& p : mesh.positions) {
      float need = std::max(std::abs(glm::dot(p, view.right) - cx) / kx,
                            std::abs(glm::dot(p, view.up) - cy) / ky);
      cz = std::max(cz, glm::dot(p, view.back) + need);
    }
    float td = glm::dot(*target, view.back);
    if (!(cz > td)) cz = td + radius_of(mesh, *target);
    return *target + view.back * (cz - td);
  }
  auto [cx, czx] = fit_axis(mesh, view.right, view.back, kx);
  auto [cy, czy] = fit_axis(mesh, view.up, view.back, ky);
  float cz = std::max(czx, czy);
  if (czx < cz) cx = centre_axis(mesh, view.right, view.back, cz, cx);
  if (czy < cz) cy = centre_axis(mesh, view.up, view.back, cz, cy);
  return cx * view.right + cy * view.up + cz * view.back;
}

// Near and far for a scene spanning the distances [lo, hi] in front of the eye (along the view
// direction), with a margin, from the flags where given; an automatic value that contradicts a
// given one gives way to it.
void set_depth_range(Camera& camera, float lo, float hi, const CameraFlags& flags) {
  // Relative to the scene's own size and distance, so that a model in tiny units (1e-9) gets
  // planes around it, not a fixed floor in front of it.
  float margin = kDepthMargin * std::max(hi - lo, 1.0e-3f * std::abs(hi));
  if (!(margin > 0.0f)) margin = 1.0e-6f;                        // a flat model through the eye
  float far_plane = hi + margin > 0.0f ? hi + margin : 1.0e-3f;  // 1e-3: nothing in front
  float near_plane = std::max(lo - margin, far_plane * kMinNearRatio);
  if (camera.orthographic) near_plane = lo - margin;  // anything in front of the box
  if (flags.far_plane && !flags.near_plane && near_plane >= *flags.far_plane) {
    near_plane = *flags.far_plane * kMinNearRatio;
  }
  if (flags.near_plane && !flags.far_plane && far_plane <= *flags.near_plane) {
    far_plane = *flags.near_plane / kMinNearRatio;
  }
  camera.near_plane = flags.near_plane.value_or(near_plane);
  camera.far_plane = flags.far_plane.value_or(far_plane);
}

// The distances every vertex spans in front of the camera.
std::pair<float, float> vertex_depths(const Camera& camera, const Mesh& mesh) {
  // Normalised in double: float squares overflow for a model in units past 1.8e19.
  glm::vec3 forward = glm::vec3(glm::normalize(glm::dvec3(camera.target) - glm::dvec3(camera.eye)));
  float lo = std::numeric_limits<float>::max(), hi = -lo;
  for (const glm::vec3& p : mesh.positions) {
    float d = glm::dot(p - camera.eye, forward);
    lo = std::min(lo, d), hi = std::max(hi, d);
  }
  return {lo, hi};
}

}  // namespace

std::optional<Orientation> view_named(std::string_view name) {
  for (const NamedView& v : kViews) {
    if (v.name == name) return v.orientation;
  }
  return std::nullopt;
}

std::string view_names() {
  std::string list;
  for (size_t i = 0; i < kViews.size(); ++i) {
    if (i > 0) list += i + 1 == kViews.size() ? " or " : ", ";
    list += kViews[i].name;
  }
  return list;
}

Camera frame_model(const Mesh& mesh, const CameraFlags& flags, float aspect) {
  Camera camera;
  apply_flags(camera, flags);
  ViewFrame view = view_frame(model_frame(flags.up_axis), orientation_for(mesh, flags));
  camera.up = flags.up.value_or(view.up);
  glm::vec3 center = center_of(mesh);
  camera.target = flags.target.value_or(center);
  if (flags.eye) {
    camera.eye = *flags.eye;
  } else if (camera.orthographic) {  // the box is given: any distance outside the model suits
    camera.eye = camera.target + view.back * (2.0f * radius_of(mesh, camera.target));
  } else {
    float ky = std::tan(radians(camera.fov_y_degrees) * 0.5f) * kFrameFill * flags.zoom;
    float kx = ky * aspect;
    camera.eye = fit_eye(mesh, view, kx, ky, flags.target);
    if (!flags.target) {  // look at the model's centre depth, along the fitted axis
      float distance = glm::dot(camera.eye - center, view.back);
      camera.target = camera.eye - view.back * (distance > 0.0f ? distance : 1.0e-6f);
    }
  }
  if (!flags.up) camera.up = default_up(camera, view.up, model_frame(flags.up_axis));
  auto [lo, hi] = vertex_depths(camera, mesh);
  set_depth_range(camera, lo, hi, flags);
  return camera;
}

Bounds bounds_of(const Mesh& mesh) {
  if (mesh.positions.empty()) return {};
  Bounds bounds;
  bounds.center = center_of(mesh);
  bounds.radius = radius_of(mesh, bounds.center);
  bounds.flat_in_y = flat_along(mesh, glm::vec3(0.0f, 1.0f, 0.0f));
  bounds.flat_in_x = !bounds.flat_in_y && flat_along(mesh, glm::vec3(1.0f, 0.0f, 0.0f));
  return bounds;
}

Camera frame_model(const Bounds& bounds, const CameraFlags& flags, float aspect) {
  Camera camera;
  apply_flags(camera, flags);
  camera.target = flags.target.value_or(bounds.center);
  float distance = 2.0f * bounds.radius;  // any distance outside suits an orthographic camera
  if (!camera.orthographic) {
    float half_y = radians(camera.fov_y_degrees) * 0.5f;
    float half_x = std::atan(std::tan(half_y) * aspect);
    distance = bounds.radius / std::sin(std::min(half_y, half_x));
  }
  glm::vec3 direction = bounds.flat_in_y   ? glm::normalize(glm::vec3(0.0f, 1.0f, 1.0f))
                        : bounds.flat_in_x ? glm::vec3(1.0f, 0.0f, 0.0f)
                                           : glm::vec3(0.0f, 0.0f, 1.0f);
  camera.eye = flags.eye.value_or(camera.target + direction * distance);
  if (!flags.up)
    camera.up = default_up(camera, camera.up, model_frame(glm::vec3(0.0f, 1.0f, 0.0f)));
  float to_center = float(glm::length(glm::dvec3(camera.eye) - glm::dvec3(bounds.center)));
  set_depth_range(camera, to_center - bounds.radius, to_center + bounds.radius, flags);
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
