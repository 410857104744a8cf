// CHOLMOD loaded on first use (cholmod_loader.h). The CHOLMOD functions polydg calls through
// Eigen's CholmodSupport are defined here, hidden (not exported from libpolydg, so a program
// that links CHOLMOD itself keeps its own), each passing its call on to the library's.
#include "physics/solvers/cholmod_loader.h"

#include <dlfcn.h>

#include <cholmod.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace polydg {

namespace {

void* library = nullptr;

/// CHOLMOD's function `name`, the library loaded first.
void* cholmodFunction(const char* name) {
  loadCholmod();
  void* function = ::dlsym(library, name);
  if (function == nullptr)
    throw std::runtime_error(std::string(POLYDG_CHOLMOD_SONAME) + " has no function " + name +
                             "; install the CHOLMOD that polydg was built with (Debian: "
                             "libcholmod3)");
  return function;
}

/// The library's function of the same name as `Shim`, looked up once.
template <auto Shim>
auto real(const char* name) {
  static const auto function = reinterpret_cast<decltype(Shim)>(cholmodFunction(name));
  return function;
}

}  // namespace

void loadCholmod() {
  static std::once_flag once;
  std::call_once(once, [] {
    // RTLD_GLOBAL: its BLAS's symbols become visible (cli/main.cpp, cli/blas_threads.h).
    library = ::dlopen(POLYDG_CHOLMOD_SONAME, RTLD_NOW | RTLD_GLOBAL);
    if (library == nullptr)
      throw std::runtime_error(std::string("solving needs CHOLMOD, which could not be loaded (") +
                               ::dlerror() + "); install it (Debian: libcholmod3)");
  });
}

}  // namespace polydg

#define POLYDG_HIDDEN __attribute__((visibility("hidden")))

extern "C" {

POLYDG_HIDDEN int cholmod_start(cholmod_common* common) {
  return polydg::real<&cholmod_start>("cholmod_start")(common);
}

POLYDG_HIDDEN int cholmod_finish(cholmod_common* common) {
  return polydg::real<&cholmod_finish>("cholmod_finish")(common);
}

POLYDG_HIDDEN cholmod_factor* cholmod_analyze(cholmod_sparse* a, cholmod_common* common) {
  return polydg::real<&cholmod_analyze>("cholmod_analyze")(a, common);
}

POLYDG_HIDDEN int cholmod_factorize_p(cholmod_sparse* a, double beta[2], int* fset, size_t fsize,
                                      cholmod_factor* l, cholmod_common* common) {
  return polydg::real<&cholmod_factorize_p>("cholmod_factorize_p")(a, beta, fset, fsize, l, common);
}

POLYDG_HIDDEN cholmod_dense* cholmod_solve(int sys, cholmod_factor* l, cholmod_dense* b,
                                           cholmod_common* common) {
  return polydg::real<&cholmod_solve>("cholmod_solve")(sys, l, b, common);
}

POLYDG_HIDDEN int cholmod_free_dense(cholmod_dense** x, cholmod_common* common) {
  return polydg::real<&cholmod_free_dense>("cholmod_free_dense")(x, common);
}

POLYDG_HIDDEN int cholmod_free_factor(cholmod_factor** l, cholmod_common* common) {
  return polydg::real<&cholmod_free_factor>("cholmod_free_factor")(l, common);
}

}  // extern "C"
