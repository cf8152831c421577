// The binned draw reuses its memory: once a scene has been drawn, drawing it again into a
// framebuffer of the same size allocates nothing (vertex arrays, record arenas, bins, tile
// scratch all keep their capacity). Counted with a replacement of the global operator new, which
// counts for the whole test binary and otherwise behaves as the standard one.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <utility>
#include <vector>

#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"

namespace {
std::atomic<long> g_allocations{0};

void* counted_allocation(std::size_t size, std::size_t alignment) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = alignment <= alignof(std::max_align_t)
                ? std::malloc(size)
                : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t size) {
  return counted_allocation(size, 0);
}
void* operator new[](std::size_t size) {
  return counted_allocation(size, 0);
}
void* operator new(std::size_t size, std::align_val_t a) {
  return counted_allocation(size, std::size_t(a));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return counted_allocation(size, std::size_t(a));
}
// The nothrow forms too (std::stable_sort's temporary buffer uses them): otherwise the runtime's
// own operator new allocates what the replaced operator delete frees with std::free, which
// AddressSanitizer reports as an alloc-dealloc mismatch.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_allocation(size, 0);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_allocation(size, 0);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace softrast {
namespace {

// Constant colour; `resolved` blocks are shaded with the depth test off (see deferred_test.cpp).
struct Flat {
  static constexpr int kVaryings = 3;
  glm::vec4 vertex(uint32_t, float*) const { return {}; }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    out = glm::vec4(in.vec3(0), 1.0f);
    return true;
  }
};
void flat_block(const void* shader, const detail::ShadeTarget& target,
                const detail::Interpolants& in, int x, int y, uint32_t mask) {
  if (!target.resolved) return detail::shade_block<Flat>(shader, target, in, x, y, mask);
  RenderState state = *target.state;
  state.depth_test = false;
  detail::ShadeTarget plain{target.framebuffer, &state, false};
  detail::shade_block<Flat>(shader, plain, in, x, y, mask);
}

TEST(Allocation, TheCounterCounts) {
  long before = g_allocations.load();
  Framebuffer fb(8, 8);
  EXPECT_EQ(g_allocations.load() - before, 3);  // colour, depth and the tiles' pending clears
}

TEST(Allocation, SecondFrameOfTheSameSceneAllocatesNothing) {
  // 40,000 triangles (two batches), small and large, some crossing the near plane (clipped).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), pos(-1.3f, 1.3f);
  std::vector<float> clip;
  std::vector<uint32_t> indices;
  for (int t = 0; t < 40000; ++t) {
    float size = t % 100 == 0 ? 1.0f : 0.02f;
    float cx = pos(rng), cy = pos(rng);
    for (int k = 0; k < 3; ++k) {
      float w = 0.5f + unit(rng), z = t % 50 == 0 ? -1.5f + 2.0f * unit(rng) : unit(rng) - 0.5f;
      float x = cx + size * (unit(rng) - 0.5f), y = cy + size * (unit(rng) - 0.5f);
      for (float f : {x * w, y * w, z * w, w, unit(rng), unit(rng), unit(rng)}) clip.push_back(f);
      indices.push_back(uint32_t(indices.size()));
    }
  }
  detail::ClipVertices vertices{clip.data(), indices.size(), 7, 3};
  Flat shader;
  // Single-sampled with and without deferred shading, then 4 samples (its own triangle list, bins
  // and sample buffers).
  for (auto [samples, deferrable] : {std::pair{1, false}, {1, true}, {4, false}}) {
    RenderState state;
    state.cull = CullMode::kNone;
    state.samples = samples;
    detail::FragmentProgram program{&flat_block, &shader, deferrable};
    Framebuffer fb(640, 360);
    auto frame = [&](int threads) {
      state.threads = threads;
      fb.clear();
      detail::draw_clip_space(fb, state, vertices, indices.data(), indices.size(), program);
    };
    for (int threads : {1, 2, 1, 2}) frame(threads);
    // Thread counts alternating, as an application may: the caches serve both.
    long before = g_allocations.load();
    for (int threads : {1, 2, 1}) frame(threads);
    EXPECT_EQ(g_allocations.load() - before, 0) << samples << " samples, deferrable " << deferrable;
  }
}

// The same through the renderer for a textured scene: the demo scene (its textures, the floor
// sampled trilinearly) with the texture shader and phong, bilinear and trilinear. The first
// frame builds what the draws keep (the mip chains, the textures' row pairs, the bins); the
// frames after it allocate nothing.
TEST(Allocation, LaterFramesOfATexturedSceneAllocateNothing) {
  DemoScene demo = make_demo_scene();
  Image checker(64, 64);
  for (size_t k = 0; k < checker.rgba.size(); ++k) checker.rgba[k] = uint8_t(k * 37 + k / 256);
  for (ShaderKind shader : {ShaderKind::kTexture, ShaderKind::kPhong}) {
    for (Filter filter : {Filter::kBilinear, Filter::kTrilinear}) {
      RenderOptions options;
      options.shader = shader;
      options.sampler.filter = filter;
      options.texture = std::make_shared<const Texture>(Texture::from_image(checker));
      options.state.cull = CullMode::kBack;
      Framebuffer fb(320, 240);
      options.state.threads = 2;
      auto frame = [&] {
        fb.clear();
        render_mesh(fb, demo.mesh, demo.camera, options);
      };
      frame();
      long before = g_allocations.load();
      for (int k = 0; k < 3; ++k) frame();
      EXPECT_EQ(g_allocations.load() - before, 0)
          << shader_kind_name(shader) << ", filter " << int(filter);
    }
  }
}

}  // namespace
}  // namespace softrast
