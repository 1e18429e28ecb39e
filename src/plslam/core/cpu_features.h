#pragma once
// What the CPU running this process offers beyond baseline x86-64, read once. The library is
// built for the baseline; a few kernels are also compiled for AVX2 and chosen with this at run
// time (a flag, not GCC's target_clones: its ifunc resolvers crash under ThreadSanitizer).

namespace plslam::core {

// False on other architectures.
bool cpu_has_avx2();

}  // namespace plslam::core
