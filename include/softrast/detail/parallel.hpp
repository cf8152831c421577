// softrast/detail/parallel.hpp: one process-wide pool of worker threads and a parallel for over
// indices. The calling thread works too; a parallel_for inside a worker runs serially (no nesting).
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

namespace softrast::detail {

// Threads the machine offers (at least 1).
int hardware_threads();

// Calls fn(context, i) for every i in [0, count), spread over at most `max_threads` threads
// (including the caller), and returns when all calls have returned. Indices are handed out one
// at a time in increasing order, so give each index a sizeable piece of work.
void parallel_for(size_t count, int max_threads, void (*fn)(void* context, size_t index),
                  void* context);

// The calling thread's place among the threads of a parallel_for: 0 for the thread that calls it,
// k for the pool's k-th worker (parallel_for with max_threads T runs on places 0 to T - 1). A
// thread keeps its place for the life of the process, so work handed out by place meets the same
// thread, and the same cache, from one parallel_for to the next.
int parallel_slot();

template <class F>
void parallel_for(size_t count, int max_threads, F&& f) {
  using Fn = std::remove_reference_t<F>;
  parallel_for(
      count, max_threads, [](void* c, size_t i) { (*static_cast<Fn*>(c))(i); },
      const_cast<void*>(static_cast<const void*>(&f)));
}

}  // namespace softrast::detail
