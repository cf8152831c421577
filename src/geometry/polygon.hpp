// geometry/polygon.hpp: a model file's polygon faces cut into triangles (OBJ's and PLY's faces
// of more than three corners).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace softrast::detail {

// Appends the n - 2 triangles of the polygon whose corners, in order, are at `points[0..n)` (n >=
// 3) to `out`, as corner numbers (three per triangle), each triangle turning as the polygon does.
//
// A convex polygon (every turn the same way, seen along the polygon's normal; also any polygon
// whose corners are not all finite or whose area is zero) gives the fan around corner 0: (0, 1,
// 2), (0, 2, 3), ..., what the model formats' convex faces have always given. A concave one is cut
// by ear clipping in the plane it faces most, so that no triangle covers what lies outside the
// polygon (a fan would fill a ring's hole or an L's notch): corners at one position, such as the
// two ends of the cut that joins a hole to its outline, are not taken as lying inside an ear.
//
// The ears are searched with at most kEarTests point tests per squared corner count, and
// polygons of more than kMaxEarCorners corners are fanned (a self-intersecting polygon has no
// ears to find; its remainder is fanned). `budget`, when given, is a file's allowance of point
// tests, shared by its faces and reduced by each: once it is spent, faces are fanned, so that a
// file of many large concave faces costs a bounded time (kFileEarTests, about a second), not a
// time that grows with the square of its faces' size.
void triangulate_polygon(const glm::vec3* points, size_t n, std::vector<uint32_t>& out,
                         uint64_t* budget = nullptr);

// The fan around corner 0 of a polygon of n corners: (0, 1, 2), (0, 2, 3), ...
void append_fan(size_t n, std::vector<uint32_t>& out);

inline constexpr size_t kMaxEarCorners = 256;
inline constexpr size_t kEarTests = 4;
inline constexpr uint64_t kFileEarTests = uint64_t(1) << 28;

}  // namespace softrast::detail
