// softrast/shader.hpp: programmable shaders. Opt in to this header to draw with your own vertex
// and fragment shader; it compiles the fragment stage for your shader type (no virtual calls).
//
// A shader is any type with:
//   static constexpr int kVaryings = N;               // 0..16 floats from vertex to fragment
//   glm::vec4 vertex(uint32_t index, float* varyings) const;   // clip-space position; writes N
// and a fragment shader, in one of two forms:
//   template <int N> SOFTRAST_SIMD_INLINE void shade(Fragments<N>& f) const;  // wide: 4x4 at once
//   bool fragment(FragmentInput& in, glm::vec4& color) const;  // scalar: one pixel, false discards
// The wide form is written with softrast::simd types (simd.hpp) as if for one pixel: f.vec3(0)
// is a varying for all 16 pixels, f.color the output (or f.set_rgba8(packed) for a result that
// comes as bytes, such as softrast::sample_rgba8's); it is compiled for SSE2, SSE4, AVX2 and
// AVX-512 and the widest the CPU has runs. Declare it SOFTRAST_SIMD_INLINE (always inline): GCC
// can otherwise compile it once, for the baseline x86-64, and call that copy from every level's
// block function (its wide operations then run as SSE2 code that calls out for every operation,
// which made the built-in Gouraud shading several times slower). Functions it calls with wide
// values must then be always inline too (SOFTRAST_SIMD_INLINE, as every softrast::simd function and
// Fragments member is), or take and return them by reference: an out-of-line function is
// compiled for the baseline, whose ABI for 8- and 16-lane values differs. Optional traits:
//   static constexpr bool kWritesDepth = true;  // the shader sets the depth: late depth test
//   static constexpr bool kDiscards = true;     // a wide shader that calls f.discard()
// A wide shader that neither writes depth nor discards lets opaque depth-tested draws resolve
// visibility first and shade each visible pixel once (deferred shading in tiles). One that also
// never reads derivatives (f.ddx, f.ddy, sampling with them) in a draw, and whose every pixel's
// colour depends on that pixel's inputs alone (no value combined across lanes), may say so:
//   bool reads_derivatives() const { return false; }
// and a 4x4 block whose pixels several triangles cover is then shaded in one call, each pixel
// with its own triangle's varyings (a 2x2 quad may mix triangles, so ddx and ddy would be
// meaningless there: they stop the program with a message if called after all). A shader whose
// fragment work is only a few operations (the built-in Gouraud scales one varying) gains little
// from that, since picking each pixel's triangle costs about as much; it may say so with
//   static constexpr bool kCheapToShade = true;
// and is then shaded that way only at AVX-512 (16 lanes to fill, and a broadcast per coefficient)
// and only in tiles shaded as their triangles come (the held blocks of a dense mesh), one
// triangle per call elsewhere.
// A scalar shader is taken to discard (it returns a bool) and is always shaded immediately.
//
// The vertex shader pulls its own inputs by index (from whatever arrays the shader holds), so
// any vertex layout works. Varyings are interpolated perspective-correctly. A shader may also
// have a wide vertex shader, run on 16 vertices a call where the CPU has AVX2 or AVX-512
// (vertex() runs elsewhere):
//   template <int N> SOFTRAST_SIMD_INLINE simd::Vec4<N> vertices(const Vertices<N>& v,
//                                                               simd::Float<N>* varyings) const;
// lane l is vertex v.index[l]; v.vec3(array) and the like read each lane's element of an array
// (in one pass when the 16 are consecutive). It must compute what vertex() computes for each
// lane (the built-in shaders do the same operations in the same order: the same bits). A shader
// whose wide form covers only some of its settings says which draws take it with
//   bool wide_vertices() const;
#pragma once

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "softrast/detail/interpolants.hpp"
#include "softrast/detail/parallel.hpp"
#include "softrast/detail/shade_block.hpp"
#include "softrast/detail/shade_simd.hpp"
#include "softrast/detail/texture_simd.hpp"
#include "softrast/detail/vertex_simd.hpp"
#include "softrast/framebuffer.hpp"
#include "softrast/render_state.hpp"

namespace softrast {

inline constexpr int kMaxVaryings = detail::kMaxVaryings;

namespace detail {
template <class S>
concept ScalarShader = requires(const S& s, FragmentInput& in, glm::vec4& color) {
  { s.fragment(in, color) } -> std::convertible_to<bool>;
};
}  // namespace detail

template <class S>
concept ShaderProgram = requires(const S& s, uint32_t index, float* out) {
  requires S::kVaryings >= 0 && S::kVaryings <= kMaxVaryings;
  { s.vertex(index, out) } -> std::convertible_to<glm::vec4>;
  requires detail::WideShader<S> || detail::ScalarShader<S>;
};

// Draws `indices` (three per triangle, two per line, one per point, as state.primitive says)
// over vertices 0..vertex_count-1 into `framebuffer`. Runs the vertex shader once per vertex
// (only for the vertices the indices name when there are fewer indices than vertices), then
// clipping, culling, rasterization, depth test, the fragment shader and blending. Indices
// >= vertex_count skip their primitive; primitives with NaN or Inf positions draw nothing.
// vertex() and fragment() may run on several threads at once (state.threads), so they must not
// write to shared data; every pixel still sees the primitives in submission order.
template <ShaderProgram S>
void draw(Framebuffer& framebuffer, const RenderState& state, const S& shader,
          std::span<const uint32_t> indices, uint32_t vertex_count) {
  constexpr int kStride = 4 + S::kVaryings;
  constexpr uint32_t kVerticesPerJob = 1024;
  // A draw with fewer indices than vertices (one of many draws over a shared vertex array: an
  // OBJ's material runs, a glTF scene's primitives) shades only the vertices it names,
  // renumbered (detail::compact_draw): shading all of them in every draw made a scene of many
  // small draws quadratic in its size (an OBJ of 32,000 one-triangle material runs took 41 s).
  // Each vertex gets the same values either way, so the image is the same. Kept per thread and
  // per shader type, as `clip` below.
  thread_local std::vector<uint32_t> names, renumbered;
  const uint32_t* name = nullptr;  // vertex k of this draw is the mesh's name[k] (null: k)
  const uint32_t mesh_vertices = vertex_count;
  if (indices.size() < vertex_count) {
    detail::compact_draw(indices, vertex_count, names, renumbered);
    name = names.data();
    vertex_count = uint32_t(names.size());
    indices = renumbered;
  }
  // The vertex stage's output, kept per thread and per shader type between draws: a scene drawn
  // again allocates nothing (the vector only grows; every element used is written below).
  thread_local std::vector<float> clip;
  if (clip.size() < size_t(vertex_count) * kStride) clip.resize(size_t(vertex_count) * kStride);
  float* const out = clip.data();  // the calling thread's buffer (workers have their own)
  // A shader with a wide vertex shader runs it on 16 vertices a call (vertex_simd.hpp), where the
  // indices fit its loads' 32-bit offsets, at AVX2 and AVX-512: at SSE it measured no faster
  // than this loop (BM_VertexShaderWide, Gouraud: 451 and 465 us against 438 at SSE4 and SSE2;
  // 309 at AVX2, 242 at AVX-512).
  detail::ShadeVerticesFn wide = nullptr;
  if constexpr (detail::WideVertexShader<S>) {
    const SimdLevel level = simd_level();
    if (level >= SimdLevel::kAvx2 && mesh_vertices < (uint32_t(1) << 28) &&
        detail::uses_wide_vertices(shader)) {
      wide = detail::wide_shade_vertices<S>(level);
    }
  }
  auto shade_vertices = [&](size_t job) {
    uint32_t end = uint32_t(std::min<size_t>(vertex_count, (job + 1) * kVerticesPerJob));
    if (wide != nullptr) {
      wide(&shader, name, uint32_t(job * kVerticesPerJob), end, out);
      return;
    }
    for (uint32_t i = uint32_t(job * kVerticesPerJob); i < end; ++i) {
      float* v = out + size_t(i) * kStride;
      glm::vec4 p = shader.vertex(name != nullptr ? name[i] : i, v + 4);
      v[0] = p.x, v[1] = p.y, v[2] = p.z, v[3] = p.w;
    }
  };
  size_t jobs = (size_t(vertex_count) + kVerticesPerJob - 1) / kVerticesPerJob;
  detail::parallel_for(jobs, state.threads > 0 ? state.threads : detail::hardware_threads(),
                       shade_vertices);
  detail::ClipVertices vertices{out, vertex_count, kStride, S::kVaryings};
  detail::FragmentProgram program;
  program.shader = &shader;
  program.writes_depth = detail::WritesDepth<S>;
  if constexpr (detail::WideShader<S>) {
    program.shade_block = detail::wide_shade_block<S>(simd_level());
    program.deferrable = !detail::WritesDepth<S> && !detail::DeclaresDiscards<S>;
    if (program.deferrable && !detail::reads_derivatives(shader) &&
        (!detail::CheapToShade<S> || simd_level() >= SimdLevel::kAvx512)) {
      program.shade_mixed = detail::wide_shade_mixed<S>(simd_level());
      program.mixed_winners = !detail::CheapToShade<S>;
    }
  } else {
    program.shade_block = &detail::shade_block<S>;
  }
  detail::draw_clip_space(framebuffer, state, vertices, indices.data(), indices.size(), program);
}

}  // namespace softrast
