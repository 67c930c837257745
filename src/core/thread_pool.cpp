#include "pointillist/core/thread_pool.hpp"

#include <algorithm>

namespace pointillist {

unsigned ThreadPool::max_threads() { return 4 * std::max(1u, std::thread::hardware_concurrency()); }

ThreadPool::ThreadPool(unsigned thread_count) {
  if (thread_count == 0) thread_count = std::max(1u, std::thread::hardware_concurrency());
  thread_count_ = std::min(thread_count, max_threads());
  for (unsigned i = 1; i < thread_count_; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::work_on_current_job(std::unique_lock<std::mutex>& lock) {
  // Entered and left with `lock` held; released while a task runs.
  while (job_ != nullptr && next_task_ < job_tasks_) {
    const std::size_t task = next_task_++;
    const auto* fn = job_;
    lock.unlock();
    std::exception_ptr err;
    try {
      (*fn)(task);
    } catch (...) {
      err = std::current_exception();
    }
    lock.lock();
    if (err && (!error_ || task < error_task_)) {
      error_ = err;
      error_task_ = task;
    }
    if (++finished_tasks_ == job_tasks_) done_.notify_all();
  }
}

void ThreadPool::worker_loop() {
  std::unique_lock lock(mutex_);
  std::size_t seen = generation_;
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
    if (stopping_) return;
    seen = generation_;
    ++busy_workers_;
    work_on_current_job(lock);
    if (--busy_workers_ == 0) done_.notify_all();
  }
}

void ThreadPool::run(std::size_t task_count, const std::function<void(std::size_t)>& fn) {
  if (task_count == 0) return;
  if (workers_.empty() || task_count == 1) {
    for (std::size_t i = 0; i < task_count; ++i) fn(i);
    return;
  }
  std::unique_lock lock(mutex_);
  job_ = &fn;
  job_tasks_ = task_count;
  next_task_ = 0;
  finished_tasks_ = 0;
  error_ = nullptr;
  error_task_ = 0;
  ++generation_;
  wake_.notify_all();
  work_on_current_job(lock);
  // Wait until every task finished and every worker left the job, so `fn` may die after return.
  done_.wait(lock, [&] { return finished_tasks_ == job_tasks_ && busy_workers_ == 0; });
  job_ = nullptr;
  std::exception_ptr err = error_;
  error_ = nullptr;
  lock.unlock();
  if (err) std::rethrow_exception(err);
}

void parallel_for(ThreadPool& pool, std::size_t count, std::size_t grain,
                  const std::function<void(std::size_t, std::size_t)>& fn) {
  if (count == 0) return;
  grain = std::max<std::size_t>(grain, 1);
  const std::size_t chunks = (count + grain - 1) / grain;
  pool.run(chunks, [&](std::size_t c) {
    const std::size_t begin = c * grain;
    fn(begin, std::min(count, begin + grain));
  });
}

}  // namespace pointillist
