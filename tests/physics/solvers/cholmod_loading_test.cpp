// physics/solvers/cholmod_loader.h: CHOLMOD, and the BLAS it brings, is loaded by the first
// factorization, not when a program that links polydg starts. A test program of its own: in
// another, an earlier test could have factorized first.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>

#include "tests/support/run_polydg.h"

namespace {

bool isLoaded(const char* soname) {
  void* handle = dlopen(soname, RTLD_NOW | RTLD_NOLOAD);
  if (handle != nullptr) dlclose(handle);
  return handle != nullptr;
}

TEST(CholmodLoading, TheFirstFactorizationLoadsCholmodAndItSolves) {
  EXPECT_FALSE(isLoaded(POLYDG_CHOLMOD_SONAME));
  // -u'' = 2 on (0, 1), u(0) = u(1) = 0, by central differences: u = x (1 - x) at the nodes,
  // exactly (the scheme is exact for quadratics).
  constexpr int n = 99;
  const double h = 1.0 / (n + 1);
  Eigen::SparseMatrix<double> a(n, n);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 2.0 / (h * h));
    if (i > 0) entries.emplace_back(i, i - 1, -1.0 / (h * h));
    if (i + 1 < n) entries.emplace_back(i, i + 1, -1.0 / (h * h));
  }
  a.setFromTriplets(entries.begin(), entries.end());
  const Eigen::VectorXd b = Eigen::VectorXd::Constant(n, 2.0);
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt(a);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::VectorXd u = llt.solve(b);
  EXPECT_TRUE(isLoaded(POLYDG_CHOLMOD_SONAME));
  for (int i = 0; i < n; ++i) {
    const double x = (i + 1) * h;
    EXPECT_NEAR(u[i], x * (1.0 - x), 1e-12) << i;
  }
}

TEST(CholmodLoading, AProgramThatDoesNotFactorizeDoesNotLoadIt) {
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_is("intel") && __builtin_cpu_supports("avx2"))
    GTEST_SKIP() << "on Intel CPUs with AVX2 polydg loads CHOLMOD at its start, to check the "
                    "BLAS kernels (cli/main.cpp)";
#endif
  // The dynamic loader names every library it loads (LD_DEBUG=libs); without a kernel choice
  // of the user's (OPENBLAS_CORETYPE), which the program would respect.
  const polydg::testing::CommandResult info = polydg::testing::runShell(
      "env -u OPENBLAS_CORETYPE LD_DEBUG=libs " + std::string(POLYDG_BINARY) + " info " +
      polydg::testing::testData("torus.obj"));
  ASSERT_EQ(info.exitCode, 0) << info.out;
  EXPECT_NE(info.out.find("libjemalloc"), std::string::npos) << info.out;  // the log is there
  EXPECT_EQ(info.out.find(POLYDG_CHOLMOD_SONAME), std::string::npos) << info.out;
}

}  // namespace
