// core/thread_pool.cpp: workers sleep on a condition variable between jobs; a job is a counter
// of indices that the workers and the caller take from until it runs out.
#include "softrast/detail/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace softrast::detail {
namespace {

thread_local bool t_inside_pool_job = false;

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
      busy_ = helpers;
      ++generation_;
    }
    if (helpers > 0) wake_.notify_all();
    work();
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
  }

 private:
  void work() {
    bool was_inside = t_inside_pool_job;
    t_inside_pool_job = true;
    for (size_t i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) fn_(context_, i);
    t_inside_pool_job = was_inside;
  }

  void worker(int id) {
    uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || (generation_ != seen && id < helpers_); });
        if (stopping_) return;
        seen = generation_;
      }
      work();
      std::lock_guard lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex job_mutex_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stopping_ = false;
  uint64_t generation_ = 0;
  int helpers_ = 0;
  int busy_ = 0;
  void (*fn_)(void*, size_t) = nullptr;
  void* context_ = nullptr;
  size_t count_ = 0;
  std::atomic<size_t> next_{0};
};

}  // namespace

int hardware_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
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
