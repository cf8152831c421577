// tests/polygon_test.cpp: polygon faces into triangles (geometry/polygon.hpp), alone and through
// the OBJ and PLY loaders. The oracle is independent of the code: a triangulation of a simple
// polygon has n - 2 triangles that all turn as the polygon does, whose areas add up to the
// polygon's (shoelace) area and whose centroids lie inside it (crossing number). A fan passes
// for convex polygons only: concave ones (a U, a ring joined to its hole by a cut, a star) fail
// it there.

#include <gtest/gtest.h>
#include <unistd.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "geometry/polygon.hpp"
#include "softrast/mesh.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;
using P2 = glm::dvec2;

double shoelace(const std::vector<P2>& p) {
  double a = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const P2 &u = p[i], &v = p[(i + 1) % p.size()];
    a += u.x * v.y - v.x * u.y;
  }
  return a / 2.0;
}

// Even-odd crossing number: inside a simple polygon.
bool inside(const std::vector<P2>& p, P2 q) {
  bool in = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    if ((p[i].y > q.y) != (p[j].y > q.y) &&
        q.x < (p[j].x - p[i].x) * (q.y - p[i].y) / (p[j].y - p[i].y) + p[i].x) {
      in = !in;
    }
  }
  return in;
}

// The polygon placed in 3D by `to3d` (any plane), triangulated, checked in its own plane.
void expect_triangulates(const std::vector<P2>& poly, const glm::dmat4& to3d) {
  std::vector<glm::vec3> points;
  for (P2 p : poly) points.push_back(glm::vec3(to3d * glm::dvec4(p, 0.0, 1.0)));
  std::vector<uint32_t> tri;
  detail::triangulate_polygon(points.data(), points.size(), tri);
  ASSERT_EQ(tri.size(), 3 * (poly.size() - 2));
  const double area = shoelace(poly), sign = area > 0 ? 1.0 : -1.0;
  double sum = 0.0;
  for (size_t t = 0; t < tri.size(); t += 3) {
    ASSERT_LT(tri[t], poly.size());
    ASSERT_LT(tri[t + 1], poly.size());
    ASSERT_LT(tri[t + 2], poly.size());
    const std::vector<P2> abc = {poly[tri[t]], poly[tri[t + 1]], poly[tri[t + 2]]};
    const double a = shoelace(abc);
    EXPECT_GE(a * sign, 0.0) << "triangle " << t / 3 << " turns against the polygon";
    sum += a;
    if (std::fabs(a) > 1e-9 * std::fabs(area)) {
      EXPECT_TRUE(inside(poly, (abc[0] + abc[1] + abc[2]) / 3.0))
          << "triangle " << t / 3 << " lies outside the polygon";
    }
  }
  EXPECT_NEAR(sum, area, 1e-6 * std::fabs(area));
}

std::vector<P2> reversed(std::vector<P2> p) {
  return {p.rbegin(), p.rend()};
}

// A U whose first corner is the top of its right arm: the fan from there crosses the notch.
std::vector<P2> u_shape() {
  return {{2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}, {0, 0}, {3, 0}, {3, 3}};
}

// A ring as one polygon: the outer circle counter-clockwise, a cut in, the inner circle
// clockwise, the cut out again (its two ends repeated, as in a LightWave export).
std::vector<P2> ring(int segments) {
  std::vector<P2> p;
  for (int i = 0; i <= segments; ++i) {
    double t = 2.0 * M_PI * i / segments;
    p.push_back({2.0 * std::cos(t), 2.0 * std::sin(t)});
  }
  for (int i = segments; i >= 0; --i) {
    double t = 2.0 * M_PI * i / segments;
    p.push_back({1.5 * std::cos(t), 1.5 * std::sin(t)});
  }
  return p;
}

std::vector<P2> star(int points) {
  std::vector<P2> p;
  for (int i = 0; i < 2 * points; ++i) {
    double t = M_PI * i / points, r = i % 2 ? 0.4 : 1.0;
    p.push_back({r * std::cos(t), r * std::sin(t)});
  }
  return p;
}

const glm::dmat4 kFlat(1.0);
const glm::dmat4 kTilted =
    glm::rotate(glm::rotate(glm::dmat4(1.0), 1.1, glm::dvec3(1, 0, 0)), -0.7, glm::dvec3(0, 1, 0));
const glm::dmat4 kSideways = glm::rotate(glm::dmat4(1.0), M_PI / 2, glm::dvec3(0, 1, 0));

TEST(Polygon, ConcavePolygonsBecomeTrianglesInsideThem) {
  for (const glm::dmat4& m : {kFlat, kTilted, kSideways}) {
    expect_triangulates(u_shape(), m);
    expect_triangulates(reversed(u_shape()), m);  // clockwise: triangles clockwise too
    expect_triangulates(ring(32), m);
    expect_triangulates(star(5), m);
    expect_triangulates(star(int(detail::kMaxEarCorners) / 2), m);  // 256 corners
  }
}

TEST(Polygon, AFanFailsTheOracle) {  // the oracle above tells a fan of a concave polygon apart
  std::vector<P2> u = u_shape();
  const double area = shoelace(u);
  bool some_outside = false;
  for (size_t k = 2; k < u.size(); ++k) {
    const std::vector<P2> abc = {u[0], u[k - 1], u[k]};
    const P2 c = (abc[0] + abc[1] + abc[2]) / 3.0;
    if (std::fabs(shoelace(abc)) > 1e-9 * area && !inside(u, c)) some_outside = true;
  }
  EXPECT_TRUE(some_outside);
}

TEST(Polygon, ConvexPolygonsAreTheFan) {
  std::vector<glm::vec3> hexagon;
  for (int i = 0; i < 6; ++i) {
    hexagon.push_back({std::cos(i * 1.047f), 0.5f, std::sin(-i * 1.047f)});
  }
  std::vector<uint32_t> tri;
  detail::triangulate_polygon(hexagon.data(), hexagon.size(), tri);
  EXPECT_EQ(tri, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5}));
  // A square with a corner on one of its edges (collinear) is still the fan.
  std::vector<glm::vec3> square = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  tri.clear();
  detail::triangulate_polygon(square.data(), square.size(), tri);
  EXPECT_EQ(tri, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
}

TEST(Polygon, DegenerateAndSelfCrossingPolygonsStillGiveNMinusTwoTriangles) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::vector<glm::vec3>> cases = {
      {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}},                     // a line
      {{0, 0, 0}, {1, 0, 0}, {nan, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}},  // not finite
      {{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}},                     // a bow tie
      {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}},          // one point
  };
  std::vector<glm::vec3> scribble;  // 200 corners crossing one another at random
  uint32_t seed = 12345;
  for (int i = 0; i < 200; ++i) {
    seed = seed * 1664525u + 1013904223u;
    float x = float(seed >> 8) / 16777216.0f;
    seed = seed * 1664525u + 1013904223u;
    scribble.push_back({x, float(seed >> 8) / 16777216.0f, 0.0f});
  }
  cases.push_back(scribble);
  for (const std::vector<glm::vec3>& c : cases) {
    std::vector<uint32_t> tri;
    detail::triangulate_polygon(c.data(), c.size(), tri);
    ASSERT_EQ(tri.size(), 3 * (c.size() - 2));
    for (uint32_t k : tri) EXPECT_LT(k, c.size());
  }
}

// A file's allowance of point tests: each concave face takes from it, and once it is spent the
// faces are fanned (bounded time for a file of many large concave faces).
TEST(Polygon, AFilesAllowanceIsSharedAndThenFacesAreFanned) {
  std::vector<glm::vec3> points;
  for (P2 p : u_shape()) points.push_back(glm::vec3(float(p.x), float(p.y), 0.0f));
  std::vector<uint32_t> fan;
  for (uint32_t k = 2; k < points.size(); ++k) fan.insert(fan.end(), {0, k - 1, k});
  uint64_t budget = 1000;
  std::vector<uint32_t> tri;
  detail::triangulate_polygon(points.data(), points.size(), tri, &budget);
  EXPECT_NE(tri, fan);
  EXPECT_LT(budget, 1000u);
  EXPECT_GT(budget, 0u);
  budget = 0;
  tri.clear();
  detail::triangulate_polygon(points.data(), points.size(), tri, &budget);
  EXPECT_EQ(tri, fan);
}

class PolygonFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "softrast_polygon_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
  // The loaded triangles against the U in the plane z = 0.
  static void expect_u(const Result<Mesh>& mesh) {
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    const std::vector<P2> u = u_shape();
    ASSERT_EQ(mesh->indices.size(), 3 * (u.size() - 2));
    double sum = 0.0;
    for (size_t t = 0; t < mesh->indices.size(); t += 3) {
      std::vector<P2> abc;
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = mesh->positions[mesh->indices[t + k]];
        abc.push_back({p.x, p.y});
      }
      sum += shoelace(abc);
      EXPECT_GT(shoelace(abc), 0.0);  // counter-clockwise, as the face
      EXPECT_TRUE(inside(u, (abc[0] + abc[1] + abc[2]) / 3.0)) << "triangle " << t / 3;
    }
    EXPECT_NEAR(sum, shoelace(u), 1e-9);
  }
  fs::path dir_;
};

TEST_F(PolygonFileTest, ObjConcaveFaceCoversOnlyItself) {
  std::string obj;
  for (P2 p : u_shape()) obj += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
  obj += "f 1 2 3 4 5 6 7 8\n";
  expect_u(load_model(write("u.obj", obj)));
}

TEST_F(PolygonFileTest, PlyConcaveFaceCoversOnlyItself) {
  const std::vector<P2> u = u_shape();
  std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(u.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (P2 p : u) ply += std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
  ply += "8 0 1 2 3 4 5 6 7\n";
  expect_u(load_model(write("u.ply", ply)));
}

}  // namespace
}  // namespace softrast
