// core/isa_target.hpp: the code between SOFTRAST_TARGET_BEGIN_AVX2 (or _AVX512) and
// SOFTRAST_TARGET_END is compiled for that instruction set, with GCC (its target pragmas) and
// with clang (which ignores them; the fuzz preset builds with it). For the kernels compiled once
// per SIMD level and picked at run time from simd_level(), so the binary runs on any x86-64.
#pragma once

#if defined(__clang__)
#define SOFTRAST_TARGET_BEGIN_AVX2 \
  _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
// _Pragma takes one string literal, not adjacent ones: one long line.
// clang-format off
#define SOFTRAST_TARGET_BEGIN_AVX512 _Pragma("clang attribute push(__attribute__((target(\"avx512f,avx512bw,avx512dq,avx512vl\"))), apply_to = function)")
// clang-format on
#define SOFTRAST_TARGET_END _Pragma("clang attribute pop")
#else
// GCC 12's _mm512_undefined_ps initialises a variable with itself, and -Wmaybe-uninitialized
// reports it inside every AVX-512 min/max (GCC bug 105593, fixed in GCC 13): off in the region.
#define SOFTRAST_TARGET_BEGIN_GCC(isa)                                    \
  _Pragma("GCC push_options") _Pragma(isa) _Pragma("GCC diagnostic push") \
      _Pragma("GCC diagnostic ignored \"-Wmaybe-uninitialized\"")
#define SOFTRAST_TARGET_BEGIN_AVX2 SOFTRAST_TARGET_BEGIN_GCC("GCC target(\"avx2\")")
#define SOFTRAST_TARGET_BEGIN_AVX512 \
  SOFTRAST_TARGET_BEGIN_GCC("GCC target(\"avx512f,avx512bw,avx512dq,avx512vl\")")
#define SOFTRAST_TARGET_END _Pragma("GCC diagnostic pop") _Pragma("GCC pop_options")
#endif
