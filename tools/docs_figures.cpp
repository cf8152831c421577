// tools/docs_figures.cpp: the figures of the pipeline chapters in docs/ that the command line
// cannot draw, rendered through the library's public API (softrast/shader.hpp, render_mesh).
//   softrast_docs_figures OUT_DIR
// writes into OUT_DIR:
//   coverage_top_left.png      two triangles sharing an edge through pixel centres, magnified
//   edge_walking.png           one triangle drawn by the edge-walking rasterizer, its two
//                              trapezoids in two colours
//   edge_equations_blocks.png  the same triangle drawn by the edge-equation rasterizer, its
//                              pixels shaded by the 4x4 block and 2x2 quad they belong to
//   perspective.png            a checkered floor with and without perspective-correct varyings
//   clipping.png               a triangle crossing the near plane: the camera's image with the
//                              clipped triangles' edges, and the scene seen from above
//   depth_buffer.png           the demo scene's depth buffer as stored, and the depth view
// and prints the pixel counts the chapters quote. Small images are magnified with nearest
// filtering (every pixel a square, the pixel grid drawn between them); the triangle edges over
// them are lines softrast draws at the magnified size.
//
// The fragment shaders here are scalar (`fragment()`): these pictures are a few thousand pixels,
// and one instantiation per shader keeps this program quick to compile.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/vec2.hpp>

#include "softrast/shader.hpp"
#include "softrast/softrast.hpp"

namespace {

using glm::vec2;
using glm::vec3;
using glm::vec4;

const vec4 kBackground{0.12f, 0.12f, 0.12f, 1.0f};
const vec4 kOrange{0.95f, 0.55f, 0.20f, 1.0f};
const vec4 kBlue{0.25f, 0.50f, 0.95f, 1.0f};
const vec4 kWhite{1.0f, 1.0f, 1.0f, 1.0f};

// Clip-space position of a window position (x right, y down, in pixels) of a w x h framebuffer:
// the inverse of the viewport transform, so these shaders place vertices on exact window
// coordinates.
vec4 clip_of_window(vec2 p, int w, int h) {
  return {2.0f * p.x / float(w) - 1.0f, 1.0f - 2.0f * p.y / float(h), 0.0f, 1.0f};
}

// Positions given in window pixels, one colour.
struct FlatPixels {
  static constexpr int kVaryings = 0;
  const vec2* points;
  int width, height;
  vec4 color;
  vec4 vertex(uint32_t i, float*) const { return clip_of_window(points[i], width, height); }
  bool fragment(softrast::FragmentInput&, vec4& out) const {
    out = color;
    return true;
  }
};

// Positions in window pixels; samples above `split_y` get one colour, the others another.
struct SplitAtRow {
  static constexpr int kVaryings = 0;
  const vec2* points;
  int width, height;
  float split_y;
  vec4 vertex(uint32_t i, float*) const { return clip_of_window(points[i], width, height); }
  bool fragment(softrast::FragmentInput& in, vec4& out) const {
    out = in.position.y < split_y ? vec4(0.20f, 0.70f, 0.65f, 1.0f) : vec4(0.70f, 0.35f, 0.80f, 1);
    return true;
  }
};

// Positions in window pixels; each pixel coloured by its 4x4 block (alternating hues) and its
// 2x2 quad within the block (alternating brightness).
struct BlockColours {
  static constexpr int kVaryings = 0;
  const vec2* points;
  int width, height;
  vec4 vertex(uint32_t i, float*) const { return clip_of_window(points[i], width, height); }
  bool fragment(softrast::FragmentInput& in, vec4& out) const {
    int x = int(in.position.x), y = int(in.position.y);
    bool block_odd = ((x / 4) + (y / 4)) % 2 != 0;
    bool quad_odd = ((x / 2) + (y / 2)) % 2 != 0;
    vec3 c = block_odd ? vec3(0.95f, 0.55f, 0.20f) : vec3(0.30f, 0.75f, 0.40f);
    out = vec4(c * (quad_odd ? 0.75f : 1.0f), 1.0f);
    return true;
  }
};

// A floor with (u, v) in [0, 1]^2, drawn as a checkerboard of `cells_u` x `cells_v` squares.
// With `affine` the shader passes u * w, v * w and w instead of u and v: the perspective-correct
// interpolation of a / w and 1 / w then yields sum(b_i a_i) / sum(b_i / w_i) for a_i = u_i w_i
// and a_i = w_i, whose ratio is sum(b_i u_i), the screen-space (affine) interpolation of u with
// the window barycentrics b_i. So both pictures come from the same pipeline.
struct Checker {
  static constexpr int kVaryings = 3;
  const vec3* positions;
  const vec2* uvs;
  glm::mat4 mvp;
  bool affine;
  float cells_u, cells_v;
  vec4 vertex(uint32_t i, float* out) const {
    vec4 clip = mvp * vec4(positions[i], 1.0f);
    float w = affine ? clip.w : 1.0f;
    out[0] = uvs[i].x * w;
    out[1] = uvs[i].y * w;
    out[2] = w;
    return clip;
  }
  bool fragment(softrast::FragmentInput& in, vec4& out) const {
    float u = in.varyings[0] / in.varyings[2], v = in.varyings[1] / in.varyings[2];
    int cell = int(std::floor(u * cells_u)) + int(std::floor(v * cells_v));
    out = (cell & 1) ? vec4(0.92f, 0.92f, 0.88f, 1.0f) : vec4(0.20f, 0.30f, 0.55f, 1.0f);
    return true;
  }
};

// World positions with a colour per vertex, and the distance in front of a camera (its view
// matrix `eye_view`) as a varying: fragments nearer than `near_plane` are darkened. Seen from
// that camera none are (the clipper removed them); seen from above they show what was cut.
struct NearTint {
  static constexpr int kVaryings = 4;
  const vec3* positions;
  const vec3* colors;
  glm::mat4 mvp, eye_view;
  float near_plane;
  vec4 vertex(uint32_t i, float* out) const {
    out[0] = colors[i].r, out[1] = colors[i].g, out[2] = colors[i].b;
    out[3] = -(eye_view * vec4(positions[i], 1.0f)).z;
    return mvp * vec4(positions[i], 1.0f);
  }
  bool fragment(softrast::FragmentInput& in, vec4& out) const {
    vec3 c = in.vec3(0);
    out = in.varyings[3] < near_plane ? vec4(c * 0.3f + 0.1f, 1.0f) : vec4(c, 1.0f);
    return true;
  }
};

// World positions, one colour (lines and the wireframe pass).
struct FlatWorld {
  static constexpr int kVaryings = 0;
  const vec3* positions;
  glm::mat4 mvp;
  vec4 color;
  vec4 vertex(uint32_t i, float*) const { return mvp * vec4(positions[i], 1.0f); }
  bool fragment(softrast::FragmentInput&, vec4& out) const {
    out = color;
    return true;
  }
};

softrast::RenderState overlay_state(softrast::Primitive primitive) {
  softrast::RenderState s;
  s.primitive = primitive;
  s.cull = softrast::CullMode::kNone;
  s.depth_test = false;
  return s;
}

// Lines between window points of `fb`, two pixels wide (the line and its copy one pixel right
// and one down), so that they stay visible over the magnified pixels.
void draw_lines(softrast::Framebuffer& fb, const std::vector<vec2>& ends, vec4 color) {
  for (vec2 offset : {vec2(0, 0), vec2(1, 0), vec2(0, 1)}) {
    std::vector<vec2> moved;
    std::vector<uint32_t> indices;
    for (vec2 p : ends) {
      indices.push_back(uint32_t(moved.size()));
      moved.push_back(p + offset);
    }
    softrast::draw(fb, overlay_state(softrast::Primitive::kLines),
                   FlatPixels{moved.data(), fb.width(), fb.height(), color}, indices,
                   uint32_t(moved.size()));
  }
}

uint32_t pack(vec4 c) {
  return softrast::pack_rgba8(c);
}

// `small` magnified `k` times with nearest filtering: each pixel a (k-1)-wide square and a
// one-pixel grid line between pixels (brighter every `block` pixels when block > 0).
softrast::Framebuffer magnify(const softrast::Framebuffer& small, int k, int block) {
  softrast::Framebuffer big(small.width() * k + 1, small.height() * k + 1);
  big.clear_color({0.32f, 0.32f, 0.32f, 1.0f});
  for (int y = 0; y < small.height(); ++y) {
    for (int x = 0; x < small.width(); ++x) {
      uint32_t c = small.color_at(x, y);
      for (int j = 1; j < k; ++j) {
        for (int i = 1; i < k; ++i) big.set_color(x * k + i, y * k + j, c);
      }
    }
  }
  if (block > 0) {
    const uint32_t bright = pack({0.85f, 0.85f, 0.85f, 1});
    for (int y = 0; y < big.height(); ++y) {
      for (int x = 0; x < big.width(); ++x) {
        if ((x % (k * block) == 0) || (y % (k * block) == 0)) big.set_color(x, y, bright);
      }
    }
  }
  return big;
}

// A dot at every pixel centre of `small` on its magnification `big` (drawn last, so that a sample
// on an edge shows on the edge's line): dark over a covered pixel, grey over the background.
void draw_sample_dots(const softrast::Framebuffer& small, softrast::Framebuffer& big, int k) {
  const uint32_t background = pack(kBackground);
  for (int y = 0; y < small.height(); ++y) {
    for (int x = 0; x < small.width(); ++x) {
      bool empty = small.color_at(x, y) == background;
      uint32_t dot = empty ? pack({0.55f, 0.55f, 0.55f, 1}) : pack({0.05f, 0.05f, 0.05f, 1});
      for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) big.set_color(x * k + k / 2 + i, y * k + k / 2 + j, dot);
      }
    }
  }
}

// A window point of the small framebuffer on the magnified one (its grid line at x * k).
vec2 on_big(vec2 p, int k) {
  return p * float(k) + 0.5f;
}

// Images side by side with `gap` pixels of white between them, tops aligned.
softrast::Image side_by_side(const std::vector<softrast::Image>& images, int gap) {
  int width = -gap, height = 0;
  for (const softrast::Image& im : images)
    width += im.width + gap, height = std::max(height, im.height);
  softrast::Image out(width, height);
  std::fill(out.rgba.begin(), out.rgba.end(), uint8_t(255));
  int x0 = 0;
  for (const softrast::Image& im : images) {
    for (int y = 0; y < im.height; ++y) {
      std::copy(im.pixel(0, y), im.pixel(0, y) + size_t(im.width) * 4, out.pixel(x0, y));
    }
    x0 += im.width + gap;
  }
  return out;
}

bool save(const std::string& path, const softrast::Image& image) {
  softrast::Status s = softrast::save_image(path, image);
  if (!s)
    std::fprintf(stderr, "softrast_docs_figures: %s\n", s.message().c_str());
  else
    std::printf("wrote %s (%dx%d)\n", path.c_str(), image.width, image.height);
  return bool(s);
}

int count_color(const softrast::Framebuffer& fb, vec4 color) {
  int n = 0;
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) n += fb.color_at(x, y) == pack(color);
  }
  return n;
}

// Two triangles sharing their diagonal, every edge through pixel centres (CONVENTIONS.md's
// example moved one pixel in): which triangle owns each centre on an edge is the fill rule's
// choice alone. The left panel draws both, the right panel counts fragments per pixel.
bool coverage_figure(const std::string& dir) {
  constexpr int kW = 8, kH = 8, kScale = 40;
  std::vector<vec2> pts = {{1.5f, 1.5f}, {6.5f, 1.5f}, {6.5f, 6.5f}, {1.5f, 6.5f}};
  std::vector<uint32_t> upper = {0, 1, 2}, lower = {3, 0, 2};
  softrast::RenderState state;
  state.cull = softrast::CullMode::kNone;
  softrast::Framebuffer fb(kW, kH);
  fb.clear(kBackground, 1.0f, 1);
  state.depth_test = false;
  softrast::draw(fb, state, FlatPixels{pts.data(), kW, kH, kOrange}, upper, 4);
  softrast::draw(fb, state, FlatPixels{pts.data(), kW, kH, kBlue}, lower, 4);
  // Fragments per pixel: each triangle adds 0.4 (102 of 255) to red, green and blue.
  softrast::Framebuffer count(kW, kH);
  count.clear(kBackground, 1.0f, 1);
  softrast::RenderState add = state;
  add.blend = softrast::BlendMode::kAdditive;
  for (const auto* tri : {&upper, &lower}) {
    softrast::draw(count, add, FlatPixels{pts.data(), kW, kH, {0.4f, 0.4f, 0.4f, 0}}, *tri, 4);
  }
  int twice = 0, once = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      int hits = (int(count.color_at(x, y) & 0xff) - int(pack(kBackground) & 0xff) + 51) / 102;
      once += hits == 1, twice += hits >= 2;
    }
  }
  std::printf(
      "coverage: upper-right triangle %d pixels, lower-left %d, pixels hit once %d, "
      "hit twice %d\n",
      count_color(fb, kOrange), count_color(fb, kBlue), once, twice);
  std::vector<softrast::Image> panels;
  for (softrast::Framebuffer* f : {&fb, &count}) {
    softrast::Framebuffer big = magnify(*f, kScale, 0);
    std::vector<vec2> edges;
    for (auto [a, b] : {std::pair{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}}) {
      edges.push_back(on_big(pts[size_t(a)], kScale));
      edges.push_back(on_big(pts[size_t(b)], kScale));
    }
    draw_lines(big, edges, kWhite);
    draw_sample_dots(*f, big, kScale);
    panels.push_back(big.to_image());
  }
  return save(dir + "/coverage_top_left.png", side_by_side(panels, 16));
}

// The triangle of the two rasterizer figures: its middle vertex (by y) is (17.6, 5.4).
const std::vector<vec2> kWalkTriangle = {{2.3f, 1.2f}, {17.6f, 5.4f}, {7.1f, 12.8f}};
constexpr int kWalkW = 20, kWalkH = 14, kWalkScale = 24;

std::vector<vec2> walk_triangle_edges() {
  std::vector<vec2> e;
  for (auto [a, b] : {std::pair{0, 1}, {1, 2}, {2, 0}}) {
    e.push_back(on_big(kWalkTriangle[size_t(a)], kWalkScale));
    e.push_back(on_big(kWalkTriangle[size_t(b)], kWalkScale));
  }
  return e;
}

bool edge_walking_figure(const std::string& dir) {
  softrast::RenderState state;
  state.cull = softrast::CullMode::kNone;
  state.raster = softrast::RasterAlgorithm::kScanline;
  softrast::Framebuffer fb(kWalkW, kWalkH);
  fb.clear(kBackground, 1.0f, 1);
  const vec2 top = kWalkTriangle[0], mid = kWalkTriangle[1], bottom = kWalkTriangle[2];
  std::vector<uint32_t> tri = {0, 1, 2};
  softrast::draw(fb, state, SplitAtRow{kWalkTriangle.data(), kWalkW, kWalkH, mid.y}, tri, 3);
  softrast::Framebuffer big = magnify(fb, kWalkScale, 0);
  std::vector<vec2> edges = walk_triangle_edges();
  // The split: the row of the middle vertex, from the long edge to that vertex.
  float t = (mid.y - top.y) / (bottom.y - top.y);
  vec2 on_long_edge = top + t * (bottom - top);
  edges.push_back(on_big(on_long_edge, kWalkScale));
  edges.push_back(on_big(mid, kWalkScale));
  draw_lines(big, edges, kWhite);
  draw_sample_dots(fb, big, kWalkScale);
  return save(dir + "/edge_walking.png", big.to_image());
}

bool edge_equations_figure(const std::string& dir) {
  softrast::RenderState state;
  state.cull = softrast::CullMode::kNone;
  softrast::Framebuffer fb(kWalkW, kWalkH);
  fb.clear(kBackground, 1.0f, 1);
  std::vector<uint32_t> tri = {0, 1, 2};
  softrast::draw(fb, state, BlockColours{kWalkTriangle.data(), kWalkW, kWalkH}, tri, 3);
  // The same coverage as the edge-walking figure, or the chapter's claim is wrong.
  softrast::Framebuffer walked(kWalkW, kWalkH);
  walked.clear(kBackground, 1.0f, 1);
  state.raster = softrast::RasterAlgorithm::kScanline;
  softrast::draw(walked, state, FlatPixels{kWalkTriangle.data(), kWalkW, kWalkH, kWhite}, tri, 3);
  int covered = 0, differ = 0;
  for (int y = 0; y < kWalkH; ++y) {
    for (int x = 0; x < kWalkW; ++x) {
      bool a = fb.color_at(x, y) != pack(kBackground), b = walked.color_at(x, y) == pack(kWhite);
      covered += a, differ += a != b;
    }
  }
  std::printf("rasterizers: %d pixels covered, %d differ between edge equations and walking\n",
              covered, differ);
  // Blocks with all 16 pixels covered: the ones the hierarchical test accepts whole.
  int full_blocks = 0;
  for (int by = 0; by + 4 <= kWalkH; by += 4) {
    for (int bx = 0; bx + 4 <= kWalkW; bx += 4) {
      bool full = true;
      for (int i = 0; i < 16; ++i) full &= fb.color_at(bx + i % 4, by + i / 4) != pack(kBackground);
      full_blocks += full;
    }
  }
  std::printf("rasterizers: %d 4x4 blocks wholly covered\n", full_blocks);
  softrast::Framebuffer big = magnify(fb, kWalkScale, 4);
  draw_lines(big, walk_triangle_edges(), kWhite);
  draw_sample_dots(fb, big, kWalkScale);
  return save(dir + "/edge_equations_blocks.png", big.to_image());
}

bool perspective_figure(const std::string& dir) {
  constexpr int kW = 360, kH = 270;
  std::vector<vec3> pos = {{-1, 0, 1}, {1, 0, 1}, {1, 0, -5}, {-1, 0, -5}};
  std::vector<vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  softrast::Camera camera;
  camera.eye = {0.0f, 1.5f, 2.3f};
  camera.target = {0.0f, 0.0f, -1.4f};
  glm::mat4 mvp = camera.view_projection(float(kW) / float(kH));
  softrast::RenderState state;
  state.cull = softrast::CullMode::kNone;
  std::vector<softrast::Image> panels;
  for (bool affine : {false, true}) {
    softrast::Framebuffer fb(kW, kH);
    fb.clear(kBackground, 1.0f, 1);
    softrast::draw(fb, state, Checker{pos.data(), uv.data(), mvp, affine, 6.0f, 18.0f}, indices, 4);
    // The shared diagonal, where the affine picture bends.
    std::vector<vec3> diagonal = {pos[0], pos[2]};
    std::vector<uint32_t> line = {0, 1};
    softrast::draw(fb, overlay_state(softrast::Primitive::kLines),
                   FlatWorld{diagonal.data(), mvp, {0.9f, 0.2f, 0.2f, 1}}, line, 2);
    panels.push_back(fb.to_image());
  }
  return save(dir + "/perspective.png", side_by_side(panels, 12));
}

bool clipping_figure(const std::string& dir) {
  constexpr int kW = 360, kH = 270;
  const float aspect = float(kW) / float(kH);
  std::vector<vec3> pos = {{-1.6f, -0.9f, -3.4f}, {1.5f, -0.6f, -2.9f}, {0.1f, 0.45f, -0.7f}};
  std::vector<vec3> col = {{0.9f, 0.3f, 0.2f}, {0.2f, 0.8f, 0.3f}, {0.3f, 0.4f, 0.95f}};
  std::vector<uint32_t> tri = {0, 1, 2};
  softrast::Camera eye;  // at the origin, looking down -z
  eye.eye = {0, 0, 0};
  eye.target = {0, 0, -1};
  eye.fov_y_degrees = 60.0f;
  eye.near_plane = 1.5f;
  eye.far_plane = 10.0f;
  const glm::mat4 eye_mvp = eye.view_projection(aspect);
  softrast::RenderState state;
  state.cull = softrast::CullMode::kNone;

  // What the camera sees: the clipped triangle, then the edges of the triangles the clipper
  // made (RenderState::wireframe draws the edges of each triangle after clipping).
  softrast::Framebuffer seen(kW, kH);
  seen.clear(kBackground, 1.0f, 1);
  // The whole triangle's outline in grey, as a camera with its near plane at 0.5 would see it
  // (the same x and y; only depth differs): the part the clipper removes.
  softrast::Camera nearer = eye;
  nearer.near_plane = 0.5f;
  std::vector<uint32_t> outline = {0, 1, 1, 2, 2, 0};
  softrast::draw(seen, overlay_state(softrast::Primitive::kLines),
                 FlatWorld{pos.data(), nearer.view_projection(aspect), {0.5f, 0.5f, 0.5f, 1}},
                 outline, 3);
  softrast::draw(seen, state, NearTint{pos.data(), col.data(), eye_mvp, eye.view(), 0.0f}, tri, 3);
  softrast::RenderState wire = overlay_state(softrast::Primitive::kTriangles);
  wire.wireframe = true;
  softrast::draw(seen, wire, FlatWorld{pos.data(), eye_mvp, kWhite}, tri, 3);

  // From above: orthographic, -z up the image, the camera near the bottom edge.
  softrast::Camera above;
  above.eye = {0.3f, 10.0f, -2.1f};
  above.target = {0.3f, 0.0f, -2.1f};
  above.up = {0.0f, 0.0f, -1.0f};
  above.orthographic = true;
  above.ortho_bottom = -2.25f, above.ortho_top = 2.25f;
  above.ortho_left = -2.25f * aspect, above.ortho_right = 2.25f * aspect;
  above.near_plane = 1.0f;
  above.far_plane = 20.0f;
  const glm::mat4 top_mvp = above.view_projection(aspect);
  softrast::Framebuffer top(kW, kH);
  top.clear(kBackground, 1.0f, 1);
  softrast::draw(top, state, NearTint{pos.data(), col.data(), top_mvp, eye.view(), eye.near_plane},
                 tri, 3);
  // The frustum's sides to z = -4.4 and its near plane, in the plane y = 0.
  const float half_w = std::tan(glm::radians(eye.fov_y_degrees / 2)) * aspect;
  const float z_end = -4.4f, n = eye.near_plane;
  std::vector<vec3> frustum = {{0, 0, 0},
                               {-half_w * -z_end, 0, z_end},
                               {0, 0, 0},
                               {half_w * -z_end, 0, z_end},
                               {-half_w * n, 0, -n},
                               {half_w * n, 0, -n}};
  std::vector<uint32_t> lines = {0, 1, 2, 3, 4, 5};
  softrast::draw(top, overlay_state(softrast::Primitive::kLines),
                 FlatWorld{frustum.data(), top_mvp, {0.9f, 0.9f, 0.5f, 1}}, lines, 6);
  // The camera: a small triangle pointing along -z.
  std::vector<vec3> marker = {{0, 0, -0.05f}, {-0.12f, 0, 0.12f}, {0.12f, 0, 0.12f}};
  softrast::draw(top, overlay_state(softrast::Primitive::kTriangles),
                 FlatWorld{marker.data(), top_mvp, kWhite}, tri, 3);
  return save(dir + "/clipping.png", side_by_side({seen.to_image(), top.to_image()}, 12));
}

bool depth_figure(const std::string& dir) {
  constexpr int kW = 360, kH = 270;
  softrast::DemoScene scene = softrast::make_demo_scene();
  softrast::RenderOptions options;
  softrast::Framebuffer fb(kW, kH);
  fb.clear();
  softrast::render_mesh(fb, scene.mesh, scene.camera, options);
  // The stored window depth, linear grey: 0 (the near plane) black, 1 (far, or cleared) white.
  softrast::Image raw(kW, kH);
  std::vector<float> drawn;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      float d = fb.depth_at(x, y);
      uint8_t g = softrast::to_unorm8(d);
      uint8_t* p = raw.pixel(x, y);
      p[0] = p[1] = p[2] = g, p[3] = 255;
      if (d < 1.0f) drawn.push_back(d);
    }
  }
  std::sort(drawn.begin(), drawn.end());
  auto at = [&](double q) {
    return drawn.empty() ? 1.0f : drawn[size_t(q * double(drawn.size() - 1))];
  };
  std::printf(
      "depth: %zu pixels drawn; stored depth min %.3f, 10%% %.3f, median %.3f, 90%% %.3f, "
      "max %.3f (near %.2f, far %.1f)\n",
      drawn.size(), at(0), at(0.1), at(0.5), at(0.9), at(1), scene.camera.near_plane,
      scene.camera.far_plane);
  softrast::Framebuffer view(kW, kH);
  view.clear();
  options.shader = softrast::ShaderKind::kDepth;
  softrast::render_mesh(view, scene.mesh, scene.camera, options);
  return save(dir + "/depth_buffer.png", side_by_side({raw, view.to_image()}, 12));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: softrast_docs_figures OUT_DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  bool ok = coverage_figure(dir) && edge_walking_figure(dir) && edge_equations_figure(dir) &&
            perspective_figure(dir) && clipping_figure(dir) && depth_figure(dir);
  return ok ? 0 : 1;
}
