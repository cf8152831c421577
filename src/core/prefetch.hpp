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

}  // namespace softrast::detail
