// tests/model_formats_test.cpp: PLY and STL input, and load_model's choice of format.
// One mesh, written by this test as OBJ, ASCII PLY, binary PLY (little and big endian) and
// ASCII and binary STL, loads to the same triangles and renders the same image in each; every
// truncation of each file is a clear error; files that are not models say what they are.

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "softrast/framebuffer.hpp"
#include "softrast/image.hpp"
#include "softrast/mesh.hpp"
#include "softrast/renderer.hpp"

namespace softrast {
namespace {

namespace fs = std::filesystem;

// A box with six quad faces, 4 vertices of its own per face (flat shading), counter-clockwise
// seen from outside, with axis-aligned normals (exact in every format).
struct Quad {
  glm::vec3 p[4];
  glm::vec3 n;
};

std::vector<Quad> box() {
  const float x0 = -0.75f, x1 = 0.5f, y0 = -0.5f, y1 = 0.625f, z0 = -0.25f, z1 = 0.375f;
  return {
      {{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}, {0, 0, 1}},
      {{{x1, y0, z0}, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}}, {0, 0, -1}},
      {{{x1, y0, z1}, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}}, {1, 0, 0}},
      {{{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}}, {-1, 0, 0}},
      {{{x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, {x0, y1, z0}}, {0, 1, 0}},
      {{{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}, {0, -1, 0}},
  };
}

std::string num(float v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", double(v));
  return buffer;
}

std::string vec(const glm::vec3& v) {
  return num(v.x) + " " + num(v.y) + " " + num(v.z);
}

// With `coloured`, every position carries the PLY files' colour (200, 100, 50) / 255 as an OBJ
// vertex colour, written so that it reads back as the same float.
std::string obj_text(bool coloured = false) {
  std::string s = "# box\n";
  std::string colour;  // appended: "..." + std::string draws GCC 12's false -Wrestrict here
  for (double c : {200.0, 100.0, 50.0}) colour.append(" ").append(num(float(c / 255.0)));
  int k = 0;
  for (const Quad& q : box()) {
    for (const glm::vec3& p : q.p) s += "v " + vec(p) + (coloured ? colour : "") + "\n";
    s += "vn " + vec(q.n) + "\n";
    ++k;
    std::string n = std::to_string(k);
    int b = 4 * (k - 1);
    s += "f " + std::to_string(b + 1) + "//" + n + " " + std::to_string(b + 2) + "//" + n + " " +
         std::to_string(b + 3) + "//" + n + " " + std::to_string(b + 4) + "//" + n + "\n";
  }
  return s;
}

std::string ply_header(const char* format, const char* normal_type, const char* list) {
  return std::string("ply\nformat ") + format +
         " 1.0\ncomment written by softrast's tests\nelement vertex 24\n"
         "property float x\nproperty float y\nproperty float z\n"
         "property " +
         normal_type + " nx\nproperty " + normal_type + " ny\nproperty " + normal_type +
         " nz\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         "element face 6\nproperty list " +
         list + "\nend_header\n";
}

std::string ply_ascii() {
  std::string s = ply_header("ascii", "float", "uchar int vertex_indices");
  for (const Quad& q : box()) {
    for (const glm::vec3& p : q.p) s += vec(p) + " " + vec(q.n) + " 200 100 50\n";
  }
  for (int f = 0; f < 6; ++f) {
    s += "4 " + std::to_string(4 * f) + " " + std::to_string(4 * f + 1) + " " +
         std::to_string(4 * f + 2) + " " + std::to_string(4 * f + 3) + "\n";
  }
  return s;
}

template <class T>
void put(std::string& s, T value, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

// Little endian: normals as doubles, list "uchar uint vertex_indices"; big endian: normals as
// floats, list "int ushort vertex_index".
std::string ply_binary(bool big) {
  std::string s = big ? ply_header("binary_big_endian", "float", "int ushort vertex_index")
                      : ply_header("binary_little_endian", "double", "uchar uint vertex_indices");
  for (const Quad& q : box()) {
    for (const glm::vec3& p : q.p) {
      for (int c = 0; c < 3; ++c) put(s, p[c], big);
      for (int c = 0; c < 3; ++c) {
        if (big) {
          put(s, q.n[c], big);
        } else {
          put(s, double(q.n[c]), big);
        }
      }
      s += "\xc8\x64\x32";
    }
  }
  for (int f = 0; f < 6; ++f) {
    if (big) {
      put(s, int32_t(4), big);
      for (int k = 0; k < 4; ++k) put(s, uint16_t(4 * f + k), big);
    } else {
      put(s, uint8_t(4), big);
      for (int k = 0; k < 4; ++k) put(s, uint32_t(4 * f + k), big);
    }
  }
  return s;
}

// The quads fanned as (0, 1, 2), (0, 2, 3), as the loaders fan polygons.
std::string stl_ascii() {
  std::string s = "solid box\n";
  for (const Quad& q : box()) {
    for (int t = 0; t < 2; ++t) {
      s += "  facet normal " + vec(q.n) + "\n    outer loop\n";
      for (int k : {0, t + 1, t + 2}) s += "      vertex " + vec(q.p[k]) + "\n";
      s += "    endloop\n  endfacet\n";
    }
  }
  return s + "endsolid\n";
}

// With `clockwise`, each facet's corners run clockwise about its (outward) normal.
std::string stl_binary(bool clockwise = false) {
  std::string s(80, ' ');
  std::memcpy(s.data(), "binary STL written by softrast's tests", 38);
  put(s, uint32_t(12), false);
  for (const Quad& q : box()) {
    for (int t = 0; t < 2; ++t) {
      for (int c = 0; c < 3; ++c) put(s, q.n[c], false);
      const std::array<int, 3> order =
          clockwise ? std::array<int, 3>{0, t + 2, t + 1} : std::array<int, 3>{0, t + 1, t + 2};
      for (int k : order) {
        for (int c = 0; c < 3; ++c) put(s, q.p[k][c], false);
      }
      put(s, uint16_t(0), false);
    }
  }
  return s;
}

struct Corner {
  glm::vec3 p, n;
  bool operator==(const Corner&) const = default;
};

std::vector<Corner> corners(const Mesh& mesh) {
  std::vector<Corner> out;
  for (uint32_t i : mesh.indices) out.push_back({mesh.positions[i], mesh.normals[i]});
  return out;
}

Image render(const Mesh& mesh) {
  Framebuffer fb(96, 72);
  Camera camera;
  camera.eye = {1.6f, 1.3f, 2.4f};
  RenderOptions options;
  options.shader = ShaderKind::kPhong;
  render_mesh(fb, mesh, camera, options);
  return fb.to_image();
}

class ModelFormatsTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("softrast_models_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return (dir_ / name).string();
  }
  fs::path dir_;
};

struct Encoded {
  const char* name;  // file name: its extension does not decide the format (load_model sniffs)
  std::string bytes;
};

std::vector<Encoded> encodings() {
  return {{"ascii.ply", ply_ascii()},
          {"little.ply", ply_binary(false)},
          {"big.ply", ply_binary(true)},
          {"ascii.stl", stl_ascii()},
          {"binary.stl", stl_binary()}};
}

// The PLY files carry vertex colours, drawn as the albedo: they render as the OBJ with the same
// colours (OBJ vertex colours), the STL files as the plain OBJ.
TEST_F(ModelFormatsTest, EveryEncodingLoadsTheSameTrianglesAndRendersTheSameImage) {
  Result<Mesh> obj = load_model(write("box.obj", obj_text()));
  Result<Mesh> coloured_obj = load_model(write("coloured.obj", obj_text(true)));
  ASSERT_TRUE(obj.ok()) << obj.status().message();
  ASSERT_TRUE(coloured_obj.ok()) << coloured_obj.status().message();
  ASSERT_EQ(obj->triangle_count(), 12u);
  std::vector<Corner> expected = corners(*obj);
  EXPECT_EQ(corners(*coloured_obj), expected);
  Image expected_image = render(*obj), coloured_image = render(*coloured_obj);
  EXPECT_FALSE(coloured_image.rgba == expected_image.rgba);
  for (const Encoded& e : encodings()) {
    // Named .model so that only the content can tell the format.
    std::string path = write(std::string(e.name) + ".model", e.bytes);
    Result<Mesh> mesh = load_model(path);
    ASSERT_TRUE(mesh.ok()) << e.name << ": " << mesh.status().message();
    EXPECT_EQ(corners(*mesh), expected) << e.name;
    const bool ply = std::string(e.name).find(".ply") != std::string::npos;
    EXPECT_EQ(mesh->colors.empty(), !ply) << e.name;
    EXPECT_TRUE(render(*mesh).rgba == (ply ? coloured_image : expected_image).rgba) << e.name;
    EXPECT_TRUE(mesh->warnings.empty());
  }
  // The format's own loaders read them too.
  EXPECT_TRUE(load_ply(write("a.ply", ply_binary(true))).ok());
  EXPECT_TRUE(load_stl(write("a.stl", stl_ascii())).ok());
}

// STL as some writers make it: ASCII keywords in upper case; a binary file with bytes after its
// triangles (padding, or the writer's own data), also when its header begins with "solid". The
// same triangles as the plain files; the extra bytes are a warning. Before, each was refused.
TEST_F(ModelFormatsTest, StlInUpperCaseOrWithTrailingBytesLoads) {
  Result<Mesh> obj = load_model(write("box.obj", obj_text()));
  ASSERT_TRUE(obj.ok()) << obj.status().message();
  std::vector<Corner> expected = corners(*obj);
  std::string upper = stl_ascii();
  for (char& c : upper) c = char(std::toupper((unsigned char)c));
  Result<Mesh> mesh = load_model(write("upper.model", upper));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(corners(*mesh), expected);
  EXPECT_TRUE(mesh->warnings.empty());
  std::string solid_header = stl_binary();
  std::memcpy(solid_header.data(), "solid binary    ", 16);
  for (const std::string& binary : {stl_binary(), solid_header}) {
    std::string p = write("padded.stl", binary + std::string(7, '\0'));
    mesh = load_model(p);
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_EQ(corners(*mesh), expected);
    ASSERT_EQ(mesh->warnings.size(), 1u);
    EXPECT_EQ(mesh->warnings[0],
              p + ": 7 bytes after the 12 triangles the binary STL declares are ignored");
  }
}

TEST_F(ModelFormatsTest, EveryTruncationIsAClearError) {
  for (const Encoded& e : encodings()) {
    // Every cut short of the last byte (for the text formats, the final newline, without which
    // the file still holds all of its data).
    size_t step = std::max<size_t>(1, e.bytes.size() / 97);
    for (size_t cut = 0; cut + 1 < e.bytes.size(); cut += step) {
      std::string path = write(e.name, e.bytes.substr(0, cut));
      Result<Mesh> mesh = load_model(path);
      ASSERT_FALSE(mesh.ok()) << e.name << " cut to " << cut << " bytes loaded";
      const std::string& m = mesh.status().message();
      EXPECT_EQ(m.rfind(path + ":", 0), 0u) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
}

TEST_F(ModelFormatsTest, MessagesNameTheFileAndPlace) {
  // Loads `bytes` as file `name`; the load must fail with "<path>" + `message`.
  auto expect_error = [&](const std::string& name, const std::string& bytes,
                          const std::string& message) {
    std::string p = write(name, bytes);
    Result<Mesh> mesh = load_model(p);
    ASSERT_FALSE(mesh.ok()) << name;
    EXPECT_EQ(mesh.status().message(), p + message);
  };
  expect_error("a.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
               "property float y\nproperty float z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n"
               "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
               ":13: face 0: vertex index 7 is out of range (0..2)");
  expect_error("b.ply",
               "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
               "property float x\nproperty float y\nproperty float z\nend_header\n",
               ": 1000000000 vertex elements need at least 12 bytes each, but 0 bytes are left "
               "(truncated)");
  expect_error("c.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty flaot x\nend_header\n",
               ":4: unknown type 'flaot'");
  // A point cloud (a scanner's PLY) loads as points: every vertex one, in their colours.
  std::string cloud_path = write("cloud.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nproperty uchar red\n"
                                 "property uchar green\nproperty uchar blue\nend_header\n"
                                 "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n");
  Result<Mesh> cloud = load_model(cloud_path);
  ASSERT_TRUE(cloud.ok()) << cloud.status().message();
  EXPECT_EQ(cloud->triangle_count(), 0u);
  EXPECT_EQ(cloud->point_indices, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_EQ(cloud->colors.size(), 3u);
  EXPECT_EQ(cloud->colors[1], glm::vec4(0, 1, 0, 1));
  std::string stl = stl_binary();
  expect_error("d.stl", stl.substr(0, stl.size() - 10),
               ": binary STL declares 12 triangles (684 bytes) but has 674 bytes (truncated)");
  expect_error("e.stl",
               "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n"
               " endloop\n endfacet\nendsolid x\n",
               ":6: expected 'vertex', found 'endloop'");
}

// A header line that is no PLY statement (Blender 2.4x's "Created by ..." without 'comment', as in
// assimp's Wuson.ply) is read past with a warning naming it, and the model loads.
TEST_F(ModelFormatsTest, PlyHeaderLineThatIsNoStatementIsAWarning) {
  std::string p = write("blender.ply",
                        "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\n"
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  Result<Mesh> mesh = load_model(p);
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 1u);
  ASSERT_EQ(mesh->warnings.size(), 1u);
  EXPECT_EQ(mesh->warnings[0], p + ":3: header line 'Created by Blender3D 247 - www.blender.org' "
                                   "is not a PLY statement; read past as a comment");
}

// An STL whose corners run clockwise about its normals throughout (assimp's Spider_binary.stl)
// loads with its winding turned to agree with them, so that the outside is the front (lit under
// two-sided lighting, kept by --cull back), and one warning; the same box wound by the rule has no
// warning and the same corners in each triangle.
TEST_F(ModelFormatsTest, StlWoundAgainstItsNormalsIsTurned) {
  Result<Mesh> turned = load_model(write("clockwise.stl", stl_binary(true)));
  Result<Mesh> plain = load_model(write("plain.stl", stl_binary()));
  ASSERT_TRUE(turned.ok()) << turned.status().message();
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_TRUE(plain->warnings.empty());
  ASSERT_EQ(turned->warnings.size(), 1u);
  EXPECT_NE(turned->warnings[0].find("12 of 12 facets list their corners clockwise"),
            std::string::npos)
      << turned->warnings[0];
  ASSERT_EQ(turned->indices.size(), 36u);
  for (size_t t = 0; t < 36; t += 3) {
    const glm::vec3 a = turned->positions[turned->indices[t]],
                    b = turned->positions[turned->indices[t + 1]],
                    c = turned->positions[turned->indices[t + 2]];
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), turned->normals[turned->indices[t]]), 0.0f)
        << "triangle " << t / 3;
    std::vector<glm::vec3> mine = {a, b, c}, theirs;
    for (int k = 0; k < 3; ++k) theirs.push_back(plain->positions[plain->indices[t + size_t(k)]]);
    EXPECT_TRUE(std::is_permutation(mine.begin(), mine.end(), theirs.begin()));
  }
}

TEST_F(ModelFormatsTest, FilesThatAreNotModelsSayWhatTheyAre) {
  Image pixel(1, 1);
  ASSERT_TRUE(save_image((dir_ / "tex.png").string(), pixel).ok());
  ASSERT_TRUE(save_image((dir_ / "tex.jpg").string(), pixel).ok());
  ASSERT_TRUE(save_image((dir_ / "tex.tga").string(), pixel).ok());
  write("models.zip", std::string("PK\x03\x04", 4) + std::string(26, '\0'));
  write("paper.pdf", "%PDF-1.7\n");
  const std::pair<const char*, const char*> cases[] = {
      {"tex.png", "a PNG image"},      {"tex.jpg", "a JPEG image"},     {"tex.tga", "a TGA image"},
      {"models.zip", "a ZIP archive"}, {"paper.pdf", "a PDF document"},
  };
  for (auto [name, what] : cases) {
    std::string path = (dir_ / name).string();
    Result<Mesh> mesh = load_model(path);
    ASSERT_FALSE(mesh.ok()) << name;
    EXPECT_EQ(mesh.status().message(),
              path + ": this is " + what + ", not a model (softrast reads OBJ, PLY, STL and glTF)");
  }
  // Models in other 3D formats, told by their extension (read as OBJ, they failed with "no faces"
  // or "NUL byte: not a text file").
  write("duck.dae", "<?xml version=\"1.0\"?>\n<COLLADA version=\"1.4.1\">\n</COLLADA>\n");
  write("car.3ds", std::string("\x4d\x4d\x10\x00\x00\x00", 6) + std::string(32, '\0'));
  const std::pair<const char*, const char*> others[] = {
      {"duck.dae", "a COLLADA scene (.dae)"},
      {"car.3ds", "a 3D Studio scene (.3ds)"},
  };
  for (auto [name, what] : others) {
    std::string path = (dir_ / name).string();
    Result<Mesh> mesh = load_model(path);
    ASSERT_FALSE(mesh.ok()) << name;
    EXPECT_EQ(mesh.status().message(),
              path + ": this is " + what +
                  ", a format softrast does not read (it reads OBJ, PLY, STL and glTF 2.0): "
                  "export the model as one of those");
  }
}

}  // namespace
}  // namespace softrast

namespace softrast {
namespace {

// Mutated PLY and STL files (flipped bytes, overwritten runs, cuts, splices): each loads as a
// valid mesh or fails with a one-line message naming the file, never a crash or a hang.
TEST_F(ModelFormatsTest, MutatedFilesLoadOrFailCleanly) {
  uint32_t state = 2024;
  auto next = [&](uint32_t n) {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) % n;
  };
  int failed = 0, loaded = 0;
  for (const Encoded& e : encodings()) {
    for (int round = 0; round < 300; ++round) {
      std::string bytes = e.bytes;
      int edits = 1 + int(next(4));
      for (int k = 0; k < edits; ++k) {
        size_t at = next(uint32_t(bytes.size()));
        switch (next(4)) {
          case 0:
            bytes[at] = char(next(256));
            break;
          case 1:
            bytes[at] ^= char(1 << next(8));
            break;
          case 2:
            bytes.replace(at, std::min<size_t>(4, bytes.size() - at), "\xff\xff\xff\x7f", 4);
            break;
          case 3:
            bytes.insert(at, e.bytes.substr(next(uint32_t(e.bytes.size())), next(64)));
            break;
        }
      }
      std::string path = write(e.name, bytes);
      Result<Mesh> mesh = load_model(path);
      if (mesh.ok()) {
        ++loaded;
        for (uint32_t i : mesh->indices) ASSERT_LT(i, mesh->vertex_count());
        ASSERT_EQ(mesh->normals.size(), mesh->vertex_count());
        ASSERT_EQ(mesh->uvs.size(), mesh->vertex_count());
      } else {
        ++failed;
        EXPECT_EQ(mesh.status().message().rfind(path + ":", 0), 0u) << mesh.status().message();
      }
    }
  }
  EXPECT_GT(failed, 100);
  EXPECT_GT(loaded, 10);
}

// A pipe can be read once: load_model does not sniff it, it reads it as OBJ.
TEST_F(ModelFormatsTest, AnObjFromAPipeLoadsWhole) {
  std::string path = (dir_ / "pipe.obj").string();
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(path, std::ios::binary) << obj_text(); });
  Result<Mesh> mesh = load_model(path);
  writer.join();
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  EXPECT_EQ(mesh->triangle_count(), 12u);
}

}  // namespace
}  // namespace softrast
