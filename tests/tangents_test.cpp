// Tangent frames: the direction of increasing u, handedness from the direction of increasing v.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "softrast/mesh.hpp"

namespace softrast {
namespace {

// A unit quad in the z = 0 plane facing +z, uv = f(position).
Mesh quad(glm::vec2 (*uv_of)(glm::vec2)) {
  Mesh m;
  glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (glm::vec2 c : corners) {
    m.positions.emplace_back(c.x, c.y, 0.0f);
    m.normals.emplace_back(0.0f, 0.0f, 1.0f);
    m.uvs.push_back(uv_of(c));
  }
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

void expect_frame(const Mesh& m, glm::vec3 tangent, float w) {
  ASSERT_EQ(m.tangents.size(), m.positions.size());
  for (const glm::vec4& t : m.tangents) {
    EXPECT_NEAR(t.x, tangent.x, 1e-6f);
    EXPECT_NEAR(t.y, tangent.y, 1e-6f);
    EXPECT_NEAR(t.z, tangent.z, 1e-6f);
    EXPECT_EQ(t.w, w);
  }
}

TEST(Tangents, FollowIncreasingU) {
  Mesh m = quad([](glm::vec2 p) { return p; });
  compute_tangents(m);
  expect_frame(m, {1, 0, 0}, 1.0f);
  // u along +y, v along -x: the tangent is +y, and cross(n, t) = -x is the bitangent: w = +1.
  Mesh r = quad([](glm::vec2 p) { return glm::vec2(p.y, 1.0f - p.x); });
  compute_tangents(r);
  expect_frame(r, {0, 1, 0}, 1.0f);
}

TEST(Tangents, MirroredVGivesNegativeHandedness) {
  Mesh m = quad([](glm::vec2 p) { return glm::vec2(p.x, 1.0f - p.y); });
  compute_tangents(m);
  expect_frame(m, {1, 0, 0}, -1.0f);
}

TEST(Tangents, AreOrthogonalToTheNormal) {
  Mesh m = quad([](glm::vec2 p) { return p; });
  glm::vec3 tilted = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
  for (auto& n : m.normals) n = tilted;
  compute_tangents(m);
  for (const glm::vec4& t : m.tangents) {
    EXPECT_NEAR(glm::dot(glm::vec3(t), tilted), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-6f);
  }
}

TEST(Tangents, DegenerateUvsStillGiveAUnitFrame) {
  Mesh m = quad([](glm::vec2) { return glm::vec2(0.5f); });
  compute_tangents(m);
  for (const glm::vec4& t : m.tangents) {
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-6f);
    EXPECT_NEAR(t.z, 0.0f, 1e-6f);
    EXPECT_EQ(t.w, 1.0f);
  }
}

}  // namespace
}  // namespace softrast
