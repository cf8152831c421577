// pipeline/binned_draw.cpp: filled triangles binned into 64x64 tiles, on the calling thread alone
// or on several.
//   0. Vertices (in parallel): each vertex's outcode and, inside the clip volume, its snapped
//      window position, once per vertex instead of once per triangle corner.
//   1. Geometry, per batch of triangles: the batch is cut into chunks of consecutive triangles;
//      each chunk (one thread at a time) trivially accepts triangles whose three vertices are
//      inside the clip volume (guard band, near, far) and clips the others, culls by the snapped
//      area, sets up a compact record (triangle_record.hpp) in the chunk's arena and appends its
//      offset to the bin of every tile its bounds touch. At AVX2 and AVX-512 the accept, the cull,
//      the coverage (edges, bounds) and the planes take 8 or 16 triangles at once
//      (triangle_kernels.hpp).
//   2. Raster: each tile (one thread at a time) walks the bins of all chunks in chunk order, so
//      every pixel sees its triangles in submission order and blending stays order-correct; the
//      tile is the raster region, so no two threads ever touch the same pixel. Deferrable draws
//      resolve the tile's visibility first and shade each visible pixel once (tile_visibility.hpp).
// The image equals the reference path's bit for bit: setup is the same code, the window vertices
// the same function of the clip vertex, the tile kernels' coverage that of the edge-equation
// rasterizer, and the depth resolve the fragment stage's arithmetic.
//
// Memory: the per-vertex arrays, the arenas and the bins live in a cache of the calling thread
// and keep their capacity, so after the first frame of a scene a draw allocates nothing. Bins
// hold offsets into their chunk's arena rather than copies of the records: a triangle touching
// many tiles is stored once, and a tile still reads each chunk's records in increasing address
// order.
#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "core/prefetch.hpp"
#include "pipeline/draw_internal.hpp"
#include "pipeline/record_transpose.hpp"
#include "pipeline/tile_kernels.hpp"
#include "pipeline/tile_visibility.hpp"
#include "pipeline/triangle_kernels.hpp"
#include "pipeline/triangle_record.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/framebuffer.hpp"

namespace softrast::detail {
namespace {

static_assert(Framebuffer::kTileSize == kTileSize && Framebuffer::kBlockSize == kBlockSize,
              "the framebuffer stores the binning tiles contiguously");

// Triangles per batch: bounds the records held at once (184 bytes each for 3 varyings).
constexpr size_t kBatchTriangles = 32768;
// Chunks per thread in the geometry phase, for load balance when clipping is uneven.
constexpr int kChunksPerThread = 4;
// The fewest triangles a chunk takes: a draw of few triangles gets fewer chunks (one below 256).
// Every chunk clears and every raster phase reads each tile's bin of every chunk, a fixed cost
// per draw that made eight chunks of a one-triangle draw cost more than its triangle (a scene of
// 10,000 such draws).
constexpr size_t kMinChunkTriangles = 256;
// How many groups of triangles ahead of the kernel setup_chunk prefetches their varyings (1, 4
// and 8 measured the same as 2).
constexpr size_t kPrefetchGroups = 2;
// How far ahead of its records add_group asks for the arena's lines for writing, with several
// threads. A chunk's arena was last read by the tiles of every thread, so its lines sit in the
// other core's cache, and each store to one waited for that copy to be invalidated: with two
// threads write_records took 2.3 times its one-thread time (spheres_1m gouraud, AVX-512). Asked
// for ahead (PREFETCHW: for writing), the invalidations overlap.
constexpr size_t kArenaWriteAhead = 4096;
// ... and of one index in four: neighbouring triangles share most of their vertices, and a step
// of four takes each corner in turn (spheres_1m, one thread: 3 % faster than every index; one
// in two or three measured the same as four).
constexpr size_t kPrefetchStep = 4;

// Cache-line aligned: each chunk's arena and bins are written by one thread while neighbours are
// written by others.
struct alignas(64) Chunk {
  RecordArena records;
  std::vector<std::vector<uint32_t>> bins;  // per tile: offsets of its records in `records`
  // The tiles whose bins hold records, in the order they got their first (capacity: every tile,
  // so it never grows during a draw). A batch of small triangles reaches a few dozen of the
  // image's tiles: clearing the bins and listing the batch's tiles visit these alone, not every
  // bin of every chunk (BinnedDraw::order_tiles).
  std::vector<uint32_t> touched;
  // Per tile (deferrable draws): the area of its records' bounding boxes clipped to it.
  std::vector<int64_t> box_area;
  size_t place = 0;  // the thread that set it up (parallel_slot)
};

// A thread place's next jobs in a phase (BinnedDraw::run_phase), on a cache line of its own.
struct alignas(64) PlaceCounters {
  std::atomic<size_t> chunk{0};  // its next chunk: place + this times the places
  std::atomic<size_t> tile{0};   // its next tile in DrawCache::place_tiles
};

// A tile worker's scratch for the draws that may defer (deferred tiles, and the batch of the
// immediate ones).
struct DeferredScratch {
  TileVisibility visibility;
  BlockBatch batch;                          // immediate tiles' held blocks (empty between tiles)
  std::vector<const Interpolants*> interps;  // by id: the tile's triangles in submission order
};

// What a draw reuses from the previous draw on the same thread.
struct DrawCache {
  WindowVertices vertices;
  std::vector<Chunk> chunks;
  std::vector<std::unique_ptr<DeferredScratch>> scratch;  // per tile worker
  // (~bit width of the tile's record count, tile): the busiest class first, in tile order
  std::vector<std::pair<uint32_t, uint32_t>> tile_order;
  // Per thread place (run_phase): the tiles it takes first, busiest first, and its counters.
  std::vector<std::vector<uint32_t>> place_tiles;
  std::vector<size_t> place_records;  // scratch: a tile's records set up by each place
  // order_tiles: per tile, the last listing that took it (a tile touched by several chunks is
  // listed once), and that listing's number.
  std::vector<uint32_t> tile_listed;
  uint32_t listing = 0;
  std::unique_ptr<PlaceCounters[]> counters;
  size_t num_counters = 0;
};

DrawCache& draw_cache() {
  thread_local DrawCache cache;
  return cache;
}

// The scanline rasterizer's blocks of one triangle into the tile's depth resolve.
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

class BinnedDraw {
 public:
  BinnedDraw(const GeometryStage& geometry, const RenderState& state, const ShadeTarget& target,
             const FragmentProgram& program, int threads)
      : geometry_(geometry),
        state_(state),
        target_(target),
        program_(program),
        threads_(threads),
        cache_(draw_cache()) {
    deferred_ = deferred_shading_applies(state, program);
    kernels_ = tile_kernels(simd_level());
    triangle_kernel_ = triangle_kernel(simd_level());
    scanline_ = state.raster == RasterAlgorithm::kScanline;
    prefetch_writes_ = threads != 1 && prefetch_for_write_supported();
    record_bytes_ = record_bytes(geometry.num_varyings(), scanline_);
    const PixelRect& s = geometry.scissor();
    tiles_x_ = (s.x1 + kTileSize - 1) / kTileSize;
    tiles_y_ = (s.y1 + kTileSize - 1) / kTileSize;
    max_chunks_ = threads == 1 ? 1 : size_t(threads) * kChunksPerThread;
    if (TileTimes* t = state.tile_times; t && (t->tiles_x != tiles_x_ || t->tiles_y != tiles_y_)) {
      t->tiles_x = tiles_x_;
      t->tiles_y = tiles_y_;
      t->seconds.assign(size_t(tiles_x_) * size_t(tiles_y_), 0.0);
    }
  }

  void draw(const uint32_t* indices, size_t index_count) {
    cache_.vertices.transform(geometry_, threads_);
    size_t triangles = index_count / 3;
    size_t batches = (triangles + kBatchTriangles - 1) / kBatchTriangles;
    // With several threads and batches, batch b's setup runs in the same parallel phase as batch
    // b - 1's raster, into the other half of the chunks: half the phases, and a worker that ends
    // its share of one early takes jobs of the other instead of waiting at the phase's end. Each
    // tile still draws the batches in order (batch b's raster is a phase after batch b - 1's).
    // One thread, or one batch, gains nothing from it: setup, then raster.
    const bool overlap = threads_ > 1 && batches > 1;
    const size_t sets = overlap ? 2 : 1;
    num_chunks_ = std::clamp<size_t>(
        (std::min(triangles, kBatchTriangles) + kMinChunkTriangles - 1) / kMinChunkTriangles, 1,
        max_chunks_);
    // The cache keeps the most chunks any draw used (one thread needs one), so alternating
    // thread counts does not free and reallocate arenas.
    if (cache_.chunks.size() < sets * num_chunks_) cache_.chunks.resize(sets * num_chunks_);
    const size_t tiles = size_t(tiles_x_) * size_t(tiles_y_);
    for (size_t c = 0; c < sets * num_chunks_; ++c) {
      cache_.chunks[c].bins.resize(tiles);
      cache_.chunks[c].touched.reserve(tiles);
      cache_.chunks[c].box_area.resize(deferred_ ? tiles : 0);
    }
    if (cache_.tile_listed.size() < tiles) cache_.tile_listed.resize(tiles, cache_.listing);
    auto setup_of = [&](size_t b) {
      SetupJobs jobs;
      jobs.indices = indices;
      jobs.first = b * kBatchTriangles;
      jobs.count = std::min(kBatchTriangles, triangles - jobs.first);
      jobs.per_chunk = (jobs.count + num_chunks_ - 1) / num_chunks_;
      jobs.chunks = cache_.chunks.data() + (b % sets) * num_chunks_;
      return jobs;
    };
    for (size_t b = 0; b < batches; ++b) {
      if (!overlap) {
        run_phase(setup_of(b), false);
        raster_chunks_ = cache_.chunks.data();
        run_phase(SetupJobs{}, true);
        continue;
      }
      if (b == 0) run_phase(setup_of(0), false);
      raster_chunks_ = cache_.chunks.data() + (b % sets) * num_chunks_;
      run_phase(b + 1 < batches ? setup_of(b + 1) : SetupJobs{}, true);
    }
  }

 private:
  // A batch's geometry jobs: chunk c sets up triangles [first + c * per_chunk, ...) of the batch
  // into chunks[c] (none when `chunks` is null).
  struct SetupJobs {
    const uint32_t* indices = nullptr;
    size_t first = 0, count = 0, per_chunk = 0;
    Chunk* chunks = nullptr;
  };

  // Phase 1 for one chunk.
  void setup_chunk(Chunk& chunk, const uint32_t* indices, size_t begin, size_t end) {
    chunk.records.clear();
    // Only the tiles it touched last time hold anything (those past a smaller image's tiles went
    // with the resize; box_area is summed where records are binned, in the same tiles).
    for (uint32_t tile : chunk.touched) {
      if (tile < chunk.bins.size()) chunk.bins[tile].clear();
      if (tile < chunk.box_area.size()) chunk.box_area[tile] = 0;
    }
    chunk.touched.clear();
    auto add = [&](const WindowVertex& a, const WindowVertex& b, const WindowVertex& c) {
      add_triangle(chunk, a, b, c);
    };
    auto keep = [&](int64_t area) { return kept(area); };
    const WindowVertices& vertices = cache_.vertices;
    // The SIMD kernel takes groups of triangles (triangle_kernels.hpp); the triangles it leaves to
    // the scalar path go there in their place, so the records keep submission order.
    const size_t n = vertices.size();
    if (triangle_kernel_.fn != nullptr && n != 0 && n < (size_t(1) << 31) / 6) {
      TriangleBatch batch;
      batch.indices = indices;
      batch.vertex_count = n;
      batch.window = vertices.window();
      batch.cull = state_.cull;
      batch.front_face = state_.front_face;
      batch.scissor = geometry_.scissor();
      batch.varyings = geometry_.varyings(0);
      batch.stride = geometry_.stride();
      batch.num_varyings = geometry_.num_varyings();
      TriangleLanes lanes;
      const size_t width = size_t(triangle_kernel_.lanes);
      // Groups of set-up triangles only, at least four of them, take write_records
      // (record_transpose.hpp; below four, field by field was fewer instructions), where the
      // records hold no vertices and at most kMaxTransposedVaryings varyings.
      const bool transposed = !scanline_ && batch.num_varyings <= kMaxTransposedVaryings;
      alignas(32) std::byte scratch[kMaxTransposedBytes];
      // A group's triangles as records, in lane order: the set-up ones (planes made), and those
      // the kernel left to the scalar path (triangle t + l) through it, in their place.
      auto emit = [&](const TriangleLanes& g, size_t t) {
        const uint32_t ready = g.ready, two = ready & (ready - 1), three = two & (two - 1);
        if (transposed && (g.scalar | g.scalar_planes) == 0 && (three & (three - 1)) != 0) {
          add_group(chunk, g, int(width), scratch);
          return;
        }
        for (uint32_t todo = g.ready | g.scalar; todo != 0; todo &= todo - 1) {
          int l = __builtin_ctz(todo);
          if ((g.scalar >> l) & 1u) {
            vertices.triangle(geometry_, indices + 3 * (t + size_t(l)), keep, add);
          } else {
            add_set_up(chunk, g, l);
          }
        }
      };
      // The set-up triangles of consecutive groups gathered into full groups before their planes
      // and records are made (triangle_kernels.hpp): on a dense closed mesh about 40 % of the
      // lanes are culled or dropped, and the planes and the record transpose cost the same for a
      // lane that is not ready. A group with a lane for the scalar path ends the gathering (what
      // is gathered goes first), so the records keep submission order.
      const bool gather = transposed && triangle_kernel_.append != nullptr;
      TriangleLanes full{};  // (vertex 0 in the lanes not yet used: every lane's loads are valid)
      int filled = 0;
      auto flush = [&] {
        if (filled == 0) return;
        triangle_kernel_.finish(batch, full);
        emit(full, 0);
        full.ready = 0;
        filled = 0;
      };
      for (size_t t = begin; t < end; t += width) {
        // The varyings of the group after next, prefetched: the kernel reads them late in its
        // work, each vertex's from wherever its index points, and a miss there stalled the
        // group (spheres_1m gouraud, one thread, AVX-512: 32.4 -> 27.4 ms a frame). The window
        // vertices, read first, gain nothing from it. (A draw without varyings has none to fetch.)
        if (const size_t ahead = t + kPrefetchGroups * width;
            batch.num_varyings > 0 && ahead < end) {
          const uint32_t* ahead_indices = indices + 3 * ahead;
          const size_t m = 3 * std::min(width, end - ahead);
          for (size_t j = 0; j < m; j += kPrefetchStep) {
            if (ahead_indices[j] < n) {
              prefetch_line(batch.varyings + size_t(ahead_indices[j]) * batch.stride);
            }
          }
        }
        const int count = int(std::min(width, end - t));
        if (!gather) {
          triangle_kernel_.fn(batch, t, count, lanes);
          emit(lanes, t);
          continue;
        }
        triangle_kernel_.select(batch, t, count, lanes);
        if (lanes.scalar != 0) {
          flush();
          triangle_kernel_.finish(batch, lanes);
          emit(lanes, t);
          continue;
        }
        const uint32_t ready = lanes.ready;
        const int k = __builtin_popcount(ready), room = int(width) - filled;
        if (k < room) {
          triangle_kernel_.append(lanes, ready, full, filled);
          filled += k;
          continue;
        }
        uint32_t rest = ready;  // the lanes past the first `room`
        for (int i = 0; i < room; ++i) rest &= rest - 1;
        triangle_kernel_.append(lanes, ready & ~rest, full, filled);
        filled = int(width);
        flush();
        triangle_kernel_.append(lanes, rest, full, 0);
        filled = k - room;
      }
      flush();
      return;
    }
    for (size_t t = begin; t < end; ++t) vertices.triangle(geometry_, indices + 3 * t, keep, add);
  }

  // The records of a group whose ready lanes are all set up by the kernel, planes included, in
  // one stretch of the arena, in lane order; then their places in the bins.
  void add_group(Chunk& chunk, const TriangleLanes& lanes, int width, std::byte* scratch) {
    // The records, and the edges of those that have them: the specks whose blocks the kernel
    // found go without (TriRecord). (Counted by loops: this file is built for the baseline, where
    // __builtin_popcount is a call into libgcc.)
    uint32_t with_edges = 0;
    size_t count = 0, edge_count = 0;
    for (uint32_t m = lanes.ready; m != 0; m &= m - 1) {
      const int l = __builtin_ctz(m);
      const bool edges = (lanes.blocks[0][l] | lanes.blocks[1][l]) == 0;
      with_edges |= uint32_t(edges) << l;
      ++count;
      edge_count += edges;
    }
    const size_t bytes = count * record_bytes_ + edge_count * sizeof(RecordEdges);
    const uint32_t first = chunk.records.allocate(bytes, kRecordSlack);
    std::byte* const data = reinterpret_cast<std::byte*>(chunk.records.at(first));
    std::byte* dest[TriangleLanes::kMaxLanes];
    std::byte* edges[TriangleLanes::kMaxLanes];
    for (int l = 0; l < width; ++l) dest[l] = edges[l] = scratch;
    std::byte* to = data;
    uint32_t offsets[TriangleLanes::kMaxLanes];
    for (uint32_t todo = lanes.ready; todo != 0; todo &= todo - 1) {
      const int l = __builtin_ctz(todo);
      if ((with_edges >> l) & 1u) {
        edges[l] = to;
        to += sizeof(RecordEdges);
      }
      dest[l] = to;
      offsets[l] = first + uint32_t(to - data);
      to += record_bytes_;
    }
    // The lines kArenaWriteAhead on, for writing: see kArenaWriteAhead.
    if (prefetch_writes_) chunk.records.prefetch_for_write(first + kArenaWriteAhead, to - data);
    GroupTiles tiles;
    write_records(lanes, width, geometry_.num_varyings(), state_.front_face, dest, edges, tiles_x_,
                  tiles);
    const bool box_area = !chunk.box_area.empty();
    for (uint32_t todo = lanes.ready; todo != 0; todo &= todo - 1) {
      const int l = __builtin_ctz(todo);
      const uint32_t offset = offsets[l];
      auto bounds = [&] {
        return PixelRect{lanes.bounds[0][l], lanes.bounds[1][l], lanes.bounds[2][l],
                         lanes.bounds[3][l]};
      };
      if ((tiles.spans >> l) & 1u) {
        bin(chunk, bounds(), offset);
      } else if (box_area) {
        bin_in_tile(chunk, tiles.tile[l], bounds(), offset);
      } else {
        push(chunk, tiles.tile[l], offset);
      }
    }
  }

  // Room for a record with its edges (TriRecord); returns the offset of its header.
  uint32_t allocate_with_edges(Chunk& chunk) {
    return chunk.records.allocate(sizeof(RecordEdges) + record_bytes_) +
           uint32_t(sizeof(RecordEdges));
  }

  // A triangle that the SIMD kernel set up (lane l): its record, as add_triangle makes it.
  void add_set_up(Chunk& chunk, const TriangleLanes& lanes, int l) {
    const uint32_t offset = allocate_with_edges(chunk);
    TriRecord* rec = chunk.records.at(offset);  // every field is written below
    write_coverage(lanes, l, rec);
    if (scanline_) {
      int32_t* v = rec->vertices(geometry_.num_varyings());
      for (int k = 0; k < 3; ++k) v[k] = lanes.x[k][l], v[3 + k] = lanes.y[k][l];
    }
    if ((lanes.scalar_planes >> l) & 1u) {
      WindowVertex v[3];
      for (int k = 0; k < 3; ++k) v[k] = cache_.vertices.vertex(geometry_, lanes.vertex[k][l]);
      const WindowVertex* ordered[3] = {&v[0], &v[1], &v[2]};
      finish_record(chunk, offset, ordered, lanes.area[l]);
      return;
    }
    write_planes(lanes, l, geometry_.num_varyings(), state_.front_face, rec->interp());
    bin(chunk, rec->bounds, offset);
  }

  // Both paths end here: the record's interpolants (from the clockwise-ordered vertices) and its
  // place in the bins, once its coverage is written.
  void finish_record(Chunk& chunk, uint32_t offset, const WindowVertex* const ordered[3],
                     int64_t area) {
    TriRecord* rec = chunk.records.at(offset);
    setup_triangle_interpolants(ordered, geometry_.num_varyings(), area, state_.front_face,
                                rec->interp());
    bin(chunk, rec->bounds, offset);
  }

  // Whether a triangle of snapped signed area `area` survives culling (zero area never does).
  bool kept(int64_t area) const {
    return area != 0 && !is_culled(area, state_.cull, state_.front_face);
  }

  void add_triangle(Chunk& chunk, const WindowVertex& a, const WindowVertex& b,
                    const WindowVertex& c) {
    // Clipped pieces are culled here; accepted triangles were, before their vertices were made
    // (setup_chunk), and the check passes them again. The area is needed below either way.
    int64_t area = signed_area_fx16(a, b, c);
    if (!kept(area)) return;
    TriangleCoverage t;
    const WindowVertex* ordered[3];
    if (!setup_triangle_coverage(a, b, c, area, geometry_.scissor(), t, ordered)) return;
    const uint32_t offset = allocate_with_edges(chunk);
    // TriRecord is an implicit-lifetime aggregate living in allocated bytes; every field is
    // written below.
    TriRecord* rec = chunk.records.at(offset);
    rec->set_edges(t.edge);
    rec->bounds = t.bounds;
    auto extent = [](const int32_t v[3]) {
      return int64_t(std::max({v[0], v[1], v[2]})) - std::min({v[0], v[1], v[2]});
    };
    rec->small = extent(t.vx) <= kSmallTriangleFx8 && extent(t.vy) <= kSmallTriangleFx8;
    rec->blocks = 0;
    if (scanline_) {
      int32_t* v = rec->vertices(geometry_.num_varyings());
      for (int k = 0; k < 3; ++k) v[k] = t.vx[k], v[3 + k] = t.vy[k];
    }
    finish_record(chunk, offset, ordered, area);
  }

  // Inline, for the usual triangle of a dense mesh: one tile, all of it; the rest out of line
  // (with it inline too, the function kept six registers saved and restored per record).
  void bin(Chunk& chunk, const PixelRect& bounds, uint32_t offset) {
    // The bounds lie inside the scissor: no coordinate is negative.
    int tx0 = int(unsigned(bounds.x0) / kTileSize), tx1 = int(unsigned(bounds.x1 - 1) / kTileSize);
    int ty0 = int(unsigned(bounds.y0) / kTileSize), ty1 = int(unsigned(bounds.y1 - 1) / kTileSize);
    if (tx0 != tx1 || ty0 != ty1) {
      bin_tiles(chunk, bounds, offset, tx0, ty0, tx1, ty1);
      return;
    }
    bin_in_tile(chunk, size_t(ty0) * tiles_x_ + tx0, bounds, offset);
  }

  // A record's offset into tile `tile`'s bin (Chunk::touched lists the tile on its first).
  static void push(Chunk& chunk, size_t tile, uint32_t offset) {
    std::vector<uint32_t>& bin = chunk.bins[tile];
    if (bin.empty()) chunk.touched.push_back(uint32_t(tile));
    bin.push_back(offset);
  }

  // bin() for a triangle whose bounds lie in one tile.
  void bin_in_tile(Chunk& chunk, size_t tile, const PixelRect& bounds, uint32_t offset) {
    push(chunk, tile, offset);
    if (!chunk.box_area.empty()) {
      chunk.box_area[tile] += int64_t(bounds.x1 - bounds.x0) * (bounds.y1 - bounds.y0);
    }
  }

  // bin() for a triangle whose bounds span tiles [tx0, tx1] x [ty0, ty1].
  [[gnu::noinline]] void bin_tiles(Chunk& chunk, const PixelRect& bounds, uint32_t offset, int tx0,
                                   int ty0, int tx1, int ty1) {
    for (int ty = ty0; ty <= ty1; ++ty) {
      for (int tx = tx0; tx <= tx1; ++tx) push(chunk, size_t(ty) * tiles_x_ + tx, offset);
    }
    if (chunk.box_area.empty()) return;
    // The bounds lie inside the scissor, so clipped to the tile they are clipped to its region.
    for (int ty = ty0; ty <= ty1; ++ty) {
      int64_t h = std::min(bounds.y1, (ty + 1) * kTileSize) - std::max(bounds.y0, ty * kTileSize);
      for (int tx = tx0; tx <= tx1; ++tx) {
        int64_t w = std::min(bounds.x1, (tx + 1) * kTileSize) - std::max(bounds.x0, tx * kTileSize);
        chunk.box_area[size_t(ty) * tiles_x_ + tx] += w * h;
      }
    }
  }

  PixelRect tile_region(size_t tile) const {
    int tx = int(tile % size_t(tiles_x_)), ty = int(tile / size_t(tiles_x_));
    PixelRect region{tx * kTileSize, ty * kTileSize, (tx + 1) * kTileSize, (ty + 1) * kTileSize};
    return intersect(region, geometry_.scissor());
  }

  // One parallel phase: the chunks of `setup` (phase 1), then, when `raster`, the tiles of the
  // batch in raster_chunks_ (phase 2). Each job has a place (parallel_slot, a thread that keeps
  // it from phase to phase): chunk k the place k modulo the workers, a tile the place that set
  // up most of its records. A worker takes its own place's chunks, then any chunk left, then its
  // own tiles, then any tile left, until none is left; the tiles of each place busiest first.
  // So most records are read by the thread that wrote them, from its own cache, and a chunk's
  // arena is rewritten by the thread that wrote it last (with every job taken by whoever came
  // first, the record writes and reads that crossed between the threads made spheres_1m phong
  // 4 % and quad_grid texture 2 % slower at two threads). Each worker has its own scratch in the
  // cache (not one per thread), so what is allocated does not depend on which thread ran which
  // tile.
  void run_phase(const SetupJobs& setup, bool raster) {
    const size_t setup_jobs = setup.chunks != nullptr ? num_chunks_ : 0;
    std::vector<std::pair<uint32_t, uint32_t>>& order = cache_.tile_order;
    order.clear();
    if (raster) order_tiles();
    const size_t jobs = setup_jobs + order.size();
    if (jobs == 0) return;
    const size_t workers = std::min<size_t>(size_t(threads_), jobs);
    if (raster && deferred_) {
      // A tile holds at most every record of the batch once (each takes record_bytes_ or more).
      size_t records = 0;
      for (const Chunk& c : chunks()) records += c.records.used() / record_bytes_;
      if (cache_.scratch.size() < workers) cache_.scratch.resize(workers);
      for (size_t w = 0; w < workers; ++w) {
        if (!cache_.scratch[w]) cache_.scratch[w] = std::make_unique<DeferredScratch>();
        if (cache_.scratch[w]->interps.size() < records) cache_.scratch[w]->interps.resize(records);
      }
    }
    place_jobs(workers);
    const std::vector<std::vector<uint32_t>>& tiles = cache_.place_tiles;
    PlaceCounters* counters = cache_.counters.get();
    constexpr size_t kNone = SIZE_MAX;
    // The next job for place `me`: below setup_jobs a chunk, else setup_jobs + a tile.
    auto take = [&](size_t me) {
      for (size_t i = 0, p = me; i < workers; ++i, p = p + 1 == workers ? 0 : p + 1) {
        size_t k = p + workers * counters[p].chunk.fetch_add(1, std::memory_order_relaxed);
        if (k < setup_jobs) return k;
      }
      for (size_t i = 0, p = me; i < workers; ++i, p = p + 1 == workers ? 0 : p + 1) {
        size_t j = counters[p].tile.fetch_add(1, std::memory_order_relaxed);
        if (j < tiles[p].size()) return setup_jobs + tiles[p][j];
      }
      return kNone;
    };
    parallel_for(workers, threads_, [&](size_t worker) {
      const size_t me = size_t(parallel_slot()) % workers;
      // Each worker takes its next job before doing the current one, so that a next tile's
      // framebuffer lines are on their way while this one is drawn (a pair per block drawn, the
      // rest at the end).
      TilePrefetch ahead;
      size_t following = take(me);
      for (size_t k = following; k != kNone; k = following) {
        following = take(me);
        if (k < setup_jobs) {
          size_t begin = std::min(setup.first + setup.count, setup.first + k * setup.per_chunk);
          size_t end = std::min(setup.first + setup.count, begin + setup.per_chunk);
          setup.chunks[k].place = me;
          setup_chunk(setup.chunks[k], setup.indices, begin, end);
          continue;
        }
        ahead = following != kNone && following >= setup_jobs
                    ? tile_prefetch(following - setup_jobs)
                    : TilePrefetch{};
        raster_tile_job(k - setup_jobs, worker, ahead);
        ahead.rest();
      }
    });
  }

  // The phase's tiles (cache_.tile_order) by place, into cache_.place_tiles, and the places'
  // counters at 0. Sized for every place the draw's threads may use and every tile, once: which
  // place gets how many tiles depends on which thread set up which chunk, so it changes from
  // frame to frame, and a later frame must not allocate (tests/allocation_test.cpp).
  void place_jobs(size_t workers) {
    const size_t places = std::max<size_t>(workers, size_t(threads_));
    const size_t all_tiles = size_t(tiles_x_) * size_t(tiles_y_);
    std::vector<std::vector<uint32_t>>& tiles = cache_.place_tiles;
    if (tiles.size() < places) tiles.resize(places);
    for (size_t p = 0; p < places; ++p) {
      if (tiles[p].capacity() < all_tiles) tiles[p].reserve(all_tiles);
    }
    for (size_t p = 0; p < workers; ++p) tiles[p].clear();
    if (cache_.num_counters < places) {
      cache_.counters = std::make_unique<PlaceCounters[]>(places);
      cache_.num_counters = places;
    }
    for (size_t p = 0; p < workers; ++p) {
      cache_.counters[p].chunk.store(0, std::memory_order_relaxed);
      cache_.counters[p].tile.store(0, std::memory_order_relaxed);
    }
    std::vector<size_t>& records = cache_.place_records;
    if (records.capacity() < places) records.reserve(places);
    records.resize(workers);
    for (const auto& [busy, tile] : cache_.tile_order) {
      size_t owner = 0;
      if (workers > 1) {
        std::fill(records.begin(), records.end(), 0);
        for (const Chunk& chunk : chunks())
          records[chunk.place % workers] += chunk.bins[tile].size();
        owner = size_t(std::max_element(records.begin(), records.end()) - records.begin());
      }
      tiles[owner].push_back(tile);
    }
  }

  // The tiles the batch in raster_chunks_ touches, into cache_.tile_order, in the order the
  // chunks reached them (one worker: any order draws the same image); with several workers the
  // tiles with the most records first, then in tile order, so that the last tiles taken are short
  // ones and no worker is left alone with a long tile at the end of the phase. From the
  // chunks' touched lists, not a scan of every tile's bin in every chunk (4,080 bins at
  // 1920x1080 and two threads, read by the calling thread between phases while the others wait:
  // spheres_1m gouraud, two threads, 0.43 % of the samples before, 0.11 % after).
  void order_tiles() {
    std::vector<std::pair<uint32_t, uint32_t>>& order = cache_.tile_order;
    std::vector<uint32_t>& listed = cache_.tile_listed;
    if (++cache_.listing == 0) {  // the numbers wrapped: no tile may look listed already
      std::fill(listed.begin(), listed.end(), 0);
      cache_.listing = 1;
    }
    const uint32_t now = cache_.listing;
    for (const Chunk& chunk : chunks()) {
      for (uint32_t tile : chunk.touched) {
        if (listed[tile] == now) continue;
        listed[tile] = now;
        size_t records = 0;
        for (const Chunk& c : chunks()) records += c.bins[tile].size();
        order.emplace_back(uint32_t(~std::bit_width(records)), tile);
      }
    }
    if (threads_ > 1) std::sort(order.begin(), order.end());
  }

  void raster_tile_job(size_t tile, size_t worker, TilePrefetch& ahead) {
    auto start = state_.tile_times ? std::chrono::steady_clock::now()
                                   : std::chrono::steady_clock::time_point{};
    // A clear still pending on the tile is written now, into the cache the tile is drawn in.
    target_.framebuffer->prepare_tile(int(tile % size_t(tiles_x_)), int(tile / size_t(tiles_x_)));
    if (deferred_ && worth_deferring(tile)) {
      resolve_and_shade_tile(tile, *cache_.scratch[worker], ahead);
    } else {
      raster_tile(tile, deferred_ ? cache_.scratch[worker].get() : nullptr, ahead);
    }
    if (state_.tile_times) {  // the `cost` debug view; one thread owns the tile
      std::chrono::duration<double> spent = std::chrono::steady_clock::now() - start;
      state_.tile_times->seconds[tile] += spent.count();
    }
  }

  // A tile's colour and depth (16 KiB each, contiguous: framebuffer.hpp) for the cache, for a
  // tile this worker draws next: the lines arrive while the current tile is drawn, instead of
  // one miss at a time when the tile's clear writes them (the clear was a tenth of quad_grid's
  // frame, waiting for those lines).
  TilePrefetch tile_prefetch(size_t tile) const {
    int x = int(tile % size_t(tiles_x_)) * kTileSize, y = int(tile / size_t(tiles_x_)) * kTileSize;
    TilePrefetch p;
    p.color = reinterpret_cast<const char*>(target_.framebuffer->color_block(x, y));
    p.depth = reinterpret_cast<const char*>(target_.framebuffer->depth_block(x, y));
    p.end = uint32_t(kTileSize) * kTileSize * 4;
    return p;
  }

  // Whether the tile's records are shaded deferred (worth_deferring, tile_visibility.hpp). The box
  // areas are summed while binning (Chunk::box_area): reading every record's bounds again here
  // cost a cache miss per record and tile. The pixels the records cover are estimated only where
  // the rule needs them (cover_matters: few records), from the records: each clipped box times
  // the triangle's share of its whole box (at most a half), which for a triangle inside the tile
  // is its area.
  bool worth_deferring(size_t tile) const {
    PixelRect region = tile_region(tile);
    TileLoad load;
    load.pixels = int64_t(region.x1 - region.x0) * (region.y1 - region.y0);
    for (const Chunk& chunk : chunks()) load.boxes += chunk.box_area[tile];
    if (load.boxes <= kDeferredDepth * load.pixels) return false;
    for (const Chunk& chunk : chunks()) load.records += int64_t(chunk.bins[tile].size());
    if (cover_matters(load)) {
      for (const Chunk& chunk : chunks()) {
        for (uint32_t offset : chunk.bins[tile]) {
          const TriRecord& rec = record(chunk, offset);
          const PixelRect& b = rec.bounds;
          const PixelRect in = intersect(b, region);
          // The area in pixels: a speck's covered pixels (it has no edges), else half the cross
          // product of two edges' normals (in 1/256 pixels).
          double area;
          if (rec.blocks != 0) {
            area = double(__builtin_popcountll(rec.blocks));
          } else {
            const EdgeFunction e0 = rec.edge(0), e1 = rec.edge(1);
            area = std::abs(double(e0.a) * double(e1.b) - double(e1.a) * double(e0.b)) /
                   (2.0 * kSubpixelOne * kSubpixelOne);
          }
          double box = double(b.x1 - b.x0) * double(b.y1 - b.y0);
          load.cover += double(in.x1 - in.x0) * double(in.y1 - in.y0) * std::min(1.0, area / box);
        }
      }
    }
    return detail::worth_deferring(load);
  }

  // Phase 2, immediate shading: every block of every triangle goes to the fragment stage as it
  // is rasterized.
  void raster_tile(size_t tile, DeferredScratch* scratch, TilePrefetch& ahead) {
    TileJob job;
    job.region = tile_region(tile);
    job.prefetch = &ahead;
    job.program = &program_;
    job.target = &target_;
    Shading shading(program_, target_);
    // Blocks that several triangles cover, shaded several triangles at a time (block_batch.hpp),
    // where deferred shading's conditions hold and the shader reads no derivatives.
    if (scratch != nullptr && program_.shade_mixed != nullptr) {
      job.batch = &scratch->batch;
      job.batch->begin(program_, target_);
    }
    for (const Chunk& chunk : chunks()) {
      const std::vector<uint32_t>& bin = chunk.bins[tile];
      if (bin.empty()) continue;
      if (state_.raster == RasterAlgorithm::kEdgeEquations) {
        kernels_.immediate(job, chunk.records.data(), bin.data(), bin.size());
        continue;
      }
      for (uint32_t offset : bin) {
        const TriRecord& rec = record(chunk, offset);
        rasterize_triangle_scanline(rec.coverage(geometry_.num_varyings()), job.region,
                                    shading.sink(rec.interp()));
      }
    }
    if (job.batch != nullptr) job.batch->flush();  // the tile's last held blocks
  }

  // Phase 2, deferred shading (tile_visibility.hpp): visibility of all the tile's triangles
  // first, in submission order, then one shading call per block and winning triangle.
  void resolve_and_shade_tile(size_t tile, DeferredScratch& scratch, TilePrefetch& ahead) {
    TileVisibility& visibility = scratch.visibility;
    TileJob job;
    job.region = tile_region(tile);
    job.prefetch = &ahead;
    job.visibility = &visibility;
    job.less_equal = state_.depth_func == DepthFunc::kLessEqual;
    job.interps = scratch.interps.data();
    visibility.begin(*target_.framebuffer, job.region);
    for (const Chunk& chunk : chunks()) {
      const std::vector<uint32_t>& bin = chunk.bins[tile];
      if (bin.empty()) continue;
      if (state_.raster == RasterAlgorithm::kEdgeEquations) {
        kernels_.deferred(job, chunk.records.data(), bin.data(), bin.size());
        continue;
      }
      ResolveSink sink{&visibility, kernels_.resolve_block, job.less_equal, {}, 0};
      for (uint32_t offset : bin) {
        const TriRecord& rec = record(chunk, offset);
        const Interpolants& in = rec.interp();
        sink.plane = {in.x_ref, in.y_ref, in.z};
        sink.id = job.next_id++;
        job.interps[sink.id] = &in;
        rasterize_triangle_scanline(rec.coverage(geometry_.num_varyings()), job.region,
                                    BlockSink{&ResolveSink::emit, &sink});
      }
    }
    visibility.store_depth();
    ShadeTarget resolved = target_;
    resolved.resolved = true;
    shade_winners(visibility, scratch.interps.data(), program_, resolved);
    visibility.reset();
  }

  // The chunks of the batch being rasterized.
  std::span<const Chunk> chunks() const { return {raster_chunks_, num_chunks_}; }

  static const TriRecord& record(const Chunk& chunk, uint32_t offset) {
    return *reinterpret_cast<const TriRecord*>(chunk.records.data() + offset);
  }

  const GeometryStage& geometry_;
  const RenderState& state_;
  ShadeTarget target_;
  const FragmentProgram& program_;
  int threads_;
  DrawCache& cache_;
  bool deferred_ = false;
  TileKernels kernels_{};
  TriangleKernel triangle_kernel_{};
  bool scanline_ = false;         // records hold their vertices (RasterAlgorithm::kScanline)
  bool prefetch_writes_ = false;  // add_group asks for the arena's lines ahead (kArenaWriteAhead)
  size_t record_bytes_ = 0;
  size_t max_chunks_ = 1;  // the threads' chunks (kChunksPerThread each)
  size_t num_chunks_ = 1;  // this draw's: fewer for few triangles (kMinChunkTriangles)
  const Chunk* raster_chunks_ = nullptr;  // the half of the chunks phase 2 reads
  int tiles_x_ = 0, tiles_y_ = 0;
};

}  // namespace

void draw_triangles_binned(const GeometryStage& geometry, const RenderState& state,
                           const ShadeTarget& target, const FragmentProgram& program,
                           const uint32_t* indices, size_t index_count, int threads) {
  BinnedDraw(geometry, state, target, program, threads).draw(indices, index_count);
}

}  // namespace softrast::detail
