// core/prefetch.hpp: asking the cache for a line ahead of its use.
#pragma once

namespace softrast::detail {

// PREFETCHT0 of the line holding `p`, written out: GCC 12 drops __builtin_prefetch where it is the
// only effect of an inlined function or of a loop (such code counts as having no effect, and goes
// with the call), which is exactly how the tile loops use it.
[[gnu::always_inline]] inline void prefetch_line(const void* p) {
#if defined(__x86_64__) && defined(__GNUC__)
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
#else
  __builtin_prefetch(p, 0, 3);
#endif
}

// PREFETCHW of the line holding `p`: the line comes for writing (exclusive), so that a store to
// it later need not wait for the other cores' copies to be invalidated. Only where
// prefetch_for_write_supported() (a CPU without the instruction may not decode it).
[[gnu::always_inline]] inline void prefetch_line_for_write(const void* p) {
#if defined(__x86_64__) && defined(__GNUC__)
  asm volatile("prefetchw %0" : : "m"(*static_cast<const char*>(p)));
#else
  __builtin_prefetch(p, 1, 3);
#endif
}

// Whether this CPU has PREFETCHW (CPUID 0x80000001, ECX bit 8), checked once.
bool prefetch_for_write_supported();

}  // namespace softrast::detail
