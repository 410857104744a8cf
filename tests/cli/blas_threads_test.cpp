// cli/blas_threads.h: OpenBLAS's idle helper threads stop, and BLAS still multiplies (on its
// helpers again) afterwards. OpenBLAS comes in as in the program, through CHOLMOD.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <cstddef>
#include <filesystem>

#include <Eigen/Dense>

#include "cli/blas_threads.h"

namespace {

std::size_t threadsOfThisProcess() {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/task"))
    ++n;
  return n;
}

using Gemm = void (*)(const char*, const char*, const int*, const int*, const int*, const double*,
                      const double*, const int*, const double*, const int*, const double*, double*,
                      const int*);

TEST(BlasThreads, IdleHelpersStopAndAThreadedProductStillRuns) {
  ASSERT_NE(dlopen("libcholmod.so.3", RTLD_NOW | RTLD_GLOBAL), nullptr) << dlerror();
  using Count = int (*)();
  const auto count = reinterpret_cast<Count>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  const auto gemm = reinterpret_cast<Gemm>(dlsym(RTLD_DEFAULT, "dgemm_"));
  if (count == nullptr) GTEST_SKIP() << "the BLAS here is not OpenBLAS";
  ASSERT_NE(gemm, nullptr);
  // OpenBLAS computes on the calling thread and on count() - 1 helpers.
  const std::size_t helpers = static_cast<std::size_t>(count() - 1);
  const std::size_t before = threadsOfThisProcess();
  ASSERT_TRUE(polydg::cli::stopIdleBlasThreads());
  EXPECT_EQ(threadsOfThisProcess(), before - helpers);

  constexpr int n = 400;  // large enough for OpenBLAS to share the product among its threads
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(n, n), b = Eigen::MatrixXd::Random(n, n);
  Eigen::MatrixXd c(n, n);
  const double one = 1.0, zero = 0.0;
  gemm("N", "N", &n, &n, &n, &one, a.data(), &n, b.data(), &n, &zero, c.data(), &n);
  const Eigen::MatrixXd expected = a * b;
  EXPECT_LT((c - expected).cwiseAbs().maxCoeff(), 1e-12 * n);
  EXPECT_EQ(threadsOfThisProcess(), before);  // the helpers are back
}

}  // namespace
