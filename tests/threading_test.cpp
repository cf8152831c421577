// The binned path (one thread or several) against the single-threaded reference path
// (RenderState::reference_path): the same image, bit for bit, for every thread count, including
// order-dependent blending across batches.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "softrast/detail/parallel.hpp"
#include "softrast/renderer.hpp"
#include "softrast/shader.hpp"

namespace softrast {
namespace {

// Triangles given in clip space, each with its own colour (flat per triangle via three
// vertices of the same colour).
struct SoupShader {
  static constexpr int kVaryings = 4;
  const glm::vec4* positions;
  const glm::vec4* colors;
  glm::vec4 vertex(uint32_t i, float* v) const {
    v[0] = colors[i].r, v[1] = colors[i].g, v[2] = colors[i].b, v[3] = colors[i].a;
    return positions[i];
  }
  bool fragment(FragmentInput& in, glm::vec4& out) const {
    out = in.vec4(0);
    return true;
  }
};

struct Soup {
  std::vector<glm::vec4> positions, colors;
  std::vector<uint32_t> indices;
};

// `count` random triangles, some crossing the near plane and the image border, semi-transparent
// so that the result depends on the order in which each pixel sees them.
Soup random_soup(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.4f, 1.4f), depth(-1.2f, 1.0f), unit(0.0f, 1.0f),
      size(0.02f, 0.6f);
  Soup soup;
  for (int t = 0; t < count; ++t) {
    glm::vec2 centre(pos(rng), pos(rng));
    float s = size(rng);
    glm::vec4 color(unit(rng), unit(rng), unit(rng), 0.3f + 0.6f * unit(rng));
    for (int k = 0; k < 3; ++k) {
      float w = 0.5f + 2.0f * unit(rng);
      glm::vec2 p = centre + s * glm::vec2(unit(rng) - 0.5f, unit(rng) - 0.5f);
      soup.positions.push_back(glm::vec4(p * w, depth(rng) * w, w));
      soup.colors.push_back(color);
      soup.indices.push_back(uint32_t(soup.indices.size()));
    }
  }
  return soup;
}

// threads = 0 draws with the reference path. The default size is not a multiple of the tile
// size.
std::vector<uint32_t> render_soup(const Soup& soup, RenderState state, int threads, int width = 301,
                                  int height = 187) {
  Framebuffer fb(width, height);
  state.threads = threads;
  state.reference_path = threads == 0;
  SoupShader shader{soup.positions.data(), soup.colors.data()};
  draw(fb, state, shader, soup.indices, uint32_t(soup.positions.size()));
  std::vector<uint32_t> out;
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) out.push_back(fb.color_at(x, y));
  }
  return out;
}

TEST(Threading, BlendedSoupIsIdenticalForEveryThreadCount) {
  // 40,000 triangles: more than two batches of the binned path.
  Soup soup = random_soup(40000, 7);
  for (BlendMode blend : {BlendMode::kAlpha, BlendMode::kAdditive, BlendMode::kOpaque}) {
    for (RasterAlgorithm raster : {RasterAlgorithm::kEdgeEquations, RasterAlgorithm::kScanline}) {
      RenderState state;
      state.cull = CullMode::kNone;
      state.depth_test = blend == BlendMode::kOpaque;
      state.blend = blend;
      state.raster = raster;
      std::vector<uint32_t> reference = render_soup(soup, state, 0);
      for (int threads : {1, 2, 3, 8}) {
        EXPECT_TRUE(render_soup(soup, state, threads) == reference)
            << "blend " << int(blend) << " raster " << int(raster) << " threads " << threads;
      }
    }
  }
}

// The binned path keeps its bins and arenas from draw to draw on a thread, and clears only the
// tiles a chunk's last draw reached: draws of other scenes, other sizes (more tiles, then fewer,
// then more again) and other states on the same thread must leave nothing behind for the next.
TEST(Threading, DrawsAfterOtherSizesAndScenesMatchTheReference) {
  const Soup many = random_soup(40000, 11), few = random_soup(300, 12);
  RenderState opaque;  // deferrable: the tiles' box areas are summed too
  opaque.cull = CullMode::kNone;
  RenderState blended = opaque;
  blended.depth_test = false;
  blended.blend = BlendMode::kAlpha;
  struct Step {
    const Soup* soup;
    const RenderState* state;
    int width, height;
  };
  const Step steps[] = {{&many, &opaque, 701, 517},  {&few, &blended, 61, 40},
                        {&many, &blended, 301, 187}, {&few, &opaque, 701, 517},
                        {&many, &opaque, 130, 700},  {&few, &blended, 701, 517}};
  for (int threads : {1, 2}) {
    for (const Step& step : steps) {
      EXPECT_TRUE(render_soup(*step.soup, *step.state, threads, step.width, step.height) ==
                  render_soup(*step.soup, *step.state, 0, step.width, step.height))
          << step.width << "x" << step.height << " threads " << threads;
    }
  }
}

TEST(Threading, DemoSceneIsIdenticalForEveryThreadCount) {
  DemoScene scene = make_demo_scene();
  for (ShaderKind kind : {ShaderKind::kPhong, ShaderKind::kTexture, ShaderKind::kDepth}) {
    RenderOptions options;
    options.shader = kind;
    options.wireframe_overlay = kind == ShaderKind::kPhong;
    std::vector<std::vector<uint8_t>> images;
    for (int threads : {0, 1, 2, 5}) {  // 0: the reference path
      options.state.threads = threads;
      options.state.reference_path = threads == 0;
      Framebuffer fb(333, 250);
      render_mesh(fb, scene.mesh, scene.camera, options);
      images.push_back(fb.to_image().rgba);
    }
    for (size_t i = 1; i < images.size(); ++i) {
      EXPECT_TRUE(images[i] == images[0]) << shader_kind_name(kind) << " run " << i;
    }
  }
}

// parallel_slot, which the binned draw hands its jobs out by: every thread of a parallel_for has
// a place below its thread count, no two threads share one, the calling thread's is 0, and a
// thread keeps its place from one parallel_for to the next.
TEST(Threading, ParallelSlotIsAStablePlacePerThread) {
  const int threads = std::min(4, detail::hardware_threads());
  EXPECT_EQ(detail::parallel_slot(), 0);
  std::mutex mutex;
  std::map<std::thread::id, int> place_of;
  std::map<int, std::thread::id> thread_at;
  for (int round = 0; round < 50; ++round) {
    detail::parallel_for(64, threads, [&](size_t) {
      const int place = detail::parallel_slot();
      // Long enough that the pool's workers join in.
      std::this_thread::sleep_for(std::chrono::microseconds(20));
      std::lock_guard lock(mutex);
      EXPECT_GE(place, 0);
      EXPECT_LT(place, threads);
      auto [it, added] = place_of.emplace(std::this_thread::get_id(), place);
      EXPECT_EQ(it->second, place) << "a thread changed its place";
      auto [at, new_place] = thread_at.emplace(place, std::this_thread::get_id());
      EXPECT_EQ(at->second, std::this_thread::get_id()) << "two threads share place " << place;
    });
  }
  EXPECT_EQ(place_of[std::this_thread::get_id()], 0);
  if (threads > 1) {
    EXPECT_GT(place_of.size(), 1u) << "the pool's workers never ran";
  }
}

}  // namespace
}  // namespace softrast
