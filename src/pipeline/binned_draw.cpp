// pipeline/binned_draw.cpp: filled triangles on several threads, in two phases per batch.
//   1. Geometry: the batch is cut into chunks of consecutive triangles; each chunk (one thread at
//      a time) clips and sets up its triangles and appends each setup's index to the bin of
//      every 64x64 tile its bounds touch.
//   2. Raster: each tile (one thread at a time) walks the bins of all chunks in chunk order, so
//      every pixel sees its triangles in submission order and blending stays order-correct; the
//      tile is the raster region, so no two threads ever touch the same pixel.
// The image equals the single-threaded path's bit for bit: setup is the same function, and the
// rasterizers give the same coverage whatever region a triangle is cut into.
#include <algorithm>
#include <memory>
#include <vector>

#include "pipeline/draw_internal.hpp"
#include "pipeline/tile_visibility.hpp"
#include "softrast/detail/parallel.hpp"

namespace softrast::detail {
namespace {

// Triangles per batch: bounds the setups held at once (a setup is about 350 bytes).
constexpr size_t kBatchTriangles = 16384;
// Chunks per thread in the geometry phase, for load balance when clipping is uneven.
constexpr int kChunksPerThread = 4;

// A thread's scratch for deferred tiles, allocated once per thread and reused by every draw.
struct DeferredScratch {
  TileVisibility visibility;
  std::vector<const Interpolants*> interps;  // by id: the tile's triangles in submission order
};

DeferredScratch& deferred_scratch() {
  thread_local std::unique_ptr<DeferredScratch> scratch;
  if (!scratch) scratch = std::make_unique<DeferredScratch>();
  return *scratch;
}

// The rasterizer's blocks of one triangle into the tile's depth resolve.
struct ResolveSink {
  TileVisibility* visibility;
  ResolveBlockFn kernel;
  bool less_equal;
  DepthPlaneRef plane;
  int32_t id;

  static void emit(void* self, int x, int y, uint32_t mask) {
    auto* s = static_cast<ResolveSink*>(self);
    TileVisibility& v = *s->visibility;
    int b = v.block(x, y);
    s->kernel(s->plane, x, y, mask, s->id, s->less_equal, v.depth[b], v.id[b]);
  }
};

struct Chunk {
  std::vector<TriangleSetup> setups;
  std::vector<std::vector<uint32_t>> bins;  // per tile: indices into setups
};

class BinnedDraw {
 public:
  BinnedDraw(const GeometryStage& geometry, const RenderState& state, const ShadeTarget& target,
             const FragmentProgram& program, int threads)
      : geometry_(geometry), state_(state), target_(target), program_(program), threads_(threads) {
    deferred_ = deferred_shading_applies(state, program);
    if (deferred_) resolve_kernel_ = resolve_block_kernel();
    const PixelRect& s = geometry.scissor();
    tiles_x_ = (s.x1 + kTileSize - 1) / kTileSize;
    tiles_y_ = (s.y1 + kTileSize - 1) / kTileSize;
    chunks_.resize(size_t(threads) * kChunksPerThread);
    for (Chunk& c : chunks_) c.bins.resize(size_t(tiles_x_) * size_t(tiles_y_));
  }

  void draw(const uint32_t* indices, size_t index_count) {
    size_t triangles = index_count / 3;
    for (size_t first = 0; first < triangles; first += kBatchTriangles) {
      size_t count = std::min(kBatchTriangles, triangles - first);
      size_t per_chunk = (count + chunks_.size() - 1) / chunks_.size();
      parallel_for(chunks_.size(), threads_, [&](size_t c) {
        size_t begin = first + c * per_chunk;
        size_t end = std::min(first + count, begin + per_chunk);
        setup_chunk(chunks_[c], indices, begin, end);
      });
      parallel_for(size_t(tiles_x_) * size_t(tiles_y_), threads_, [&](size_t tile) {
        deferred_ ? resolve_and_shade_tile(tile) : raster_tile(tile);
      });
    }
  }

 private:
  void setup_chunk(Chunk& chunk, const uint32_t* indices, size_t begin, size_t end) {
    chunk.setups.clear();
    for (std::vector<uint32_t>& bin : chunk.bins) bin.clear();
    auto on_triangle = [&](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
      chunk.setups.emplace_back();
      TriangleSetup& tri = chunk.setups.back();
      if (!setup_triangle(a, b, c, geometry_.num_varyings(), state_.cull, state_.front_face,
                          geometry_.scissor(), tri)) {
        chunk.setups.pop_back();
        return;
      }
      bin(chunk, tri.bounds, uint32_t(chunk.setups.size() - 1));
    };
    for (size_t t = begin; t < end; ++t) {
      const uint32_t* i = indices + 3 * t;
      if (geometry_.valid(i[0]) && geometry_.valid(i[1]) && geometry_.valid(i[2])) {
        geometry_.triangle(i[0], i[1], i[2], on_triangle);
      }
    }
  }

  void bin(Chunk& chunk, const PixelRect& bounds, uint32_t id) {
    int tx0 = bounds.x0 / kTileSize, tx1 = (bounds.x1 - 1) / kTileSize;
    int ty0 = bounds.y0 / kTileSize, ty1 = (bounds.y1 - 1) / kTileSize;
    for (int ty = ty0; ty <= ty1; ++ty) {
      for (int tx = tx0; tx <= tx1; ++tx) chunk.bins[size_t(ty) * tiles_x_ + tx].push_back(id);
    }
  }

  PixelRect tile_region(size_t tile) const {
    int tx = int(tile % size_t(tiles_x_)), ty = int(tile / size_t(tiles_x_));
    PixelRect region{tx * kTileSize, ty * kTileSize, (tx + 1) * kTileSize, (ty + 1) * kTileSize};
    return intersect(region, geometry_.scissor());
  }

  // Immediate shading: every block of every triangle goes to the fragment stage as it comes.
  void raster_tile(size_t tile) {
    PixelRect region = tile_region(tile);
    Shading shading(program_, target_);
    for (const Chunk& chunk : chunks_) {
      for (uint32_t id : chunk.bins[tile]) {
        const TriangleSetup& tri = chunk.setups[id];
        rasterize_triangle(tri, state_.raster, region, shading.sink(tri.interp));
      }
    }
  }

  // Deferred shading (tile_visibility.hpp): visibility of all the tile's triangles first, in
  // submission order, then one shading call per block and winning triangle.
  void resolve_and_shade_tile(size_t tile) {
    PixelRect region = tile_region(tile);
    DeferredScratch& scratch = deferred_scratch();
    TileVisibility& visibility = scratch.visibility;
    visibility.begin(*target_.framebuffer, region);
    scratch.interps.clear();
    ResolveSink sink{&visibility, resolve_kernel_, state_.depth_func == DepthFunc::kLessEqual, {}, 0};
    for (const Chunk& chunk : chunks_) {
      for (uint32_t id : chunk.bins[tile]) {
        const TriangleSetup& tri = chunk.setups[id];
        sink.plane = {tri.interp.x_ref, tri.interp.y_ref, tri.interp.z};
        sink.id = int32_t(scratch.interps.size());
        scratch.interps.push_back(&tri.interp);
        rasterize_triangle(tri, state_.raster, region, BlockSink{&ResolveSink::emit, &sink});
      }
    }
    visibility.store_depth();
    ShadeTarget resolved = target_;
    resolved.resolved = true;
    shade_winners(visibility, scratch.interps.data(), program_, resolved);
    visibility.reset();
  }

  const GeometryStage& geometry_;
  const RenderState& state_;
  bool deferred_ = false;
  ResolveBlockFn resolve_kernel_ = nullptr;
  ShadeTarget target_;
  const FragmentProgram& program_;
  int threads_;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<Chunk> chunks_;
};

}  // namespace

void draw_triangles_binned(const GeometryStage& geometry, const RenderState& state,
                           const ShadeTarget& target, const FragmentProgram& program,
                           const uint32_t* indices, size_t index_count, int threads) {
  BinnedDraw(geometry, state, target, program, threads).draw(indices, index_count);
}

}  // namespace softrast::detail
