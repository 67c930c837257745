// A fixed pool of worker threads. It is a parameter of every parallel function (no global pool).
//
// Determinism: `run` hands out task indices dynamically, so which thread runs a task varies, but
// callers make every task write only its own output slot and merge slots in index order, so the
// result never depends on the thread count or on timing.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace pointillist {

class ThreadPool {
 public:
  // `thread_count` = 0 means one per hardware thread; more than max_threads() is capped there
  // (thousands of threads only slow the work down, and can exhaust the machine's process limit).
  // The calling thread takes part in `run`, so a pool of N threads starts N - 1 workers.
  explicit ThreadPool(unsigned thread_count = 0);
  // 4 per hardware thread.
  static unsigned max_threads();
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned thread_count() const { return thread_count_; }

  // Calls fn(i) for every i in [0, task_count), spread over the threads; returns when all are
  // done. If tasks throw, the first exception (lowest task index) is rethrown after all finished.
  // Not reentrant: do not call `run` from inside a task.
  void run(std::size_t task_count, const std::function<void(std::size_t task)>& fn);

 private:
  void worker_loop();
  void work_on_current_job(std::unique_lock<std::mutex>& lock);

  unsigned thread_count_ = 1;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t)>* job_ = nullptr;
  std::size_t job_tasks_ = 0;
  std::size_t next_task_ = 0;
  std::size_t finished_tasks_ = 0;
  std::size_t generation_ = 0;
  unsigned busy_workers_ = 0;
  bool stopping_ = false;
  std::size_t error_task_ = 0;
  std::exception_ptr error_;
};

// Splits [0, count) into chunks of about `grain` items (at least 1 item each) and calls
// fn(begin, end) for each chunk on the pool. Chunk boundaries depend only on count and grain.
void parallel_for(ThreadPool& pool, std::size_t count, std::size_t grain,
                  const std::function<void(std::size_t begin, std::size_t end)>& fn);

}  // namespace pointillist
