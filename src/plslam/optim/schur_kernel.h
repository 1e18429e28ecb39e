#pragma once
// The innermost loop of the Schur elimination in ba_schur_lm.cpp on raw column-major arrays:
// one landmark's share of the reduced camera matrix. A portable version and, on x86-64 CPUs with
// AVX2 and FMA, an intrinsics version chosen at run time (the library builds without -march
// flags, and no Eigen code is compiled for AVX2: only this file's intrinsics are).
#include <cstddef>

namespace plslam::optim {

enum class SchurKernelImpl { kPortable, kAvx2Fma };

// kAvx2Fma when this CPU has AVX2 and FMA, else kPortable.
SchurKernelImpl best_schur_kernel();
const char* to_string(SchurKernelImpl impl);

// For a landmark with m observations and k (3 or 6) parameters: Y and W hold m column-major 6 x k
// blocks back to back (Y_a = W_a L^-1, W_a = J_cam' w J_landmark), cam[a] the camera slot of
// observation a (< 0: fixed camera, skipped). Subtracts Y_a W_c' (= (Y_c W_a')') from the upper
// block triangle of the column-major matrix S (leading dimension ld, 6x6 blocks per camera slot):
// for each pair a < c the block (min, max) of their slots, both orders when they share a slot,
// and Y_a W_a' once for each a. kAvx2Fma rounds differently (fused multiply-adds) but is otherwise
// the same computation; an unsupported impl falls back to kPortable.
void schur_landmark_update(SchurKernelImpl impl, int k, int m, const int* cam, const double* Y,
                           const double* W, double* S, std::ptrdiff_t ld);

}  // namespace plslam::optim
