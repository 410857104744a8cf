// What the tests need besides the build dependencies: Debian's assimp-testmodels (the model
// corpus) and, for the system interpreter /usr/bin/python3, python3-vtk9, python3-meshio and
// python3-numpy (independent volumes and VTU checks). scripts/setup.sh installs all of them. A
// missing package fails the tests that need it, naming the package: in CI a missing package must
// fail, never skip. Use as ASSERT_TRUE(packages::assimpTestModels()).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/assimp_models.h"

namespace polydg::packages {

/// The interpreter the Python checks run with: VTK and meshio are Debian packages, which only
/// the system interpreter can import.
inline const std::filesystem::path kSystemPython = "/usr/bin/python3";

/// Success if assimp's test models are installed (corpus::kAssimpModels).
inline ::testing::AssertionResult assimpTestModels() {
  if (std::filesystem::is_directory(corpus::kAssimpModels)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << corpus::kAssimpModels.string()
         << " is missing: install Debian's assimp-testmodels (scripts/setup.sh installs every "
            "package the tests need)";
}

/// Success if /usr/bin/python3 can import `module`, which Debian's `package` provides.
inline ::testing::AssertionResult pythonModule(const std::string& module,
                                               const std::string& package) {
  if (!std::filesystem::exists(kSystemPython))
    return ::testing::AssertionFailure()
           << kSystemPython.string() << " is missing: install Debian's python3 and " << package
           << " (scripts/setup.sh installs every package the tests need)";
  const std::string command =
      kSystemPython.string() + " -c 'import " + module + "' >/dev/null 2>&1";
  if (std::system(command.c_str()) == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << kSystemPython.string() << " cannot import " << module << ": install Debian's "
         << package << " (scripts/setup.sh installs every package the tests need)";
}

}  // namespace polydg::packages
