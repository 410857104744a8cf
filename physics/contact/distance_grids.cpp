// Loading polydg's OpenVDB module (distance_grids.h) the first time a field is built.
#include "physics/contact/distance_grids.h"

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace polydg {

namespace {

namespace fs = std::filesystem;

/// The folder of the file (library or program) that holds this code.
fs::path folderOfThisCode() {
  Dl_info info;
  static const int anchor = 0;
  if (::dladdr(&anchor, &info) == 0 || info.dli_fname == nullptr || *info.dli_fname == '\0')
    return {};
  std::error_code ec;
  const fs::path file = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : file.parent_path();
}

/// Where the module may be, in order: beside the library or program that holds this code
/// (libpolydg.so, installed or built), in the library folder of an installed program, and in
/// the folder above a program's (the build tree, whose programs and tests are one folder below
/// the module). No path of the build is written into the code: an installed polydg must not
/// depend on its build tree.
std::vector<fs::path> moduleCandidates() {
  std::vector<fs::path> out;
  const fs::path here = folderOfThisCode();
  if (!here.empty()) out.push_back(here / POLYDG_OPENVDB_MODULE);
  std::error_code ec;
  const fs::path program = fs::canonical("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(program.parent_path() / POLYDG_BIN_TO_LIB / POLYDG_OPENVDB_MODULE);
    out.push_back(program.parent_path().parent_path() / POLYDG_OPENVDB_MODULE);
  }
  return out;
}

BuildDistanceGrids loadModule() {
  std::string tried;
  for (const fs::path& path : moduleCandidates()) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      tried += (tried.empty() ? "" : ", ") + path.string() + " (absent)";
      continue;
    }
    // Never closed: the grids it builds live as long as the obstacles that hold them.
    void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      tried += (tried.empty() ? "" : ", ") + path.string() + " (" + ::dlerror() + ")";
      continue;
    }
    if (void* entry = ::dlsym(module, kBuildDistanceGrids))
      return reinterpret_cast<BuildDistanceGrids>(entry);
    tried += (tried.empty() ? "" : ", ") + path.string() + " (no " + kBuildDistanceGrids + ")";
  }
  throw std::runtime_error(
      "the distance field of a surface obstacle needs polydg's OpenVDB module " +
      std::string(POLYDG_OPENVDB_MODULE) + ", which could not be loaded (tried " + tried +
      "); reinstall polydg, or use half-space obstacles");
}

}  // namespace

std::shared_ptr<const DistanceGrids> buildDistanceGrids(const IndexSpaceSurface& surface) {
  // Loaded once; a failure is not remembered, so a later call tries again.
  static const BuildDistanceGrids build = loadModule();
  return std::shared_ptr<const DistanceGrids>(build(surface));
}

}  // namespace polydg
