// tools/reference/glconform.cpp: the llvmpipe side of the conformance classes
// (tests/conformance_test.cpp). Reads many small cases from one file and draws each with OpenGL
// 3.3 core on Mesa's llvmpipe (through OSMesa) in this one process, because starting llvmpipe
// costs far more than drawing a 64x64 case. Shares no code with softrast.
//
//   glconform CASES.txt OUT.bin [--mirror-y]
//
// CASES.txt, text, one case after another (floats in C99 hex, so both sides read the same bits):
//   case W H MODE PRIMITIVE N            MODE: count, colour, texture, depth;
//                                         PRIMITIVE: triangles or lines; N vertices follow
//   [texture FILTER LEVELS               only for MODE texture; FILTER bilinear or trilinear;
//    level W H HEX...]                   LEVELS lines of RGBA8 texels, rows bottom-up, in hex
//   v X Y Z W R G B A U V                N lines: clip-space position, colour, texture coordinate
// MODE count: additive blending of 1/255 in red (red = hits), no depth test;
//      colour: the interpolated colour, opaque; texture: the texture at (U, V), GL_REPEAT;
//      depth: GL_LESS with depth writes, red.
// Clear: colour 0, depth 1. OUT.bin: per case W*H RGBA8 pixels, top row first, then W*H uint32
// depth values of the 24-bit depth buffer (0 .. 2^24 - 1), top row first.
//
// --mirror-y draws every case with y negated and reads the rows without flipping them: the same
// image, but each tie on a horizontal edge goes to the other side. llvmpipe breaks those ties
// bottom-left as seen top row first (see README.md here); mirrored, that becomes the top-left
// rule of softrast's CONVENTIONS.md, so coverage can be compared exactly.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Failure {
  std::string message;
};

[[noreturn]] void fail(const std::string& message) {
  throw Failure{message};
}

void check_gl(const char* where) {
  if (GLenum e = glGetError(); e != GL_NO_ERROR) {
    fail(std::string("OpenGL error ") + std::to_string(e) + " in " + where);
  }
}

struct Level {
  int width = 0, height = 0;
  std::vector<uint8_t> texels;
};

struct Case {
  int width = 0, height = 0;
  std::string mode, primitive, filter;
  std::vector<float> vertices;  // 10 per vertex
  std::vector<Level> levels;
};

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  fail(std::string("not a hex digit: ") + c);
}

bool read_case(std::istream& in, Case& c) {
  std::string word;
  if (!(in >> word)) return false;
  size_t n = 0;
  if (word != "case" || !(in >> c.width >> c.height >> c.mode >> c.primitive >> n)) {
    fail("expected 'case W H MODE PRIMITIVE N'");
  }
  if (c.width < 1 || c.height < 1 || c.width > 4096 || c.height > 4096) fail("bad size");
  c.levels.clear();
  if (c.mode == "texture") {
    int levels = 0;
    if (!(in >> word >> c.filter >> levels) || word != "texture" || levels < 1 || levels > 16) {
      fail("expected 'texture FILTER LEVELS'");
    }
    for (int l = 0; l < levels; ++l) {
      Level level;
      std::string hex;
      if (!(in >> word >> level.width >> level.height >> hex) || word != "level" ||
          hex.size() != size_t(level.width) * size_t(level.height) * 8) {
        fail("expected 'level W H HEX'");
      }
      level.texels.resize(hex.size() / 2);
      for (size_t i = 0; i < level.texels.size(); ++i) {
        level.texels[i] = uint8_t(hex_digit(hex[2 * i]) * 16 + hex_digit(hex[2 * i + 1]));
      }
      c.levels.push_back(std::move(level));
    }
  } else if (c.mode != "count" && c.mode != "colour" && c.mode != "depth") {
    fail("unknown mode '" + c.mode + "'");
  }
  if (c.primitive != "triangles" && c.primitive != "lines") fail("unknown primitive");
  c.vertices.resize(n * 10);
  for (size_t i = 0; i < n; ++i) {
    if (!(in >> word) || word != "v") fail("expected 'v'");
    for (int k = 0; k < 10; ++k) {
      std::string text;
      in >> text;
      char* end = nullptr;
      c.vertices[i * 10 + k] = std::strtof(text.c_str(), &end);
      if (text.empty() || *end != '\0') fail("bad number '" + text + "'");
    }
  }
  return true;
}

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec4 a_position;
layout(location = 1) in vec4 a_color;
layout(location = 2) in vec2 a_uv;
uniform float u_mirror;
out vec4 v_color;
out vec2 v_uv;
void main() {
  v_color = a_color;
  v_uv = a_uv;
  gl_Position = vec4(a_position.x, a_position.y * u_mirror, a_position.z, a_position.w);
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec4 v_color;
in vec2 v_uv;
uniform int u_mode;  // 0 count, 1 colour, 2 texture, 3 depth
uniform sampler2D u_texture;
out vec4 o_color;
void main() {
  if (u_mode == 0) o_color = vec4(1.0 / 255.0, 0.0, 0.0, 0.0);
  else if (u_mode == 1) o_color = v_color;
  else if (u_mode == 2) o_color = texture(u_texture, v_uv);
  else o_color = vec4(1.0, 0.0, 0.0, 1.0);
}
)";

GLuint compile(GLenum stage, const char* source) {
  GLuint shader = glCreateShader(stage);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    fail(std::string("shader compilation failed: ") + log);
  }
  return shader;
}

int run(int argc, char** argv) {
  if (argc < 3 || argc > 4 || (argc == 4 && std::strcmp(argv[3], "--mirror-y") != 0)) {
    std::fprintf(stderr, "usage: glconform CASES.txt OUT.bin [--mirror-y]\n");
    return 2;
  }
  bool mirror = argc == 4;
  std::ifstream in(argv[1]);
  if (!in) fail(std::string("cannot read ") + argv[1]);
  std::FILE* out = std::fopen(argv[2], "wb");
  if (!out) fail(std::string("cannot write ") + argv[2]);

  // One context for every case; each case makes its own buffer of its size current.
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_STENCIL_BITS,
                            0,
                            OSMESA_ACCUM_BITS,
                            0,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  OSMesaContext context = OSMesaCreateContextAttribs(attributes, nullptr);
  if (!context) fail("OSMesaCreateContextAttribs failed (no GL 3.3 core context)");
  std::vector<uint8_t> buffer(64 * 64 * 4);
  if (!OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, 64, 64)) {
    fail("OSMesaMakeCurrent failed");
  }
  std::string renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (renderer.find("llvmpipe") == std::string::npos) fail("GL_RENDERER is not llvmpipe");

  GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, kVertexShader));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, kFragmentShader));
  glLinkProgram(program);
  GLint linked = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!linked) fail("program link failed");
  glUseProgram(program);
  glUniform1f(glGetUniformLocation(program, "u_mirror"), mirror ? -1.0f : 1.0f);
  glUniform1i(glGetUniformLocation(program, "u_texture"), 0);
  GLint mode_location = glGetUniformLocation(program, "u_mode");

  GLuint vao = 0, vbo = 0, texture = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 40, reinterpret_cast<void*>(0));
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 40, reinterpret_cast<void*>(16));
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 40, reinterpret_cast<void*>(32));
  for (GLuint a = 0; a < 3; ++a) glEnableVertexAttribArray(a);
  glGenTextures(1, &texture);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClearDepth(1.0);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DITHER);
  check_gl("setup");

  Case c;
  std::vector<uint8_t> image;
  std::vector<uint32_t> depth, depth_out;
  while (read_case(in, c)) {
    buffer.assign(size_t(c.width) * size_t(c.height) * 4, 0);
    if (!OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, c.width, c.height)) {
      fail("OSMesaMakeCurrent failed");
    }
    glViewport(0, 0, c.width, c.height);
    int mode = c.mode == "count" ? 0 : c.mode == "colour" ? 1 : c.mode == "texture" ? 2 : 3;
    glUniform1i(mode_location, mode);
    if (mode == 0) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_ONE, GL_ONE);
    } else {
      glDisable(GL_BLEND);
    }
    if (mode == 3) {
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
      glDepthMask(GL_TRUE);
    } else {
      glDisable(GL_DEPTH_TEST);
    }
    if (mode == 2) {
      for (size_t l = 0; l < c.levels.size(); ++l) {
        const Level& level = c.levels[l];
        glTexImage2D(GL_TEXTURE_2D, GLint(l), GL_RGBA8, level.width, level.height, 0, GL_RGBA,
                     GL_UNSIGNED_BYTE, level.texels.data());
      }
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, GLint(c.levels.size()) - 1);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                      c.filter == "trilinear" ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    }
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(c.vertices.size() * sizeof(float)), c.vertices.data(),
                 GL_STREAM_DRAW);
    glDrawArrays(c.primitive == "lines" ? GL_LINES : GL_TRIANGLES, 0,
                 GLsizei(c.vertices.size() / 10));
    size_t pixels = size_t(c.width) * size_t(c.height);
    depth.resize(pixels);
    glReadPixels(0, 0, c.width, c.height, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, depth.data());
    glFinish();
    check_gl("draw");

    // OSMesa's buffer and glReadPixels hold GL's rows bottom-up; mirrored, they are top-down.
    GLint y_up = 1;
    OSMesaGetIntegerv(OSMESA_Y_UP, &y_up);
    image.resize(pixels * 4);
    depth_out.resize(pixels);
    size_t row = size_t(c.width) * 4;
    for (int y = 0; y < c.height; ++y) {
      int colour_row = (y_up && !mirror) ? c.height - 1 - y : y;
      int depth_row = mirror ? y : c.height - 1 - y;
      std::memcpy(&image[size_t(y) * row], &buffer[size_t(colour_row) * row], row);
      for (int x = 0; x < c.width; ++x) {
        depth_out[size_t(y) * c.width + x] = depth[size_t(depth_row) * c.width + x] >> 8;
      }
    }
    if (std::fwrite(image.data(), 1, image.size(), out) != image.size() ||
        std::fwrite(depth_out.data(), 4, pixels, out) != pixels) {
      fail(std::string("cannot write ") + argv[2]);
    }
  }
  if (std::fclose(out) != 0) fail(std::string("cannot write ") + argv[2]);
  OSMesaDestroyContext(context);
  return 0;
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__)
// OSMesa keeps allocations past OSMesaDestroyContext (Mesa's, not ours); see glref.cpp.
extern "C" const char* __asan_default_options() {
  return "detect_leaks=0";
}
#endif

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const Failure& f) {
    std::fprintf(stderr, "glconform: error: %s\n", f.message.c_str());
    return 1;
  }
}
