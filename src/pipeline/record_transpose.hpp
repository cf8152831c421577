// pipeline/record_transpose.hpp: the triangle kernels' set-up triangles as the records the bins
// hold (triangle_record.hpp). The kernels give their results lane by lane (TriangleLanes: each
// field an array over the group's triangles); a record holds one triangle's fields together.
// Copying the fields one by one cost about 130 instructions per record, two thirds of them
// loads and stores of single fields. write_records makes the records of a whole group at once
// instead: each record as a sequence of 32-bit words is a column of the lanes' arrays, so the
// records of eight lanes are 8x8 transposes of rows that are the arrays themselves (or, for the
// 64-bit fields, their low and high halves), stored straight into the arena.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/triangle_kernels.hpp"
#include "pipeline/triangle_record.hpp"
#include "raster/raster.hpp"
#include "softrast/render_state.hpp"

namespace softrast::detail {

// Lane l's coverage: the record's fields before its interpolants, and its edges (which must have
// their room: TriRecord). Precondition: lane l is ready.
inline void write_coverage(const TriangleLanes& lanes, int l, TriRecord* rec) {
  EdgeFunction edge[3];
  for (int k = 0; k < 3; ++k) {
    edge[k] = {lanes.edge_a[k][l], lanes.edge_b[k][l], lanes.edge_c[k][l]};
  }
  rec->set_edges(edge);
  rec->bounds = {lanes.bounds[0][l], lanes.bounds[1][l], lanes.bounds[2][l], lanes.bounds[3][l]};
  rec->small = (lanes.small >> l) & 1u;
  rec->blocks = lanes.blocks[0][l] | uint64_t(lanes.blocks[1][l]) << 32;
}

// Lane l's interpolants from the kernel's planes (the same bits as
// setup_triangle_interpolants'). Precondition: lane l is ready and not in lanes.scalar_planes.
inline void write_planes(const TriangleLanes& lanes, int l, int num_varyings, FrontFace front_face,
                         Interpolants& in) {
  in.x_ref = lanes.x_ref[l];
  in.y_ref = lanes.y_ref[l];
  in.z = {lanes.z[0][l], lanes.z[1][l], lanes.z[2][l]};
  in.inv_w = {lanes.inv_w[0][l], lanes.inv_w[1][l], lanes.inv_w[2][l]};
  in.num_varyings = num_varyings;
  in.front_facing = is_front_facing(lanes.area[l], front_face);
  for (int i = 0; i < num_varyings; ++i) {
    in.var[i] = {lanes.var[i][0][l], lanes.var[i][1][l], lanes.var[i][2][l]};
  }
}

// Records of up to kMaxTransposedVaryings varyings are written by write_records.
inline constexpr int kMaxTransposedVaryings = 8;
inline constexpr size_t kMaxTransposedBytes = 256;
static_assert(record_bytes(kMaxTransposedVaryings) <= kMaxTransposedBytes);

// write_records stores whole 32-byte blocks: past a record's end it writes up to kRecordSlack
// bytes more.
inline constexpr size_t kRecordSlack = 32;

// The bins of a group's records (write_records), from their bounds (valid for ready lanes): the
// tile of lane l's top-left pixel, tile[l] = (y0 / kTileSize) tiles_x + x0 / kTileSize, and bit l
// of `spans` where the bounds reach past that tile.
struct GroupTiles {
  alignas(32) uint32_t tile[TriangleLanes::kMaxLanes];
  uint32_t spans = 0;
};

// Writes the records of lanes [0, count) (count 8 or 16) as write_coverage and write_planes
// write them (without the scanline rasterizer's vertices): record_bytes(num_varyings) bytes at
// dest[l] for lane l, the padding bytes zero; the edges (sizeof(RecordEdges) bytes) of each lane
// whose blocks are 0 at edges[l] (other lanes' edges[l] may be written or not); and their bins
// into `tiles`. The varyings' last blocks are stored first, and the edges last, so records whose
// edges and dest are in increasing lane order and back to back get the next record's bytes over
// a record's excess; the last record needs kRecordSlack bytes of room after it. A lane that is
// not ready, or in scalar_planes, gets bytes of no meaning: point its dest at scratch room of
// kMaxTransposedBytes, and its edges there too, as those of a lane whose record goes without (a
// speck's: TriRecord). Preconditions: the CPU has AVX2, num_varyings <=
// kMaxTransposedVaryings.
void write_records(const TriangleLanes& lanes, int count, int num_varyings, FrontFace front_face,
                   std::byte* const* dest, std::byte* const* edges, int tiles_x, GroupTiles& tiles);

}  // namespace softrast::detail
