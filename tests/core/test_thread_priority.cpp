#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <thread>

#include <gtest/gtest.h>

#include "plslam/core/thread_priority.h"

namespace plslam::core {
namespace {

int my_nice() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

TEST(ThreadPriority, LowersOnlyTheCallingThread) {
  const int before = my_nice();
  int inside = 0, after_call = 0;
  std::thread t([&] {
    inside = my_nice();
    ASSERT_TRUE(lower_this_thread_priority(3));
    after_call = my_nice();
  });
  t.join();
  EXPECT_EQ(inside, before);  // a new thread starts at its creator's value
  EXPECT_EQ(after_call, std::min(before + 3, 19));
  EXPECT_EQ(my_nice(), before);
}

}  // namespace
}  // namespace plslam::core
