// CHOLMOD is loaded the first time a matrix is factorized, not when polydg starts: it brings
// OpenBLAS, whose loading and helper threads cost every command about 9 ms at start (half of
// `polydg --version`), most of which never factorize. polydg's code calls CHOLMOD as usual
// (Eigen's CholmodSupport); the few CHOLMOD functions it calls are defined in
// cholmod_loader.cpp, which loads the library on the first call and passes each call on.
#pragma once

namespace polydg {

/// Loads CHOLMOD (and so the BLAS it uses) now, if it is not loaded yet, with its symbols
/// visible to the process (dlsym(RTLD_DEFAULT, ...) then finds OpenBLAS's). Throws
/// std::runtime_error, naming the library and the package that holds it, if it cannot be
/// loaded. Thread-safe.
void loadCholmod();

}  // namespace polydg
