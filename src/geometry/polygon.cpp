// geometry/polygon.cpp: polygon faces into triangles (fan when convex, else ear clipping).
#include "geometry/polygon.hpp"

#include <algorithm>
#include <cmath>

namespace softrast::detail {
namespace {

struct Point2 {
  double x, y;
  bool operator==(const Point2&) const = default;
};

// Twice the signed area of triangle abc: positive when it turns counter-clockwise.
double turn(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// p inside counter-clockwise triangle abc or on its edges.
bool inside_or_on(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  return turn(a, b, p) >= 0.0 && turn(b, c, p) >= 0.0 && turn(c, a, p) >= 0.0;
}

// The polygon in the coordinate plane its normal (Newell's, in double) points along most, turned
// so that it runs counter-clockwise there. False when a corner is not finite or the polygon has
// no area in any plane.
bool project(const glm::vec3* points, size_t n, std::vector<Point2>& out) {
  double normal[3] = {0.0, 0.0, 0.0};
  for (size_t i = 0; i < n; ++i) {
    const glm::vec3& a = points[i];
    const glm::vec3& b = points[i + 1 == n ? 0 : i + 1];
    normal[0] += (double(a.y) - b.y) * (double(a.z) + b.z);
    normal[1] += (double(a.z) - b.z) * (double(a.x) + b.x);
    normal[2] += (double(a.x) - b.x) * (double(a.y) + b.y);
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::fabs(normal[k]) > std::fabs(normal[axis])) axis = k;
  }
  if (!std::isfinite(normal[axis]) || normal[axis] == 0.0) return false;
  // Normal component k is twice the area in the plane of axes k + 1 and k + 2 (cyclically).
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double flip = normal[axis] > 0.0 ? 1.0 : -1.0;
  out.resize(n);
  for (size_t i = 0; i < n; ++i) out[i] = {points[i][u], flip * points[i][v]};
  return true;
}

bool convex(const std::vector<Point2>& p) {
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    if (turn(p[(i + n - 1) % n], p[i], p[(i + 1) % n]) < 0.0) return false;
  }
  return true;
}

// Ear clipping of counter-clockwise polygon p: corners stay in a ring of links; a corner whose turn
// is strictly convex and whose triangle with its neighbours holds no other remaining corner (one
// at the same position as the triangle's own corners aside) is cut off. Stops at three corners,
// after a whole round without an ear, or when the budget of point tests is spent; the ring left
// is fanned.
void clip_ears(const std::vector<Point2>& p, std::vector<uint32_t>& out, uint64_t& budget) {
  const size_t n = p.size();
  std::vector<uint32_t> prev(n), next(n);
  for (size_t i = 0; i < n; ++i) {
    prev[i] = uint32_t(i == 0 ? n - 1 : i - 1);
    next[i] = uint32_t(i + 1 == n ? 0 : i + 1);
  }
  auto is_ear = [&](uint32_t a, uint32_t v, uint32_t c) {
    if (turn(p[a], p[v], p[c]) <= 0.0) return false;
    for (uint32_t r = next[c]; r != a; r = next[r]) {
      if (budget > 0) --budget;
      if (p[r] == p[a] || p[r] == p[v] || p[r] == p[c]) continue;
      if (inside_or_on(p[r], p[a], p[v], p[c])) return false;
    }
    return true;
  };
  size_t remaining = n, misses = 0;
  uint32_t v = 0;
  while (remaining > 3 && misses < remaining && budget > 0) {
    const uint32_t a = prev[v], c = next[v];
    if (!is_ear(a, v, c)) {
      v = c;
      ++misses;
      continue;
    }
    out.insert(out.end(), {a, v, c});
    next[a] = c;
    prev[c] = a;
    --remaining;
    misses = 0;
    v = c;
  }
  for (uint32_t b = next[v], c = next[b]; c != v; b = c, c = next[c])
    out.insert(out.end(), {v, b, c});
}

}  // namespace

void append_fan(size_t n, std::vector<uint32_t>& out) {
  for (size_t k = 2; k < n; ++k) out.insert(out.end(), {0u, uint32_t(k - 1), uint32_t(k)});
}

void triangulate_polygon(const glm::vec3* points, size_t n, std::vector<uint32_t>& out,
                         uint64_t* budget) {
  thread_local std::vector<Point2> projected;  // reused: a loader calls this once per face
  const uint64_t allowed = std::min<uint64_t>(kEarTests * n * n, budget ? *budget : UINT64_MAX);
  if (n > 3 && n <= kMaxEarCorners && allowed > 0 && project(points, n, projected) &&
      !convex(projected)) {
    uint64_t left = allowed;
    clip_ears(projected, out, left);
    if (budget) *budget -= allowed - left;
    return;
  }
  append_fan(n, out);
}

}  // namespace softrast::detail
