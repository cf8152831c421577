// apps/softrast/framing.hpp: the camera for a model when the command line does not give one:
// look at the bounding box's centre from +z (from 45 degrees up for flat models), far enough that
// the bounding sphere fits the view.
#pragma once

#include <optional>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "softrast/camera.hpp"
#include "softrast/mesh.hpp"

namespace softrast::cli {

// The camera settings given on the command line; the others come from the scene or framing.
struct CameraFlags {
  std::optional<glm::vec3> eye, target, up;
  std::optional<float> fov, near_plane, far_plane;
  std::optional<glm::vec4> ortho;  // left, right, bottom, top
};

// The sphere around the axis-aligned bounding box of the positions; radius > 0 (1 for an empty
// or single-point mesh).
struct Bounds {
  glm::vec3 center{0.0f};
  float radius = 1.0f;
  bool flat_in_y = false;  // height under a tenth of the width and depth: a ground plane
};
Bounds bounds_of(const Mesh& mesh);

// The camera framing `bounds` in an image of the given aspect ratio (width / height); every
// setting given in `flags` is used as is and the others adapt to it.
Camera frame_model(const Bounds& bounds, const CameraFlags& flags, float aspect);

// Replaces the settings of `camera` that `flags` gives.
void apply_flags(Camera& camera, const CameraFlags& flags);

}  // namespace softrast::cli
