#include "cli/bench/suites.h"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cli/bench/meshing_benchmark.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/files.h"

namespace polydg::bench {

namespace fs = std::filesystem;

SuiteOutput meshingSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"meshing", nlohmann::json::array(), nlohmann::json::array(), {}};
  const std::string torusPath = (fs::path(o.dataDir) / "torus.obj").string();
  if (!fs::exists(torusPath))
    throw InputError(torusPath +
                     " not found; pass the folder that holds polydg's bundled models "
                     "(share/polydg of the build or installation) with --data");
  std::vector<std::pair<std::string, TriangleSurface>> models;
  models.emplace_back("torus.obj", readSurface(torusPath));
  if (!o.quick) {
    models.emplace_back("sphere", benchmarkModel("sphere"));
    models.emplace_back("torus_knot", benchmarkModel("torus_knot"));
  }
  const std::vector<int> cells =
      o.quick ? std::vector<int>{8, 16} : std::vector<int>{16, 32, 64, 128};
  SeriesSet time, elements, volume;
  for (const auto& [name, surface] : models)
    for (int n : cells) {
      const MeshingCostRun run = runMeshingCostCase(name, surface, n);
      const MeshingBenchmarkRun& m = run.meshing;
      nlohmann::json phases = nlohmann::json::object();
      double slice = 0.0;
      for (const auto& [phase, seconds] : m.phases) {
        phases[phase] = seconds;
        if (phase == "slice") slice = seconds;
      }
      nlohmann::json j{{"model", m.model},
                       {"triangles", m.triangles},
                       {"cells", m.cells},
                       {"elements", m.elements},
                       {"hexahedra", m.hexahedra},
                       {"polyhedra", m.polyhedra},
                       {"slivers_merged", m.slivers_merged},
                       {"volume_rel_error", m.volumeRelError},
                       {"valid", m.valid},
                       {"t_total", m.secondsTotal},
                       {"t_slice", slice},
                       {"t_validate", run.geometricValidationSeconds},
                       {"t_dg_checks", run.dgCheckSeconds},
                       {"dg_elements", run.dgElements},
                       {"dg_passed", run.dgPassed},
                       {"timings_s", phases}};
      s.json.push_back(j);
      s.rows.push_back(j);
      const std::string label = m.model + " (" + std::to_string(m.triangles) + " triangles)";
      time.add(m.model + ": meshing (total)", n, m.secondsTotal);
      time.add(m.model + ": slicing", n, slice);
      time.add(m.model + ": geometric + DG validation", n,
               run.geometricValidationSeconds + run.dgCheckSeconds);
      elements.add(label, n, static_cast<double>(m.elements));
      volume.add(label, n, std::max(m.volumeRelError, std::numeric_limits<double>::epsilon()));
      if (!quiet)
        std::cout << m.model << ", " << n << " cells: " << m.elements << " elements, meshing "
                  << m.secondsTotal << " s (slice " << slice << " s), validation "
                  << run.geometricValidationSeconds << " s + DG checks " << run.dgCheckSeconds
                  << " s" << std::endl;
    }
  s.plots.push_back({"meshing_time.svg",
                     {"Meshing: wall time against grid resolution (2 cores)",
                      {"cells along the longest side", AxisScale::Log},
                      {"wall time [s]", AxisScale::Log},
                      time.series()}});
  s.plots.push_back({"meshing_elements.svg",
                     {"Meshing: elements against grid resolution",
                      {"cells along the longest side", AxisScale::Log},
                      {"elements", AxisScale::Log},
                      elements.series()}});
  s.plots.push_back({"meshing_volume_error.svg",
                     {"Meshing: relative volume error of the mesh",
                      {"cells along the longest side", AxisScale::Log},
                      {"|volume - surface volume| / volume (0 drawn at 2.2e-16)", AxisScale::Log},
                      volume.series()}});
  return s;
}

}  // namespace polydg::bench
