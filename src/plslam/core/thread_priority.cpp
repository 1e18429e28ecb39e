#include "plslam/core/thread_priority.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

namespace plslam::core {

bool lower_this_thread_priority(int nice_increment) {
  // On Linux a thread is a task with its own nice value: PRIO_PROCESS with the thread id.
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  const int current = getpriority(PRIO_PROCESS, tid);
  return setpriority(PRIO_PROCESS, tid, current + nice_increment) == 0;
}

bool name_this_thread(const char* name) {
  char cut[16] = {};  // the kernel's TASK_COMM_LEN, the terminating zero included
  std::memcpy(cut, name, std::min(std::strlen(name), sizeof(cut) - 1));
  return pthread_setname_np(pthread_self(), cut) == 0;
}

}  // namespace plslam::core
