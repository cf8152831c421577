// geometry/tangents.cpp: per-vertex tangent frames for tangent-space normal maps.
#include <cmath>

#include <glm/geometric.hpp>

#include "softrast/mesh.hpp"

namespace softrast {
namespace {

// The angle at corner a of triangle (a, b, c), or 0 when an edge is degenerate.
double corner_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  glm::dvec3 u = b - a, v = c - a;
  double lu = glm::length(u), lv = glm::length(v);
  if (!(lu > 0.0) || !(lv > 0.0)) return 0.0;
  double cosine = glm::dot(u, v) / (lu * lv);
  return std::acos(cosine < -1.0 ? -1.0 : (cosine > 1.0 ? 1.0 : cosine));
}

// Any unit vector orthogonal to the unit vector n.
glm::dvec3 orthogonal_to(const glm::dvec3& n) {
  glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(axis - n * glm::dot(axis, n));
}

}  // namespace

void compute_tangents(Mesh& mesh) {
  size_t n = mesh.positions.size();
  std::vector<glm::dvec3> tangent(n, glm::dvec3(0.0)), bitangent(n, glm::dvec3(0.0));
  if (mesh.normals.size() == n && mesh.uvs.size() == n) {
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
      if (i[0] >= n || i[1] >= n || i[2] >= n) continue;
      glm::dvec3 p[3];
      glm::dvec2 uv[3];
      for (int k = 0; k < 3; ++k) p[k] = mesh.positions[i[k]], uv[k] = mesh.uvs[i[k]];
      // Solve e1 = du1 T + dv1 B, e2 = du2 T + dv2 B for T and B.
      glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
      glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
      double det = d1.x * d2.y - d2.x * d1.y;
      if (!(std::abs(det) > 0.0) || !std::isfinite(det)) continue;
      glm::dvec3 tri_t = (e1 * d2.y - e2 * d1.y) / det;
      glm::dvec3 tri_b = (e2 * d1.x - e1 * d2.x) / det;
      double lt = glm::length(tri_t), lb = glm::length(tri_b);
      if (!(lt > 0.0) || !(lb > 0.0) || !std::isfinite(lt) || !std::isfinite(lb)) continue;
      tri_t /= lt, tri_b /= lb;
      for (int k = 0; k < 3; ++k) {
        double w = corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        tangent[i[k]] += w * tri_t;
        bitangent[i[k]] += w * tri_b;
      }
    }
  }
  mesh.tangents.resize(n);
  for (size_t v = 0; v < n; ++v) {
    glm::dvec3 normal = v < mesh.normals.size() ? glm::dvec3(mesh.normals[v]) : glm::dvec3(0, 0, 1);
    double ln = glm::length(normal);
    normal = ln > 0.0 && std::isfinite(ln) ? normal / ln : glm::dvec3(0, 0, 1);
    glm::dvec3 t = tangent[v] - normal * glm::dot(tangent[v], normal);
    double lt = glm::length(t);
    t = lt > 1e-12 && std::isfinite(lt) ? t / lt : orthogonal_to(normal);
    double w = glm::dot(glm::cross(normal, t), bitangent[v]) < 0.0 ? -1.0 : 1.0;
    mesh.tangents[v] = glm::vec4(glm::vec3(t), float(w));
  }
}

}  // namespace softrast
