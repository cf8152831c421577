// core/thread_pool.cpp: workers sleep on a condition variable between jobs; a job is a counter
// of indices that the workers and the caller take from until it runs out.
//
// A draw runs several short jobs back to back (vertices, then per batch the setup and the
// tiles), and a thread woken from a condition variable starts tens of microseconds late (more on
// a virtual machine), so workers and the waiting caller first spin for a short while (about 50
// microseconds) watching for the next job or the end of this one, and only then sleep.
#include "softrast/detail/parallel.hpp"

#include <emmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace softrast::detail {
namespace {

thread_local bool t_inside_pool_job = false;
thread_local int t_slot = 0;  // parallel_slot(): 0 outside the pool's workers

// Spins until done() or about kSpinTime has passed; true if done() came true.
constexpr auto kSpinTime = std::chrono::microseconds(50);
template <class Done>
bool spin_until(Done&& done) {
  auto start = std::chrono::steady_clock::now();
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (done()) return true;
      _mm_pause();
    }
    if (std::chrono::steady_clock::now() - start > kSpinTime) return done();
  }
}

class ThreadPool {
 public:
  ThreadPool() {
    int workers = hardware_threads() - 1;
    for (int i = 0; i < workers; ++i) threads_.emplace_back([this, i] { worker(i); });
  }
  ~ThreadPool() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }

  static ThreadPool& shared() {
    static ThreadPool pool;
    return pool;
  }

  void run(size_t count, int max_threads, void (*fn)(void*, size_t), void* context) {
    std::lock_guard job_lock(job_mutex_);  // one job at a time from any number of callers
    int helpers = std::min<int>(max_threads - 1, int(threads_.size()));
    helpers = std::min<int>(helpers, int(count) - 1);
    {
      std::lock_guard lock(mutex_);
      fn_ = fn;
      context_ = context;
      count_ = count;
      next_.store(0);
      helpers_ = helpers;
      busy_.store(helpers);
      generation_.fetch_add(1, std::memory_order_release);
    }
    if (helpers > 0) wake_.notify_all();
    work();
    if (spin_until([this] { return busy_.load(std::memory_order_acquire) == 0; })) return;
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return busy_.load() == 0; });
  }

 private:
  void work() {
    bool was_inside = t_inside_pool_job;
    t_inside_pool_job = true;
    for (size_t i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) fn_(context_, i);
    t_inside_pool_job = was_inside;
  }

  void worker(int id) {
    t_slot = id + 1;
    uint64_t seen = 0;
    for (;;) {
      spin_until([&] { return generation_.load(std::memory_order_acquire) != seen; });
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock,
                   [&] { return stopping_ || (generation_.load() != seen && id < helpers_); });
        if (stopping_) return;
        seen = generation_.load();
      }
      work();
      std::lock_guard lock(mutex_);
      if (busy_.fetch_sub(1) == 1) done_.notify_one();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex job_mutex_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stopping_ = false;
  std::atomic<uint64_t> generation_{0};
  int helpers_ = 0;
  std::atomic<int> busy_{0};
  void (*fn_)(void*, size_t) = nullptr;
  void* context_ = nullptr;
  size_t count_ = 0;
  std::atomic<size_t> next_{0};
};

}  // namespace

int hardware_threads() {
  // Asked once: glibc answers by reading /sys/devices/system/cpu/online, and every draw asks
  // (a glTF scene of 100,000 one-triangle nodes spent a tenth of its time in those reads).
  static const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  return threads;
}

int parallel_slot() {
  return t_slot;
}

void parallel_for(size_t count, int max_threads, void (*fn)(void*, size_t), void* context) {
  if (count == 0) return;
  if (max_threads <= 1 || count == 1 || t_inside_pool_job) {
    for (size_t i = 0; i < count; ++i) fn(context, i);
    return;
  }
  ThreadPool::shared().run(count, max_threads, fn, context);
}

}  // namespace softrast::detail
