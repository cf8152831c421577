// examples/custom_shader.cpp: drawing with your own vertex and fragment shader.
// A spinning-free, file-free example: a procedurally coloured quad seen in perspective, with a
// fragment shader that discards a circular hole. Writes custom_shader.png.
#include <cstdio>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "softrast/shader.hpp"
#include "softrast/softrast.hpp"

namespace {

// The shader: reads positions by index, passes (u, v) to the fragment stage. The fragment shader
// is written once for a 4x4 block of pixels (softrast::simd types hold one value per pixel) and
// softrast compiles it for SSE2, SSE4, AVX2 and AVX-512, running the widest the CPU has.
struct CheckerHole {
  static constexpr int kVaryings = 2;
  static constexpr bool kDiscards = true;  // it calls f.discard()
  const glm::vec3* positions;
  const glm::vec2* uvs;
  glm::mat4 mvp;

  glm::vec4 vertex(uint32_t i, float* varyings) const {
    varyings[0] = uvs[i].x;
    varyings[1] = uvs[i].y;
    return mvp * glm::vec4(positions[i], 1.0f);
  }

  // SOFTRAST_SIMD_INLINE: compiled inside each SIMD level's block function (see shader.hpp).
  template <int N>
  SOFTRAST_SIMD_INLINE void shade(softrast::Fragments<N>& f) const {
    using F = softrast::simd::Float<N>;
    using I = softrast::simd::Int<N>;
    F du = f.varying(0) - 0.5f, dv = f.varying(1) - 0.5f;
    f.discard(du * du + dv * dv < F(0.04f));  // a hole of radius 0.2
    I cells =
        softrast::simd::to_int(f.varying(0) * 8.0f) + softrast::simd::to_int(f.varying(1) * 8.0f);
    I odd = (cells & I(1)) == I(1);
    f.color = {select(odd, F(0.9f), F(0.2f)), select(odd, F(0.5f), F(0.3f)),
               select(odd, F(0.2f), F(0.5f)), F(1.0f)};
  }
};

}  // namespace

int main(int argc, char** argv) {
  const char* out = argc > 1 ? argv[1] : "custom_shader.png";
  std::vector<glm::vec3> positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  std::vector<glm::vec2> uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  std::vector<uint32_t> indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from above

  softrast::Framebuffer fb(640, 480);
  softrast::Camera camera;
  camera.eye = {0.0f, 1.5f, 2.2f};
  glm::mat4 mvp = camera.view_projection(640.0f / 480.0f);

  softrast::RenderState state;  // back-face culling, depth less, opaque
  softrast::draw(fb, state, CheckerHole{positions.data(), uvs.data(), mvp}, indices,
                 uint32_t(positions.size()));
  softrast::Status written = softrast::save_image(out, fb.to_image());
  if (!written) {
    std::fprintf(stderr, "%s\n", written.message().c_str());
    return 1;
  }
  std::printf("wrote %s\n", out);
  return 0;
}
