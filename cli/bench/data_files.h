// Where the polydg binary finds the data files it ships with (the models `polydg bench --suite
// meshing` reads): share/polydg beside the folder of the executable, as CMake lays them out in
// the build tree (build/cli/polydg, build/share/polydg/) and as install() does
// (<prefix>/bin/polydg, <prefix>/share/polydg/). No path of the source tree is compiled in.
#pragma once

#include <filesystem>

namespace polydg::bench {

/// <folder of the running executable>/../share/polydg, normalized. The executable is found
/// through /proc/self/exe (Linux). Throws std::runtime_error if /proc/self/exe cannot be read.
/// The folder need not exist; callers check for the files they need.
std::filesystem::path dataDirectory();

}  // namespace polydg::bench
