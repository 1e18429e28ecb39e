#include "plslam/core/worker_pool.h"

#include <algorithm>

#include "plslam/core/thread_priority.h"

namespace plslam::core {

WorkerPool::WorkerPool(int threads, const std::string& name) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) {
    workers_.emplace_back([this, name] {
      name_this_thread(name.c_str());
      work_loop();
    });
  }
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  work_cv_.notify_all();
  for (auto& w : workers_) w.join();
}

void WorkerPool::drain(std::unique_lock<std::mutex>& lock) {
  while (next_ < chunks_) {
    const int c = next_++;
    ++running_;
    const auto* body = body_;
    lock.unlock();
    std::exception_ptr err;
    try {
      (*body)(c);
    } catch (...) {
      err = std::current_exception();
    }
    lock.lock();
    if (err && !error_) error_ = err;
    if (--running_ == 0 && next_ == chunks_) done_cv_.notify_all();
  }
}

void WorkerPool::work_loop() {
  std::unique_lock<std::mutex> lock(mu_);
  long seen = 0;
  for (;;) {
    work_cv_.wait(lock, [&] { return stop_ || (job_ != seen && next_ < chunks_); });
    if (stop_) return;
    seen = job_;
    drain(lock);
  }
}

void WorkerPool::run(int chunks, const std::function<void(int)>& body) {
  if (chunks <= 0) return;
  std::unique_lock<std::mutex> lock(mu_);
  body_ = &body;
  chunks_ = chunks;
  next_ = 0;
  running_ = 0;
  error_ = nullptr;
  ++job_;
  if (!workers_.empty() && chunks > 1) work_cv_.notify_all();
  drain(lock);
  done_cv_.wait(lock, [&] { return running_ == 0 && next_ == chunks_; });
  body_ = nullptr;
  chunks_ = 0;
  if (error_) {
    auto err = error_;
    error_ = nullptr;
    std::rethrow_exception(err);
  }
}

}  // namespace plslam::core
