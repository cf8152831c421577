// softrast/render_state.hpp: the fixed-function state of a draw: culling, depth, blending and
// the choice of rasterization algorithm. Plain values; every combination is valid.
#pragma once

#include <vector>

namespace softrast {

enum class Primitive { kTriangles, kLines, kPoints };
enum class CullMode { kNone, kBack, kFront };
// Which winding, as seen in the image, is front-facing (OpenGL's default is counter-clockwise).
enum class FrontFace { kCounterClockwise, kClockwise };
enum class DepthFunc {
  kNever,
  kLess,
  kEqual,
  kLessEqual,
  kGreater,
  kNotEqual,
  kGreaterEqual,
  kAlways
};
// kOpaque writes the source; kAlpha is "over" (src * a + dst * (1 - a)); kAdditive is src + dst.
enum class BlendMode { kOpaque, kAlpha, kAdditive };
// Two triangle rasterizers with identical coverage: edge equations over tiles (the default) and
// edge walking over scanlines (a second, independent implementation of the same rules).
enum class RasterAlgorithm { kEdgeEquations, kScanline };

// Time spent on each 64x64 tile by the binned path (the `cost` debug view). A draw whose state
// points to one adds each tile's rasterization and shading time, in seconds, to `seconds`
// (row-major, tiles_x * tiles_y); a draw with a different grid starts it again from zeros.
// Lines, points and the reference path are not timed.
struct TileTimes {
  int tiles_x = 0, tiles_y = 0;
  std::vector<double> seconds;
  void clear() {
    tiles_x = tiles_y = 0;
    seconds.clear();
  }
};

struct RenderState {
  Primitive primitive = Primitive::kTriangles;
  CullMode cull = CullMode::kBack;
  FrontFace front_face = FrontFace::kCounterClockwise;
  bool depth_test = true;  // false: every fragment passes and depth is not written
  DepthFunc depth_func = DepthFunc::kLess;
  bool depth_write = true;
  BlendMode blend = BlendMode::kOpaque;
  RasterAlgorithm raster = RasterAlgorithm::kEdgeEquations;
  // Triangles drawn as their three edges (glPolygonMode GL_LINE), after culling.
  bool wireframe = false;
  // Added to every window depth before the depth test (like a polygon offset in depth units);
  // a small negative value lets a wireframe overlay win against its own filled surface.
  float depth_bias = 0.0f;
  // glPolygonOffset for triangles drawn as edges (wireframe): each edge's depth moves by
  // factor * m + units * 2^-24, where m is the triangle's largest depth slope in depth units per
  // pixel, max(|dz/dx|, |dz/dy|). Negative values pull the edges towards the viewer, so that an
  // overlay drawn over its own filled triangles keeps every pixel while hidden edges stay hidden.
  float polygon_offset_factor = 0.0f;
  float polygon_offset_units = 0.0f;
  // Samples per pixel for filled triangles: 1, 2, 4 or 8 (other values draw as 1). Above 1, each
  // triangle's coverage and depth are tested per sample at the standard Direct3D / Vulkan sample
  // positions, the fragment shader runs once per pixel and covered triangle (at the pixel
  // centre), its colour goes to the covered samples that pass the depth test, and the pixels are
  // the samples' average (see Framebuffer::multisample). Lines, points and wireframe are drawn
  // single-sampled. 1 is the single-sampled path, bit for bit.
  int samples = 1;
  // Threads a draw may use: 0 for every hardware thread. The image is the same for every value.
  int threads = 0;
  // The slow, obviously correct oracle: one thread, every primitive set up, rasterized and shaded
  // immediately in submission order (no binning, no deferred shading, `threads` ignored). The
  // tests hold the fast paths to its image and depth bit for bit.
  bool reference_path = false;
  // Optional per-tile timing (see TileTimes); null: nothing is timed. Each tile is written by
  // one thread at a time, so the pointee needs no locking, but two draws must not share it
  // concurrently.
  TileTimes* tile_times = nullptr;
};

}  // namespace softrast
