// polydg's modules: libraries of its own that are loaded the first time they are needed, so that
// their dependencies are not loaded at every start (libpolydg_openvdb.so: OpenVDB, 30 ms;
// libpolydg_assimp.so: assimp and the libraries it pulls in, 7.5 ms).
#pragma once

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace polydg {

namespace detail {

/// The folder of the file (library or program) that holds this code.
inline std::filesystem::path folderOfThisCode() {
  Dl_info info;
  static const int anchor = 0;
  if (::dladdr(&anchor, &info) == 0 || info.dli_fname == nullptr || *info.dli_fname == '\0')
    return {};
  std::error_code ec;
  const std::filesystem::path file = std::filesystem::canonical(info.dli_fname, ec);
  return ec ? std::filesystem::path() : file.parent_path();
}

}  // namespace detail

/// Loads polydg's module `file` and returns its function `entry`, or throws std::runtime_error
/// saying that `what` needs the module, the places tried and `advice`. The places, in order:
/// beside the library or program that holds this code (libpolydg.so, installed or built), the
/// library folder of an installed program (`binToLib`, relative to its own), and the folder
/// above a program's (the build tree, whose programs and tests are one folder below the
/// modules). No path of the build is written into the code: an installed polydg must not depend
/// on its build tree. The module is never closed: what it makes may live until the end.
inline void* loadModuleEntry(const char* file, const char* binToLib, const char* entry,
                             const std::string& what, const std::string& advice) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  const fs::path here = detail::folderOfThisCode();
  if (!here.empty()) candidates.push_back(here / file);
  std::error_code ec;
  const fs::path program = fs::canonical("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(program.parent_path() / binToLib / file);
    candidates.push_back(program.parent_path().parent_path() / file);
  }
  std::string tried;
  for (const fs::path& path : candidates) {
    if (!fs::exists(path, ec)) {
      tried += (tried.empty() ? "" : ", ") + path.string() + " (absent)";
      continue;
    }
    void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      tried += (tried.empty() ? "" : ", ") + path.string() + " (" + ::dlerror() + ")";
      continue;
    }
    if (void* function = ::dlsym(module, entry)) return function;
    tried += (tried.empty() ? "" : ", ") + path.string() + " (no " + entry + ")";
  }
  throw std::runtime_error(what + " needs polydg's module " + file +
                           ", which could not be loaded (tried " + tried + "); " + advice);
}

}  // namespace polydg
