// WorkerPool: every chunk runs exactly once, on several threads, exceptions come back to the
// caller, and a chunked reduction is bit-identical whatever the scheduling.
#include <pthread.h>

#include <atomic>
#include <mutex>
#include <numeric>
#include <set>
#include <string>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "plslam/core/worker_pool.h"

namespace plslam::core {
namespace {

TEST(WorkerPool, EveryChunkRunsExactlyOnce) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.threads(), 3);
  for (int chunks : {0, 1, 2, 7, 100}) {
    std::vector<int> runs(static_cast<std::size_t>(chunks), 0);
    pool.run(chunks, [&](int c) { ++runs[static_cast<std::size_t>(c)]; });  // one writer per slot
    for (int r : runs) EXPECT_EQ(r, 1) << chunks << " chunks";
  }
}

TEST(WorkerPool, UsesMoreThanTheCallingThread) {
  WorkerPool pool(2);
  std::mutex mu;
  std::set<std::thread::id> ids;
  // Each chunk waits until two distinct threads have taken chunks (or gives up after a while, so a
  // broken pool fails the assertion instead of hanging).
  std::atomic<int> started{0};
  pool.run(2, [&](int) {
    {
      std::lock_guard<std::mutex> lock(mu);
      ids.insert(std::this_thread::get_id());
    }
    ++started;
    for (int i = 0; i < 2000 && started.load() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  EXPECT_EQ(ids.size(), 2u);
}

TEST(WorkerPool, WorkersCarryThePoolsName) {
  WorkerPool pool(2, "test-pool");
  std::mutex mu;
  std::set<std::string> names;
  std::atomic<int> started{0};
  pool.run(2, [&](int) {  // as above: both chunks at once, so one runs on the worker
    char name[16] = {};
    pthread_getname_np(pthread_self(), name, sizeof(name));
    {
      std::lock_guard<std::mutex> lock(mu);
      names.insert(name);
    }
    ++started;
    for (int i = 0; i < 2000 && started.load() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  ASSERT_EQ(names.size(), 2u);
  EXPECT_EQ(names.count("test-pool"), 1u);  // the caller keeps its own name
}

TEST(WorkerPool, RethrowsTheFirstExceptionAndStaysUsable) {
  WorkerPool pool(2);
  std::atomic<int> ran{0};
  EXPECT_THROW(pool.run(10,
                        [&](int c) {
                          ++ran;
                          if (c == 3) throw std::runtime_error("chunk 3");
                        }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 10);  // the other chunks still ran
  int sum = 0;
  pool.run(1, [&](int) { sum = 42; });
  EXPECT_EQ(sum, 42);
}

TEST(WorkerPool, ChunkedSumIsBitIdenticalAcrossRuns) {
  // Values whose float sum depends on the order of addition.
  std::vector<double> v(100000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 1.0 / (1.0 + static_cast<double>(i % 977)) * ((i % 3) ? 1e8 : 1e-8);
  const int n = static_cast<int>(v.size());
  auto chunked_sum = [&](WorkerPool& pool) {
    const int chunks = pool.threads();
    std::vector<double> partial(static_cast<std::size_t>(chunks), 0.0);
    pool.run(chunks, [&](int c) {
      for (int i = chunk_begin(n, chunks, c); i < chunk_begin(n, chunks, c + 1); ++i) {
        partial[static_cast<std::size_t>(c)] += v[static_cast<std::size_t>(i)];
      }
    });
    return std::accumulate(partial.begin(), partial.end(), 0.0);
  };
  WorkerPool pool(2);
  const double first = chunked_sum(pool);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(chunked_sum(pool), first);
}

TEST(WorkerPool, ChunksCoverTheRangeContiguously) {
  for (int n : {0, 1, 5, 64, 1001}) {
    for (int chunks : {1, 2, 3, 16}) {
      EXPECT_EQ(chunk_begin(n, chunks, 0), 0);
      EXPECT_EQ(chunk_begin(n, chunks, chunks), n);
      for (int c = 0; c < chunks; ++c) EXPECT_LE(chunk_begin(n, chunks, c), chunk_begin(n, chunks, c + 1));
    }
  }
}

}  // namespace
}  // namespace plslam::core
