#pragma once
// A small fixed pool of worker threads for data-parallel loops.
//
// Why not TBB here: (1) the results must not depend on scheduling. run() hands out chunk
// indices, and callers give every chunk its own output and combine them in chunk order, so a
// reduction sums in the same order whatever thread ran which chunk and however many threads there
// are; (2) every hand-over is a std::mutex / std::condition_variable, which ThreadSanitizer sees,
// where TBB's task hand-over happens inside the uninstrumented libtbb.
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace plslam::core {

class WorkerPool {
 public:
  // threads: how many threads run the chunks, the caller's included (so threads - 1 workers are
  // started); <= 0 means one per hardware thread. The workers carry `name` (see name_this_thread).
  explicit WorkerPool(int threads, const std::string& name = "plslam-pool");
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(c) once for every c in [0, chunks), on the workers and the calling thread, and
  // returns when all have returned. The first exception a body throws is rethrown here (the other
  // chunks still run). Not reentrant: one run() at a time per pool.
  void run(int chunks, const std::function<void(int)>& body);

 private:
  void work_loop();
  // Takes and runs chunks of the current job until none is left; lock held on entry and exit.
  void drain(std::unique_lock<std::mutex>& lock);

  std::mutex mu_;
  std::condition_variable work_cv_;  // workers wait for a job or for stop
  std::condition_variable done_cv_;  // run() waits for the last chunk
  const std::function<void(int)>* body_ = nullptr;
  int chunks_ = 0;
  int next_ = 0;      // next chunk to hand out
  int running_ = 0;   // chunks handed out and not finished
  long job_ = 0;      // increments per run(), so a worker joins each job once
  bool stop_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> workers_;
};

// Splits [0, n) into `chunks` contiguous ranges of near-equal size, the same for a given n and
// chunks on every machine: chunk c is [chunk_begin(n, chunks, c), chunk_begin(n, chunks, c + 1)).
inline int chunk_begin(int n, int chunks, int c) {
  return static_cast<int>(static_cast<long long>(n) * c / chunks);
}

}  // namespace plslam::core
