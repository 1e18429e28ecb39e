#include "plslam/optim/schur_kernel.h"

#include <Eigen/Core>

#if defined(__x86_64__)
#include <immintrin.h>
#define PLSLAM_SCHUR_X86 1
#endif

namespace plslam::optim {
namespace {

namespace portable {
#include "plslam/optim/schur_kernel_pairs.inc"
}  // namespace portable

template <int K>
void update_portable(int m, const int* cam, const double* Y, const double* W, double* S,
                     std::ptrdiff_t ld) {
  using MatY = Eigen::Matrix<double, 6, K>;
  portable::landmark_pairs<K>(m, cam, Y, W, S, ld, [ld](const double* y, const double* w, double* s) {
    Eigen::Map<Eigen::Matrix<double, 6, 6>, 0, Eigen::OuterStride<>> block(s, 6, 6, Eigen::OuterStride<>(ld));
    block.noalias() -= Eigen::Map<const MatY>(y) * Eigen::Map<const MatY>(w).transpose();
  });
}

#ifdef PLSLAM_SCHUR_X86
// Only intrinsics on raw arrays below: no Eigen (or other inline library) code is instantiated for
// AVX2, so no AVX2 copy of a shared inline function can reach the portable callers at link time.
#if defined(__clang__)  // clang spells GCC's target pragma differently (fuzz builds use clang)
#pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#endif
namespace avx2 {
#include "plslam/optim/schur_kernel_pairs.inc"
}  // namespace avx2

// Rows 0-3 of a column in one 256-bit register, rows 4-5 in one 128-bit register.
template <int K>
void update_avx2(int m, const int* cam, const double* Y, const double* W, double* S,
                 std::ptrdiff_t ld) {
  avx2::landmark_pairs<K>(m, cam, Y, W, S, ld, [ld](const double* y, const double* w, double* s) {
    __m256d ylo[K];
    __m128d yhi[K];
    for (int k = 0; k < K; ++k) {
      ylo[k] = _mm256_loadu_pd(y + 6 * k);
      yhi[k] = _mm_loadu_pd(y + 6 * k + 4);
    }
    for (int j = 0; j < 6; ++j) {
      double* col = s + j * ld;
      __m256d lo = _mm256_loadu_pd(col);
      __m128d hi = _mm_loadu_pd(col + 4);
      for (int k = 0; k < K; ++k) {
        const double wjk = w[6 * k + j];
        lo = _mm256_fnmadd_pd(ylo[k], _mm256_set1_pd(wjk), lo);
        hi = _mm_fnmadd_pd(yhi[k], _mm_set1_pd(wjk), hi);
      }
      _mm256_storeu_pd(col, lo);
      _mm_storeu_pd(col + 4, hi);
    }
  });
}
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

}  // namespace

SchurKernelImpl best_schur_kernel() {
#ifdef PLSLAM_SCHUR_X86
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has ? SchurKernelImpl::kAvx2Fma : SchurKernelImpl::kPortable;
#else
  return SchurKernelImpl::kPortable;
#endif
}

const char* to_string(SchurKernelImpl impl) {
  return impl == SchurKernelImpl::kAvx2Fma ? "avx2+fma" : "portable";
}

void schur_landmark_update(SchurKernelImpl impl, int k, int m, const int* cam, const double* Y,
                           const double* W, double* S, std::ptrdiff_t ld) {
#ifdef PLSLAM_SCHUR_X86
  if (impl == SchurKernelImpl::kAvx2Fma && best_schur_kernel() == SchurKernelImpl::kAvx2Fma) {
    if (k == 3) return update_avx2<3>(m, cam, Y, W, S, ld);
    return update_avx2<6>(m, cam, Y, W, S, ld);
  }
#else
  (void)impl;
#endif
  if (k == 3) return update_portable<3>(m, cam, Y, W, S, ld);
  update_portable<6>(m, cam, Y, W, S, ld);
}

}  // namespace plslam::optim
