// The polydg program's OpenBLAS helper threads (cli/main.cpp; a header so that a test can call
// what main() calls).
#pragma once

#include <dlfcn.h>

namespace polydg::cli {

/// Stops OpenBLAS's idle helper threads; returns whether this process has an OpenBLAS to stop.
/// Debian's OpenBLAS (with threads) starts them when it is loaded, before main(), and each
/// spins, yielding, for about 0.1 s before it sleeps: on two cores that took a core's time from
/// the start of every command, most of which never call BLAS (only CHOLMOD's factorizations
/// do). OpenBLAS starts them again at its first call that runs on several threads. Another
/// BLAS (no blas_thread_shutdown_) is left alone.
inline bool stopIdleBlasThreads() {
  using Shutdown = int (*)();
  const auto shutdown = reinterpret_cast<Shutdown>(dlsym(RTLD_DEFAULT, "blas_thread_shutdown_"));
  if (shutdown == nullptr) return false;
  shutdown();
  return true;
}

}  // namespace polydg::cli
