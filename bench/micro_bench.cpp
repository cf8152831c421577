// bench/micro_bench.cpp: Google Benchmark micro-benchmarks of each pipeline stage: the vertex
// shader, clipping + setup + culling, coverage, the fragment stage per built-in shader and SIMD
// level, and whole draws (front end only, binning + raster + shading) by thread count.
// Not part of the tests; run build/release/bench/softrast_micro_bench. The speed claims of the
// project are the side-by-side figures against llvmpipe (tools/reference/side_by_side.sh).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "raster/raster.hpp"
#include "raster/setup.hpp"
#include "shaders/builtin_shaders.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

// A grid of small UV spheres facing the camera, like SCENES.md's spheres_1m but smaller.
Mesh sphere_grid(int columns, int rows, int slices, int stacks) {
  Mesh mesh;
  for (int gy = 0; gy < rows; ++gy) {
    for (int gx = 0; gx < columns; ++gx) {
      glm::vec3 centre(float(gx) - columns / 2.0f + 0.5f, float(gy) - rows / 2.0f + 0.5f, 0.0f);
      uint32_t base = uint32_t(mesh.positions.size());
      for (int j = 0; j <= stacks; ++j) {
        float theta = float(M_PI) * float(j) / float(stacks);
        for (int i = 0; i <= slices; ++i) {
          float phi = 2.0f * float(M_PI) * float(i) / float(slices);
          glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta),
                      std::sin(theta) * std::sin(phi));
          mesh.positions.push_back(centre + 0.45f * n);
          mesh.normals.push_back(n);
          mesh.uvs.push_back({float(i) / float(slices), 1.0f - float(j) / float(stacks)});
        }
      }
      for (int j = 0; j < stacks; ++j) {
        for (int i = 0; i < slices; ++i) {
          uint32_t a = base + uint32_t(j * (slices + 1) + i), b = a + uint32_t(slices + 1);
          mesh.indices.insert(mesh.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
      }
    }
  }
  return mesh;
}

// The vertex stage: the built-in Gouraud vertex shader over a mesh's vertices.
// The vertex benchmarks' shader: Gouraud over a grid of spheres (137,808 vertices).
detail::GouraudShader<false> bench_gouraud(const Mesh& mesh) {
  detail::Lighting lighting;
  lighting.light = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
  return {{&mesh, glm::mat4(1.0f)}, glm::vec3(0.9f, 0.6f, 0.3f), lighting, 1.0f, {}};
}

void BM_VertexShader(benchmark::State& state) {
  Mesh mesh = sphere_grid(16, 9, 32, 28);
  const detail::GouraudShader<false> shader = bench_gouraud(mesh);
  std::vector<float> out(mesh.positions.size() * 7);
  for (auto _ : state) {
    for (uint32_t i = 0; i < mesh.positions.size(); ++i) {
      glm::vec4 p = shader.vertex(i, &out[size_t(i) * 7 + 4]);
      out[size_t(i) * 7] = p.x;
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(mesh.positions.size()));
}
BENCHMARK(BM_VertexShader);

// The same vertices through the shader's wide form at the CPU's level (vertex_simd.hpp), as draw
// runs it.
void BM_VertexShaderWide(benchmark::State& state) {
  Mesh mesh = sphere_grid(16, 9, 32, 28);
  using Shader = detail::GouraudShader<false>;
  const Shader shader = bench_gouraud(mesh);
  std::vector<float> out(mesh.positions.size() * 7);
  const detail::ShadeVerticesFn wide = detail::wide_shade_vertices<Shader>(simd_level());
  for (auto _ : state) {
    wide(&shader, nullptr, 0, uint32_t(mesh.positions.size()), out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(mesh.positions.size()));
}
BENCHMARK(BM_VertexShaderWide);

std::vector<detail::WindowVertex> random_window_triangles(int count, float size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(0.0f, 1800.0f), d(-size, size);
  std::vector<detail::WindowVertex> v;
  for (int t = 0; t < count; ++t) {
    float cx = pos(rng), cy = pos(rng) * 0.55f;
    for (int k = 0; k < 3; ++k) {
      detail::WindowVertex w;
      w.x = int32_t((cx + d(rng)) * 256.0f);
      w.y = int32_t((cy + d(rng)) * 256.0f);
      w.z = 0.5f;
      w.inv_w = 1.0f;
      static const float kVaryings[3] = {0.2f, 0.4f, 0.6f};
      w.varyings = kVaryings;
      v.push_back(w);
    }
  }
  return v;
}

// Setup and culling of small random triangles (half of them back-facing).
void BM_Setup(benchmark::State& state) {
  std::vector<detail::WindowVertex> v = random_window_triangles(4096, 3.0f, 1);
  detail::PixelRect scissor{0, 0, 1920, 1080};
  detail::TriangleSetup tri;
  for (auto _ : state) {
    int kept = 0;
    for (size_t t = 0; t + 2 < v.size(); t += 3) {
      kept += detail::setup_triangle(v[t], v[t + 1], v[t + 2], 3, CullMode::kBack,
                                     FrontFace::kCounterClockwise, scissor, tri);
    }
    benchmark::DoNotOptimize(kept);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(v.size() / 3));
}
BENCHMARK(BM_Setup);

// Coverage by edge equations of triangles of a given size (pixels), to a sink that only counts.
void BM_Coverage(benchmark::State& state) {
  float size = float(state.range(0));
  std::vector<detail::WindowVertex> v = random_window_triangles(1024, size, 2);
  std::vector<detail::TriangleSetup> tris;
  detail::PixelRect scissor{0, 0, 1920, 1080};
  for (size_t t = 0; t + 2 < v.size(); t += 3) {
    detail::TriangleSetup tri;
    if (detail::setup_triangle(v[t], v[t + 1], v[t + 2], 0, CullMode::kNone,
                               FrontFace::kCounterClockwise, scissor, tri)) {
      tris.push_back(tri);
    }
  }
  int64_t pixels = 0;
  detail::BlockSink sink{[](void* c, int, int, uint32_t mask) {
                           *static_cast<int64_t*>(c) += __builtin_popcount(mask);
                         },
                         &pixels};
  for (auto _ : state) {
    for (const detail::TriangleSetup& tri : tris) {
      detail::rasterize_triangle_edge_equations(tri, scissor, sink);
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(tris.size()));
  state.counters["pixels_per_triangle"] =
      double(pixels) / double(state.iterations()) / double(tris.size());
}
BENCHMARK(BM_Coverage)->Arg(2)->Arg(10)->Arg(100);

// The fragment stage: a full-screen pair of triangles through each built-in shader, at each
// SIMD level the CPU has (depth test off so that every frame shades every pixel); the texturing
// shaders at AVX2 and AVX-512 with each form of gather too (third argument: GatherMode, or -1 for
// the one chosen on this CPU).
void BM_Shade(benchmark::State& state) {
  ShaderKind kind = ShaderKind(state.range(0));
  SimdLevel level = SimdLevel(state.range(1));
  if (level > cpu_simd_level()) {
    state.SkipWithError("SIMD level not available on this CPU");
    return;
  }
  set_simd_level(level);
  const GatherMode chosen = gather_mode(cpu_simd_level());
  if (state.range(2) >= 0) set_gather_mode(GatherMode(state.range(2)));
  state.SetLabel(std::string("gathers: ") + gather_mode_name(gather_mode(level)));
  Mesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.normals.assign(4, glm::vec3(0, 0, 1));
  quad.uvs = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  Image checker(256, 256);
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) checker.pixel(x, y)[0] = uint8_t(((x ^ y) & 32) ? 230 : 40);
  }
  RenderOptions options;
  options.shader = kind;
  options.texture = std::make_shared<Texture>(Texture::from_image(checker));
  options.state.threads = 1;
  options.state.depth_test = false;
  Camera camera;
  camera.eye = {0.0f, 0.0f, 2.4142f};
  Framebuffer fb(512, 512);
  for (auto _ : state) render_mesh(fb, quad, camera, options);
  state.SetItemsProcessed(int64_t(state.iterations()) * 512 * 512);
  set_simd_level(SimdLevel::kAvx512);
  set_gather_mode(chosen);
}
void shade_args(benchmark::internal::Benchmark* b) {
  for (ShaderKind k :
       {ShaderKind::kFlat, ShaderKind::kGouraud, ShaderKind::kTexture, ShaderKind::kPhong}) {
    for (int level = 0; level < 4; ++level) b->Args({int(k), level, -1});
  }
  for (ShaderKind k : {ShaderKind::kTexture, ShaderKind::kPhong}) {
    for (int level : {int(SimdLevel::kAvx2), int(SimdLevel::kAvx512)}) {
      for (GatherMode mode : {GatherMode::kInstruction, GatherMode::kLoads}) {
        b->Args({int(k), level, int(mode)});
      }
    }
  }
}
BENCHMARK(BM_Shade)->Apply(shade_args);

// A plane of columns x rows quads (two triangles each) filling the view of `camera`, counter-
// clockwise (front-facing) or, with `reversed`, clockwise (all back-facing).
Mesh plane_grid(int columns, int rows, bool reversed) {
  Mesh mesh;
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= columns; ++i) {
      mesh.positions.push_back(
          {(float(i) / columns - 0.5f) * 3.2f, (float(j) / rows - 0.5f) * 1.8f, 0});
      mesh.normals.push_back({0, 0, 1});
      mesh.uvs.push_back({float(i) / columns, float(j) / rows});
    }
  }
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      uint32_t a = uint32_t(j * (columns + 1) + i), b = a + uint32_t(columns + 1);
      if (reversed) {
        mesh.indices.insert(mesh.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
      } else {
        mesh.indices.insert(mesh.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
      }
    }
  }
  return mesh;
}

// The benchmark's frames: `mesh` cleared and drawn with Gouraud shading at 1280x720 on `threads`
// threads, the camera on +z framing plane_grid's 3.2 x 1.8 plane.
void render_frames(benchmark::State& state, const Mesh& mesh, int threads) {
  RenderOptions options;
  options.shader = ShaderKind::kGouraud;
  options.state.threads = threads;
  Camera camera;
  camera.eye = {0.0f, 0.0f, 0.9f / 0.4142f};
  Framebuffer fb(1280, 720);
  for (auto _ : state) {
    fb.clear();
    render_mesh(fb, mesh, camera, options);
  }
}

// Whole draws of 230 k triangles of about 4 pixels at 1280x720: the front end alone (vertex
// shading, clipping, setup and culling: every triangle is back-facing), then everything
// (binning, coverage, deferred Gouraud shading), by threads.
void BM_Draw(benchmark::State& state) {
  bool front_end_only = state.range(0) != 0;
  static const Mesh visible = plane_grid(320, 360, false), culled = plane_grid(320, 360, true);
  const Mesh& mesh = front_end_only ? culled : visible;
  render_frames(state, mesh, int(state.range(1)));
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(mesh.triangle_count()));
}
BENCHMARK(BM_Draw)
    ->ArgNames({"front_end_only", "threads"})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({0, 1})
    ->Args({0, 2})
    ->UseRealTime();

// A scene of many small draws over one vertex array (an OBJ with a material per quad): the
// fixed cost of a draw. Each draw once shaded the whole array's vertices, which made such scenes
// quadratic in their size; `draws` quads of 1280x720, two threads.
void BM_ManyDraws(benchmark::State& state) {
  const int draws = int(state.range(0));
  Mesh mesh = plane_grid(draws / 10, 10, false);
  for (uint32_t quad = 0; quad < uint32_t(draws); ++quad) {
    mesh.submeshes.push_back({quad * 6, 6, -1});
  }
  render_frames(state, mesh, 2);
  state.SetItemsProcessed(int64_t(state.iterations()) * draws);
}
BENCHMARK(BM_ManyDraws)->ArgName("draws")->Arg(1000)->Arg(10000)->UseRealTime();

}  // namespace
}  // namespace softrast

BENCHMARK_MAIN();
