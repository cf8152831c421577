// tools/reference/glref.cpp: the reference renderer. Draws an OBJ file with OpenGL 3.3 core on
// Mesa's llvmpipe (through OSMesa) by exactly the pipeline of shared/bench/SCENES.md, and takes
// the flags of `softrast render` that the benchmark scenes use, so that images, fragment counts
// and frame times compare one to one with softrast.
//
// Not part of the library and deliberately independent of it: the OBJ is read with tinyobjloader
// here, the matrices come straight from GLM, the shaders are GLSL. Only the pipeline description
// is shared. Used by tests/reference_diff_test.cpp and for the side-by-side benchmark.
//
// llvmpipe reads LP_NUM_THREADS when the context is created; --threads N sets it first.

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>  // includes GL/gl.h and GL/glext.h

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>
#include <tiny_obj_loader.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace {

namespace fs = std::filesystem;

// SCENES.md: untimed frames before the timed ones.
constexpr int kWarmupFrames = 2;
// Exit codes as softrast's: 2 for bad usage, 1 for anything else that fails.
constexpr int kExitUsage = 2;
constexpr int kExitFailure = 1;

// An error that ends the program with one line on stderr.
struct Failure {
  int code;
  std::string message;
};

[[noreturn]] void usage_error(const std::string& message) {
  throw Failure{kExitUsage, message};
}
[[noreturn]] void failure(const std::string& message) {
  throw Failure{kExitFailure, message};
}

// ---------------------------------------------------------------------------------------------
// Flags: the subset of `softrast render` that the scenes and the difference tests use.

struct Options {
  std::string model;
  bool trilinear = false;  // --filter trilinear: a mip chain and GL_LINEAR_MIPMAP_LINEAR
  int width = 800, height = 600;
  std::optional<glm::vec3> eye, target;
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov = 45.0f;
  std::optional<float> near_plane, far_plane;
  std::optional<glm::vec4> ortho;  // left, right, bottom, top
  std::string shader = "phong";
  std::optional<std::string> texture;
  glm::vec3 color{0.9f, 0.6f, 0.3f};
  glm::vec3 light{0.3f, 0.5f, 0.8f};  // towards the light, world space
  float alpha = 1.0f;
  std::string cull = "none", front_face = "ccw", depth = "less", blend = "opaque";
  int frames = 0;
  int msaa = 1;  // samples per pixel: above 1, a multisample framebuffer resolved by a blit
  std::optional<int> threads;
  std::optional<std::string> out;
  bool quiet = false;
};

constexpr const char* kHelp =
    "glref: the llvmpipe reference renderer (OpenGL 3.3 core through OSMesa)\n"
    "usage: glref MODEL.obj --eye X,Y,Z --target X,Y,Z --near Z --far Z [options]\n"
    "  -o, --out PATH      PNG output (glref.png; with --frames only if given)\n"
    "  --size WxH          image size (800x600)\n"
    "  --up X,Y,Z          up direction (0,1,0)\n"
    "  --fov DEG           vertical field of view, gluPerspective (45)\n"
    "  --light X,Y,Z       direction towards the light, world space (0.3,0.5,0.8)\n"
    "  --ortho L,R,B,T     glOrtho box instead of a perspective\n"
    "  --shader NAME       flat, gouraud, texture, phong, normals or wireframe (phong)\n"
    "  --texture PATH      PNG/TGA texture for texture and phong\n"
    "  --filter MODE       bilinear or trilinear (GL_LINEAR_MIPMAP_LINEAR, glGenerateMipmap)\n"
    "                      (bilinear)\n"
    "  --color R,G,B       albedo for flat, gouraud and phong (0.9,0.6,0.3)\n"
    "  --alpha A           output alpha (1)\n"
    "  --cull MODE         back, front or none (none; back faces lit as front faces, as\n"
    "                      softrast does); --front-face ccw|cw (ccw)\n"
    "  --depth FUNC        less, lequal, equal, greater, gequal, notequal, always, never, off\n"
    "  --blend MODE        opaque, alpha or add (opaque)\n"
    "  --msaa N            1, 2, 4 or 8 samples per pixel: a multisample framebuffer object,\n"
    "                      resolved into the image by glBlitFramebuffer in every frame (1)\n"
    "  --frames N          time N frames after 2 warm-ups; one JSON line on stdout\n"
    "  --threads N         set LP_NUM_THREADS (default: as in the environment)\n"
    "  -q, --quiet         no messages on stderr\n";

float parse_float(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  float v = std::strtof(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v)) {
    usage_error(flag + ": not a number: '" + text + "'");
  }
  return v;
}

int parse_int(const std::string& flag, const std::string& text, int lo, int hi) {
  char* end = nullptr;
  errno = 0;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < lo || v > hi) {
    usage_error(flag + ": expected an integer in " + std::to_string(lo) + ".." +
                std::to_string(hi) + ", got '" + text + "'");
  }
  return int(v);
}

std::vector<float> parse_floats(const std::string& flag, const std::string& text, size_t count) {
  std::vector<float> values;
  size_t start = 0;
  while (true) {
    size_t comma = text.find(',', start);
    values.push_back(parse_float(flag, text.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (values.size() != count) {
    usage_error(flag + ": expected " + std::to_string(count) + " comma-separated numbers");
  }
  return values;
}

glm::vec3 parse_vec3(const std::string& flag, const std::string& text) {
  std::vector<float> v = parse_floats(flag, text, 3);
  return {v[0], v[1], v[2]};
}

void parse_size(const std::string& text, Options& o) {
  size_t x = text.find('x');
  if (x == std::string::npos) usage_error("--size: expected WxH, got '" + text + "'");
  o.width = parse_int("--size", text.substr(0, x), 1, 16384);
  o.height = parse_int("--size", text.substr(x + 1), 1, 16384);
}

void check_choice(const std::string& flag, const std::string& value,
                  std::initializer_list<const char*> choices) {
  for (const char* c : choices) {
    if (value == c) return;
  }
  usage_error(flag + ": unknown value '" + value + "'");
}

// Applies one flag that takes a value; false if `flag` is not such a flag.
bool apply_flag(const std::string& flag, const std::string& value, Options& o) {
  if (flag == "-o" || flag == "--out") {
    o.out = value;
  } else if (flag == "--size") {
    parse_size(value, o);
  } else if (flag == "--eye") {
    o.eye = parse_vec3(flag, value);
  } else if (flag == "--target") {
    o.target = parse_vec3(flag, value);
  } else if (flag == "--up") {
    o.up = parse_vec3(flag, value);
  } else if (flag == "--light") {
    o.light = parse_vec3(flag, value);
    if (!(glm::length(o.light) > 1.0e-6f)) usage_error("--light: the direction must not be zero");
  } else if (flag == "--fov") {
    o.fov = parse_float(flag, value);
  } else if (flag == "--near") {
    o.near_plane = parse_float(flag, value);
  } else if (flag == "--far") {
    o.far_plane = parse_float(flag, value);
  } else if (flag == "--ortho") {
    std::vector<float> v = parse_floats(flag, value, 4);
    o.ortho = glm::vec4(v[0], v[1], v[2], v[3]);
  } else if (flag == "--shader") {
    check_choice(flag, value, {"flat", "gouraud", "texture", "phong", "normals", "wireframe"});
    o.shader = value;
  } else if (flag == "--texture") {
    o.texture = value;
  } else if (flag == "--filter") {
    check_choice(flag, value, {"bilinear", "trilinear"});
    o.trilinear = value == "trilinear";
  } else if (flag == "--color") {
    o.color = parse_vec3(flag, value);
  } else if (flag == "--alpha") {
    o.alpha = parse_float(flag, value);
  } else if (flag == "--cull") {
    check_choice(flag, value, {"back", "front", "none"});
    o.cull = value;
  } else if (flag == "--front-face") {
    check_choice(flag, value, {"ccw", "cw"});
    o.front_face = value;
  } else if (flag == "--depth") {
    check_choice(
        flag, value,
        {"less", "lequal", "equal", "greater", "gequal", "notequal", "always", "never", "off"});
    o.depth = value;
  } else if (flag == "--blend") {
    check_choice(flag, value, {"opaque", "alpha", "add"});
    o.blend = value;
  } else if (flag == "--frames") {
    o.frames = parse_int(flag, value, 1, 1000000);
  } else if (flag == "--threads") {
    o.threads = parse_int(flag, value, 0, 1024);
  } else if (flag == "--msaa") {
    check_choice(flag, value, {"1", "2", "4", "8"});
    o.msaa = std::stoi(value);
  } else {
    return false;
  }
  return true;
}

void check_options(const Options& o) {
  if (o.model.empty()) usage_error("no MODEL given (see --help)");
  if (!o.eye || !o.target) usage_error("--eye and --target are required (no automatic framing)");
  if (!o.near_plane || !o.far_plane) usage_error("--near and --far are required");
  if (!(*o.near_plane < *o.far_plane)) usage_error("--near must be less than --far");
  if (!o.ortho && !(*o.near_plane > 0.0f)) usage_error("--near: must be > 0 with a perspective");
  if (!(o.fov > 0.0f && o.fov < 180.0f)) usage_error("--fov: must be in (0, 180) degrees");
  if (*o.eye == *o.target) usage_error("--eye and --target must differ");
}

// `argv` as `softrast render` reads it ("render" itself is accepted and ignored).
Options parse_args(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    std::string value;
    bool has_value = false;
    if (size_t eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_value = true;
    }
    if (arg == "-h" || arg == "--help") {
      std::fputs(kHelp, stdout);
      std::exit(0);
    }
    if (arg == "-q" || arg == "--quiet") {
      o.quiet = true;
    } else if (arg == "render" && o.model.empty() && i == 1) {
      continue;
    } else if (arg.empty() || arg[0] != '-') {
      if (!o.model.empty()) usage_error("more than one MODEL: '" + arg + "'");
      o.model = arg;
    } else {
      if (!has_value) {
        if (i + 1 >= argc) usage_error(arg + ": needs a value (or unknown flag)");
        value = argv[++i];
      }
      if (!apply_flag(arg, value, o)) usage_error("unknown flag '" + arg + "'");
    }
  }
  check_options(o);
  if (!o.out && o.frames == 0) o.out = "glref.png";
  return o;
}

// ---------------------------------------------------------------------------------------------
// The mesh, as SCENES.md builds it: fan triangulation, one vertex per distinct (v, vt, vn)
// triple in order of first use, missing uvs (0, 0), missing normals the area-weighted sum of the
// face normals around the OBJ position (then normalised; (0, 0, 1) if that sum is zero).

struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  float u, v;
};

struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  size_t triangles() const { return indices.size() / 3; }
};

class MeshBuilder {
 public:
  explicit MeshBuilder(const tinyobj::attrib_t& attrib) : a_(attrib) {}

  void add_face(const tinyobj::index_t* corners, size_t count) {
    for (size_t k = 1; k + 1 < count; ++k) {
      for (size_t c : {size_t(0), k, k + 1}) mesh_.indices.push_back(vertex(corners[c]));
    }
  }

  Mesh finish() {
    if (missing_normals_) smooth_missing_normals();
    return std::move(mesh_);
  }

 private:
  uint32_t vertex(const tinyobj::index_t& c) {
    check_index("position", c.vertex_index, a_.vertices.size() / 3, false);
    check_index("texture coordinate", c.texcoord_index, a_.texcoords.size() / 2, true);
    check_index("normal", c.normal_index, a_.normals.size() / 3, true);
    // Each index fits in 21 bits for any file this tool can hold in memory; +1 maps -1 to 0.
    uint64_t key = uint64_t(c.vertex_index) << 42 | uint64_t(c.texcoord_index + 1) << 21 |
                   uint64_t(c.normal_index + 1);
    auto [it, inserted] = index_of_.try_emplace(key, uint32_t(mesh_.vertices.size()));
    if (!inserted) return it->second;
    size_t p = size_t(c.vertex_index);
    Vertex v{};
    v.position = {a_.vertices[3 * p], a_.vertices[3 * p + 1], a_.vertices[3 * p + 2]};
    if (c.texcoord_index >= 0) {
      size_t t = size_t(c.texcoord_index);
      v.u = a_.texcoords[2 * t];
      v.v = a_.texcoords[2 * t + 1];
    }
    if (c.normal_index >= 0) {
      size_t n = size_t(c.normal_index);
      v.normal = {a_.normals[3 * n], a_.normals[3 * n + 1], a_.normals[3 * n + 2]};
    } else {
      missing_normals_ = true;
    }
    mesh_.vertices.push_back(v);
    position_of_.push_back(c.vertex_index);
    has_normal_.push_back(c.normal_index >= 0);
    return it->second;
  }

  static void check_index(const char* what, int index, size_t count, bool optional) {
    if ((optional && index == -1) || (index >= 0 && size_t(index) < count)) return;
    if (index >= (1 << 21) - 1) failure("too many OBJ elements");
    failure(std::string(what) + " index " + std::to_string(int64_t(index) + 1) +
            " out of range (the file has " + std::to_string(count) + ")");
  }

  void smooth_missing_normals() {
    // Twice the area times the unit normal is the cross product: plain sums weight by area.
    std::vector<glm::dvec3> sums(a_.vertices.size() / 3, glm::dvec3(0.0));
    const std::vector<Vertex>& vs = mesh_.vertices;
    for (size_t t = 0; t + 2 < mesh_.indices.size(); t += 3) {
      const uint32_t* i = &mesh_.indices[t];
      glm::dvec3 p0(vs[i[0]].position), p1(vs[i[1]].position), p2(vs[i[2]].position);
      glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
      for (int k = 0; k < 3; ++k) sums[size_t(position_of_[i[k]])] += n;
    }
    for (size_t v = 0; v < vs.size(); ++v) {
      if (has_normal_[v]) continue;
      glm::dvec3 s = sums[size_t(position_of_[v])];
      double length = glm::length(s);
      bool usable = length > 0.0 && std::isfinite(length);
      mesh_.vertices[v].normal = usable ? glm::vec3(s / length) : glm::vec3(0.0f, 0.0f, 1.0f);
    }
  }

  const tinyobj::attrib_t& a_;
  Mesh mesh_;
  std::unordered_map<uint64_t, uint32_t> index_of_;
  std::vector<int> position_of_;  // per vertex: its OBJ position index
  std::vector<bool> has_normal_;
  bool missing_normals_ = false;
};

Mesh load_mesh(const std::string& path, bool quiet) {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::string dir = fs::path(path).parent_path().string();
  if (!dir.empty()) dir += '/';
  // No triangulation by tinyobj (it splits quads along the shorter diagonal): we fan.
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), dir.c_str(),
                        /*triangulate=*/false, /*default_vcols_fallback=*/false)) {
    while (!err.empty() && std::isspace(static_cast<unsigned char>(err.back()))) err.pop_back();
    failure(path + ": " + (err.empty() ? "cannot read OBJ" : err));
  }
  if (!materials.empty() && !quiet) {
    std::fprintf(stderr, "glref: note: %s: materials ignored (one draw with --color)\n",
                 path.c_str());
  }
  MeshBuilder builder(attrib);
  for (const tinyobj::shape_t& shape : shapes) {
    size_t first = 0;
    for (unsigned char n : shape.mesh.num_face_vertices) {
      builder.add_face(&shape.mesh.indices[first], n);
      first += n;
    }
  }
  Mesh mesh = builder.finish();
  if (mesh.indices.empty()) failure(path + ": no faces");
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// OpenGL through OSMesa.

void check_gl(const char* where) {
  if (GLenum e = glGetError(); e != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", e);
    failure(std::string("OpenGL error ") + code + " in " + where);
  }
}

class Context {
 public:
  Context(int width, int height) : width_(width), height_(height) {
    // clang-format off
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA,
                              OSMESA_DEPTH_BITS, 24,
                              OSMESA_STENCIL_BITS, 0,
                              OSMESA_ACCUM_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION, 3,
                              OSMESA_CONTEXT_MINOR_VERSION, 3,
                              0};
    // clang-format on
    context_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!context_) failure("OSMesaCreateContextAttribs failed (no GL 3.3 core context)");
    buffer_.resize(size_t(width) * size_t(height) * 4);
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      failure("OSMesaMakeCurrent failed for " + std::to_string(width) + "x" +
              std::to_string(height));
    }
    renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (renderer_.find("llvmpipe") == std::string::npos) {
      failure("GL_RENDERER is '" + renderer_ + "', not llvmpipe");
    }
    GLint bits = 0;
    glGetIntegerv(GL_DEPTH_BITS, &bits);
    check_gl("GL_DEPTH_BITS");
    if (bits != 24) failure("depth buffer has " + std::to_string(bits) + " bits, not 24");
  }
  ~Context() { OSMesaDestroyContext(context_); }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& renderer() const { return renderer_; }

  // The image after glFinish, top row first. OSMesa's buffer holds GL's rows bottom-up
  // (OSMESA_Y_UP = 1, checked here), so row y of the PNG is buffer row height - 1 - y.
  std::vector<uint8_t> image_top_down() const {
    GLint y_up = 1;
    OSMesaGetIntegerv(OSMESA_Y_UP, &y_up);
    std::vector<uint8_t> out(buffer_.size());
    size_t row = size_t(width_) * 4;
    for (int y = 0; y < height_; ++y) {
      int source = y_up ? height_ - 1 - y : y;
      std::memcpy(&out[size_t(y) * row], &buffer_[size_t(source) * row], row);
    }
    return out;
  }

 private:
  int width_, height_;
  OSMesaContext context_ = nullptr;
  std::vector<uint8_t> buffer_;
  std::string renderer_;
};

// The shaders of SCENES.md. Attribute locations: 0 position, 1 normal, 2 uv.
constexpr const char* kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_mvp;
uniform vec3 u_albedo;
uniform vec3 u_light;  // normalised, towards the light
#if defined(GOURAUD)
out vec3 v_color;
out vec3 v_back_color;  // two-sided lighting: lit by the flipped normal
#elif defined(TEXTURE)
out vec2 v_uv;
#elif defined(PHONG)
out vec3 v_position;
out vec3 v_normal;
out vec2 v_uv;
#elif defined(NORMALS)
out vec3 v_normal;
#endif
void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
#if defined(GOURAUD)
  float d = max(dot(normalize(a_normal), u_light), 0.0);
  v_color = u_albedo * (0.15 + 0.85 * d);
  float back = max(dot(-normalize(a_normal), u_light), 0.0);
  v_back_color = u_albedo * (0.15 + 0.85 * back);
#elif defined(TEXTURE)
  v_uv = a_uv;
#elif defined(PHONG)
  v_position = a_position;
  v_normal = a_normal;
  v_uv = a_uv;
#elif defined(NORMALS)
  v_normal = a_normal;
#endif
}
)";

constexpr const char* kFragmentShader = R"(
uniform vec3 u_albedo;
uniform float u_alpha;
uniform vec3 u_light;
uniform vec3 u_eye;
uniform bool u_textured;
uniform sampler2D u_texture;
out vec4 o_color;
#if defined(FLAT)
void main() { o_color = vec4(u_albedo, u_alpha); }
#elif defined(GOURAUD)
in vec3 v_color;
in vec3 v_back_color;
void main() { o_color = vec4(gl_FrontFacing ? v_color : v_back_color, u_alpha); }
#elif defined(TEXTURE)
in vec2 v_uv;
void main() {
  vec4 t = texture(u_texture, v_uv);
  o_color = vec4(t.rgb, t.a * u_alpha);
}
#elif defined(PHONG)
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
void main() {
  vec3 n = gl_FrontFacing ? normalize(v_normal) : -normalize(v_normal);  // two-sided
  vec3 v = normalize(u_eye - v_position);
  vec3 h = normalize(u_light + v);
  float d = max(dot(n, u_light), 0.0);
  float s = d > 0.0 ? pow(max(dot(n, h), 0.0), 32.0) : 0.0;
  vec4 base = u_textured ? texture(u_texture, v_uv) : vec4(u_albedo, 1.0);
  o_color = vec4(base.rgb * (0.15 + 0.85 * d) + 0.4 * s, base.a * u_alpha);
}
#elif defined(NORMALS)
in vec3 v_normal;
void main() { o_color = vec4(normalize(v_normal) * 0.5 + 0.5, 1.0); }
#endif
)";

GLuint compile(GLenum stage, const std::string& source) {
  GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    failure(std::string("shader compilation failed: ") + log);
  }
  return shader;
}

GLuint make_program(const std::string& shader_name) {
  // wireframe: the flat shader with glPolygonMode(GL_LINE) (set_state).
  std::string define = shader_name == "wireframe" ? "flat" : shader_name;
  std::transform(define.begin(), define.end(), define.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  std::string header = "#version 330 core\n#define " + define + " 1\n";
  GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, header + kVertexShader));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, header + kFragmentShader));
  glLinkProgram(program);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    failure(std::string("shader linking failed: ") + log);
  }
  return program;
}

// Static buffers, uploaded once: interleaved vertices and uint32 indices in one VAO.
void upload_mesh(const Mesh& mesh) {
  GLuint vao = 0, buffers[2] = {0, 0};
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(2, buffers);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertices.size() * sizeof(Vertex)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  const GLsizei stride = sizeof(Vertex);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(Vertex, normal)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<void*>(offsetof(Vertex, u)));
  check_gl("upload_mesh");
}

// The texture as SCENES.md wants it: RGBA8 (no sRGB), flipped so that v = 0 is the last row of
// the file, GL_LINEAR for both filters without mipmaps, GL_REPEAT. Without --texture, one
// opaque white texel (softrast samples a missing texture as white).
void upload_texture(const std::optional<std::string>& path, bool trilinear) {
  int w = 1, h = 1;
  std::vector<uint8_t> texels = {255, 255, 255, 255};
  if (path) {
    int channels = 0;
    stbi_set_flip_vertically_on_load(1);
    uint8_t* data = stbi_load(path->c_str(), &w, &h, &channels, 4);
    if (!data) failure(*path + ": cannot load image: " + stbi_failure_reason());
    texels.assign(data, data + size_t(w) * size_t(h) * 4);
    stbi_image_free(data);
  }
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                  trilinear ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, trilinear ? 1000 : 0);
  // The chain built once, by the driver's box filter (softrast builds it at load as well).
  if (trilinear) glGenerateMipmap(GL_TEXTURE_2D);
  check_gl("upload_texture");
}

// P * V in float, as gluPerspective (or glOrtho) and gluLookAt define them.
glm::mat4 view_projection(const Options& o) {
  glm::mat4 view = glm::lookAtRH(*o.eye, *o.target, o.up);
  glm::mat4 projection;
  if (o.ortho) {
    glm::vec4 b = *o.ortho;
    projection = glm::orthoRH_NO(b.x, b.y, b.z, b.w, *o.near_plane, *o.far_plane);
  } else {
    float aspect = float(o.width) / float(o.height);
    projection = glm::perspectiveRH_NO(glm::radians(o.fov), aspect, *o.near_plane, *o.far_plane);
  }
  return projection * view;
}

void set_uniforms(GLuint program, const Options& o) {
  glUseProgram(program);
  glm::mat4 mvp = view_projection(o);
  glm::vec3 light = glm::normalize(o.light);
  glUniformMatrix4fv(glGetUniformLocation(program, "u_mvp"), 1, GL_FALSE, glm::value_ptr(mvp));
  glUniform3fv(glGetUniformLocation(program, "u_albedo"), 1, glm::value_ptr(o.color));
  glUniform3fv(glGetUniformLocation(program, "u_light"), 1, glm::value_ptr(light));
  glUniform3fv(glGetUniformLocation(program, "u_eye"), 1, glm::value_ptr(*o.eye));
  glUniform1f(glGetUniformLocation(program, "u_alpha"), o.alpha);
  glUniform1i(glGetUniformLocation(program, "u_textured"), o.texture ? 1 : 0);
  glUniform1i(glGetUniformLocation(program, "u_texture"), 0);
  check_gl("set_uniforms");
}

GLenum depth_func(const std::string& name) {
  static const std::array<std::pair<const char*, GLenum>, 8> kFuncs = {{
      {"less", GL_LESS},
      {"lequal", GL_LEQUAL},
      {"equal", GL_EQUAL},
      {"greater", GL_GREATER},
      {"gequal", GL_GEQUAL},
      {"notequal", GL_NOTEQUAL},
      {"always", GL_ALWAYS},
      {"never", GL_NEVER},
  }};
  for (const auto& [n, f] : kFuncs) {
    if (name == n) return f;
  }
  return GL_LESS;
}

void set_state(const Options& o) {
  glViewport(0, 0, o.width, o.height);
  glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
  glClearDepth(1.0);
  glDepthMask(GL_TRUE);
  if (o.depth == "off") {
    glDisable(GL_DEPTH_TEST);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(depth_func(o.depth));
  }
  glFrontFace(o.front_face == "ccw" ? GL_CCW : GL_CW);
  if (o.cull == "none") {
    glDisable(GL_CULL_FACE);
  } else {
    glEnable(GL_CULL_FACE);
    glCullFace(o.cull == "back" ? GL_BACK : GL_FRONT);
  }
  if (o.blend == "opaque") {
    glDisable(GL_BLEND);
  } else if (o.blend == "alpha") {  // softrast: rgb = s * sa + d * (1 - sa), a = sa + da (1 - sa)
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  } else {  // add
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
  }
  glDisable(GL_DITHER);
  glDisable(GL_MULTISAMPLE);
  glPolygonMode(GL_FRONT_AND_BACK, o.shader == "wireframe" ? GL_LINE : GL_FILL);
  check_gl("set_state");
}

// With --msaa above 1: a framebuffer object with multisample RGBA8 colour and 24-bit depth
// renderbuffers that frames draw into, and the samples the implementation gave it.
struct MultisampleTarget {
  GLuint fbo = 0;
  int width = 0, height = 0;
};
MultisampleTarget g_msaa;

void make_multisample_target(const Options& o) {
  if (o.msaa <= 1) return;
  GLuint buffers[2];
  glGenRenderbuffers(2, buffers);
  glBindRenderbuffer(GL_RENDERBUFFER, buffers[0]);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, o.msaa, GL_RGBA8, o.width, o.height);
  glBindRenderbuffer(GL_RENDERBUFFER, buffers[1]);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, o.msaa, GL_DEPTH_COMPONENT24, o.width,
                                   o.height);
  glGenFramebuffers(1, &g_msaa.fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, g_msaa.fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, buffers[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, buffers[1]);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    failure("the " + std::to_string(o.msaa) + "x multisample framebuffer is incomplete");
  }
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLES, &samples);
  if (samples != o.msaa) {
    failure("asked for " + std::to_string(o.msaa) + " samples, got " + std::to_string(samples));
  }
  glEnable(GL_MULTISAMPLE);
  g_msaa.width = o.width;
  g_msaa.height = o.height;
  check_gl("make_multisample_target");
}

// One frame as SCENES.md defines it: clear colour and depth, one draw, glFinish. Milliseconds.
// Multisampled: the samples are resolved into the image (glBlitFramebuffer) before glFinish.
double render_frame(const Mesh& mesh) {
  auto start = std::chrono::steady_clock::now();
  if (g_msaa.fbo) glBindFramebuffer(GL_FRAMEBUFFER, g_msaa.fbo);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDrawElements(GL_TRIANGLES, GLsizei(mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
  if (g_msaa.fbo) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, g_msaa.fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, g_msaa.width, g_msaa.height, 0, 0, g_msaa.width, g_msaa.height,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glFinish();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Fragments that pass the depth test in one more (untimed) frame.
uint64_t samples_passed(const Mesh& mesh) {
  GLuint query = 0;
  glGenQueries(1, &query);
  glBeginQuery(GL_SAMPLES_PASSED, query);
  render_frame(mesh);
  glEndQuery(GL_SAMPLES_PASSED);
  // GL 3.3, but not among libOSMesa's exported symbols: fetched through OSMesa.
  auto get_result =
      reinterpret_cast<PFNGLGETQUERYOBJECTUI64VPROC>(OSMesaGetProcAddress("glGetQueryObjectui64v"));
  if (!get_result) failure("OSMesa has no glGetQueryObjectui64v");
  GLuint64 count = 0;
  get_result(query, GL_QUERY_RESULT, &count);
  glDeleteQueries(1, &query);
  check_gl("samples_passed");
  return count;
}

std::string fixed3(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3f", v);
  return text;
}

// A JSON string literal (quotes, backslashes and control characters escaped).
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
    } else if (c < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    } else {
      out += char(c);
    }
  }
  return out + "\"";
}

// The keys of softrast's --frames line, then the reference's own.
std::string json_line(const Options& o, const Mesh& mesh, std::vector<double> ms, uint64_t samples,
                      const std::string& gl_renderer) {
  std::sort(ms.begin(), ms.end());
  size_t n = ms.size();
  double median = n % 2 == 1 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  double seconds = std::max(median, 1e-6) / 1000.0;
  double pixels = double(o.width) * double(o.height);
  const char* threads = std::getenv("LP_NUM_THREADS");
  return "{\"scene\":" + json_string(fs::path(o.model).stem().string()) +
         ",\"shader\":" + json_string(o.shader) + ",\"width\":" + std::to_string(o.width) +
         ",\"height\":" + std::to_string(o.height) + ",\"frames\":" + std::to_string(o.frames) +
         ",\"triangles\":" + std::to_string(mesh.triangles()) + ",\"median_ms\":" + fixed3(median) +
         ",\"min_ms\":" + fixed3(ms.front()) + ",\"max_ms\":" + fixed3(ms.back()) +
         ",\"mtris_per_s\":" + fixed3(double(mesh.triangles()) / seconds / 1e6) +
         ",\"mpix_per_s\":" + fixed3(pixels / seconds / 1e6) + ",\"renderer\":\"llvmpipe\"" +
         ",\"gl_renderer\":" + json_string(gl_renderer) +
         ",\"lp_num_threads\":" + json_string(threads ? threads : "default") +
         ",\"samples_passed\":" + std::to_string(samples) + "}";
}

void write_png(const std::string& path, const Options& o, const std::vector<uint8_t>& rgba) {
  if (!stbi_write_png(path.c_str(), o.width, o.height, 4, rgba.data(), o.width * 4)) {
    failure(path + ": cannot write PNG");
  }
}

int run(int argc, char** argv) {
  Options o = parse_args(argc, argv);
  if (o.threads) setenv("LP_NUM_THREADS", std::to_string(*o.threads).c_str(), 1);
  auto log = [&](const std::string& text) {
    if (!o.quiet) std::fprintf(stderr, "glref: %s\n", text.c_str());
  };
  Mesh mesh = load_mesh(o.model, o.quiet);
  Context context(o.width, o.height);
  log(std::string("renderer ") + context.renderer() + ", " + std::to_string(mesh.triangles()) +
      " triangles, " + std::to_string(mesh.vertices.size()) + " vertices");
  upload_mesh(mesh);
  upload_texture(o.texture, o.trilinear);
  set_uniforms(make_program(o.shader), o);
  set_state(o);
  make_multisample_target(o);

  if (o.frames > 0) {
    for (int i = 0; i < kWarmupFrames; ++i) render_frame(mesh);
    std::vector<double> times;
    for (int i = 0; i < o.frames; ++i) times.push_back(render_frame(mesh));
    uint64_t samples = samples_passed(mesh);
    std::string line = json_line(o, mesh, times, samples, context.renderer()) + "\n";
    std::fputs(line.c_str(), stdout);
    std::fflush(stdout);
  } else {
    double ms = render_frame(mesh);
    log("rendered " + std::to_string(o.width) + "x" + std::to_string(o.height) + " in " +
        fixed3(ms) + " ms");
  }
  check_gl("render");
  if (o.out) {
    write_png(*o.out, o, context.image_top_down());
    log("wrote " + *o.out);
  }
  return 0;
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__)
// Under the debug preset's AddressSanitizer: OSMesa keeps a few allocations of
// OSMesaMakeCurrent past OSMesaDestroyContext (Mesa's, not ours), and LeakSanitizer's exit code
// would fail every run.
extern "C" const char* __asan_default_options() {
  return "detect_leaks=0";
}
#endif

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const Failure& f) {
    std::fprintf(stderr, "glref: error: %s\n", f.message.c_str());
    return f.code;
  }
}
