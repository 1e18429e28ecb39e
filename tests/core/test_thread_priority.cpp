#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <string>
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

std::string my_name() {
  char name[16] = {};
  pthread_getname_np(pthread_self(), name, sizeof(name));
  return name;
}

TEST(ThreadName, NamesOnlyTheCallingThreadAndCutsAtFifteenCharacters) {
  const std::string before = my_name();
  std::string inside, cut;
  std::thread t([&] {
    ASSERT_TRUE(name_this_thread("plslam-mapping"));
    inside = my_name();
    ASSERT_TRUE(name_this_thread("plslam-a-name-longer-than-fifteen"));
    cut = my_name();
  });
  t.join();
  EXPECT_EQ(inside, "plslam-mapping");
  EXPECT_EQ(cut, "plslam-a-name-l");
  EXPECT_EQ(my_name(), before);
}

}  // namespace
}  // namespace plslam::core
