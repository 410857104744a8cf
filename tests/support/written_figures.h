// Figures of a file the polydg binary wrote, computed independently of polydg by
// tests/cli/written_figures.py (VTK, with the system interpreter): a solved VTU's cells, volume
// and integral of the displacement, the largest point displacement of a VTU or a VTP.
#pragma once

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/packages.h"

namespace polydg::testing {

/// The JSON line of written_figures.py for `files` (an object for one file, a list for
/// several; null, with a test failure, if it fails).
inline nlohmann::json writtenFigures(const std::vector<std::string>& files) {
  EXPECT_TRUE(packages::pythonModule("vtkmodules.vtkIOXML", "python3-vtk9"));
  std::string command =
      packages::kSystemPython.string() + " " + POLYDG_SOURCE_DIR + "/tests/cli/written_figures.py";
  for (const std::string& file : files) command += " '" + file + "'";
  command += " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    ADD_FAILURE() << "cannot run " << command;
    return nullptr;
  }
  std::string out;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) out += buffer.data();
  if (pclose(pipe) != 0) {
    ADD_FAILURE() << command << ": " << out;
    return nullptr;
  }
  return nlohmann::json::parse(out);
}

inline nlohmann::json writtenFigures(const std::string& file) {
  return writtenFigures(std::vector<std::string>{file});
}

/// Clapeyron's theorem for a solve under gravity alone: the strain energy 1/2 u^T K u equals
/// half the work of the load, 1/2 rho g . (integral of u over the body), for any Galerkin
/// solution. The integral comes from the written file (cell volumes by the divergence theorem
/// times the cells' mean displacement).
inline double gravityWorkHalf(const nlohmann::json& figures, double density,
                              const std::array<double, 3>& gravity) {
  double work = 0.0;
  for (int i = 0; i < 3; ++i)
    work += density * gravity[static_cast<std::size_t>(i)] *
            figures["displacement_integral"][static_cast<std::size_t>(i)].get<double>();
  return 0.5 * work;
}

}  // namespace polydg::testing
