#pragma once
// Background threads that must not take the cores from tracking: on 2 cores, tracking, local
// mapping and the image prefetch already compete, and loop detection or a global BA can wait.

namespace plslam::core {

// Lowers the calling thread's scheduling priority by `nice_increment` (Linux: per-thread nice
// value). Returns false when the system refused; the thread then runs at its old priority.
bool lower_this_thread_priority(int nice_increment);

}  // namespace plslam::core
