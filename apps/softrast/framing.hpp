// apps/softrast/framing.hpp: the camera for a model when the command line does not place one:
// look at the model from a side (--view, --azimuth, --elevation, relative to its --up-axis) and
// move the camera until the model's projected vertices fill 90% of the image's width or height,
// whichever limits it (--zoom scales that).
#pragma once

#include <optional>
#include <string_view>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/camera.hpp"
#include "softrast/mesh.hpp"

namespace softrast::cli {

// A direction to look from, in degrees: azimuth around the up axis from the front towards the
// right, elevation above the horizon.
struct Orientation {
  float azimuth = 0.0f;
  float elevation = 0.0f;
};

// front, back, left, right, top, bottom or iso; none for another name.
std::optional<Orientation> view_named(std::string_view name);
// "front, back, left, right, top, bottom or iso".
std::string view_names();

// The camera settings given on the command line; the others come from the scene or framing.
struct CameraFlags {
  std::optional<glm::vec3> eye, target, up;
  std::optional<float> fov, near_plane, far_plane;
  std::optional<glm::vec4> ortho;           // left, right, bottom, top
  glm::vec3 up_axis{0.0f, 1.0f, 0.0f};      // the model's up direction, a unit axis
  std::optional<float> azimuth, elevation;  // --view's, replaced by --azimuth / --elevation
  float zoom = 1.0f;
};

// The share of the image's limiting side the framed model fills at zoom 1.
inline constexpr float kFrameFill = 0.9f;

// The camera framing `mesh` (its positions, which must not be empty) in an image of the given
// aspect ratio (width / height); every setting given in `flags` is used as is and the others
// adapt to it.
Camera frame_model(const Mesh& mesh, const CameraFlags& flags, float aspect);

// The sphere around the axis-aligned bounding box of the positions (radius > 0; 1 for an empty
// or single-point mesh), for callers that move a camera around a scene without its vertices.
struct Bounds {
  glm::vec3 center{0.0f};
  float radius = 1.0f;
  bool flat_in_y = false;  // height under a tenth of the width and depth: a ground plane
  bool flat_in_x = false;  // else width under a tenth of the height and depth: a wall across
};
Bounds bounds_of(const Mesh& mesh);

// The bounding sphere's framing: from +z (45 degrees up for a model flat in y, from +x for one
// flat in x) at the distance where the sphere fits the narrower field of view; with the eye and
// target given, only near and far (around the sphere) are chosen. Looser than frame_model(mesh)
// above.
Camera frame_model(const Bounds& bounds, const CameraFlags& flags, float aspect);

// Replaces the settings of `camera` that `flags` gives.
void apply_flags(Camera& camera, const CameraFlags& flags);

}  // namespace softrast::cli
