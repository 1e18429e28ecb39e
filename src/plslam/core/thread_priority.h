#pragma once
// Background threads that must not take the cores from tracking: on 2 cores, tracking, local
// mapping and the image prefetch already compete, and loop detection or a global BA can wait.
// Each of plslam's threads also carries a name, so that a profile says which stage took the CPU.

namespace plslam::core {

// Lowers the calling thread's scheduling priority by `nice_increment` (Linux: per-thread nice
// value). Returns false when the system refused; the thread then runs at its old priority.
bool lower_this_thread_priority(int nice_increment);

// Names the calling thread as `top -H`, `perf report --sort comm` and gdb show it. Linux keeps 15
// characters; a longer name is cut there. Returns false when the system refused.
bool name_this_thread(const char* name);

}  // namespace plslam::core
