#include "cli/bench/suites.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/bench/external_commands.h"
#include "cli/bench/meshing_benchmark.h"
#include "model/files.h"
#include "polydg/mesh/surface_io.h"

namespace polydg::bench {

namespace fs = std::filesystem;

namespace {

/// polydg's whole `polydg mesh` command (read, checks, slicing, validation, DG checks, the
/// VTU written) against Debian's `tetgen -pQ` on the same closed 75k-triangle surface (the
/// bunny of scripts/get-models.sh), run alternately `rounds` times in one run. The project
/// does not link tetgen; the comparison is skipped, with one line saying why, when the bunny
/// or the tetgen command is missing.
nlohmann::json againstTetgen(const BenchOptions& o, int rounds, bool quiet) {
  const fs::path bunny = fs::path(o.dataDir) / "models" / "bunny.off";
  auto skipped = [&](const std::string& why) {
    if (!quiet) std::cout << "meshing against tetgen skipped: " << why << std::endl;
    return nlohmann::json{{"comparison", "tetgen -pQ"}, {"skipped", why}};
  };
  if (!fs::exists(bunny))
    return skipped(bunny.string() + " not found; scripts/get-models.sh fetches it");
  if (!commandExists("tetgen"))
    return skipped("tetgen not installed; scripts/get-models.sh installs it (Debian's tetgen)");
  const std::optional<fs::path> self = polydgExecutable();
  if (!self) return skipped("cannot find the polydg executable through /proc/self/exe");
  const fs::path dir = fs::temp_directory_path() / ("polydg-tetgen-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(bunny, dir / "bunny.off", fs::copy_options::overwrite_existing);
  const std::string polydg = shellQuoted(self->string()) + " mesh " +
                             shellQuoted((dir / "bunny.off").string()) + " --cells 64 -o " +
                             shellQuoted((dir / "bunny.vtu").string()) + " --quiet";
  const std::string tetgen =
      "tetgen -pQ " + shellQuoted((dir / "bunny.off").string()) + " > /dev/null";
  std::vector<double> ours, theirs;
  for (int r = 0; r < rounds; ++r) {
    ours.push_back(commandSeconds(polydg));
    theirs.push_back(commandSeconds(tetgen));
    if (ours.back() < 0 || theirs.back() < 0) {
      fs::remove_all(dir);
      return skipped(std::string(ours.back() < 0 ? "polydg mesh" : "tetgen") + " failed");
    }
  }
  fs::remove_all(dir);
  const double a = median(ours), b = median(theirs);
  if (!quiet)
    std::cout << "bunny (75,408 triangles), 64 cells: polydg mesh " << a << " s, tetgen -pQ " << b
              << " s (medians of " << rounds << ", run alternately)" << std::endl;
  return {{"comparison", "tetgen -pQ"}, {"model", "bunny.off"},   {"cells", 64},
          {"rounds", rounds},           {"polydg_seconds", ours}, {"tetgen_seconds", theirs},
          {"polydg_median", a},         {"tetgen_median", b},     {"ratio", a / b}};
}

}  // namespace

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
                       {"t_validate", run.geometryCheckSeconds},
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
               run.geometryCheckSeconds + run.dgCheckSeconds);
      elements.add(label, n, static_cast<double>(m.elements));
      volume.add(label, n, std::max(m.volumeRelError, std::numeric_limits<double>::epsilon()));
      if (!quiet)
        std::cout << m.model << ", " << n << " cells: " << m.elements << " elements, meshing "
                  << m.secondsTotal << " s (slice " << slice << " s), validation "
                  << run.geometryCheckSeconds << " s + DG checks " << run.dgCheckSeconds << " s"
                  << std::endl;
    }
  if (!o.quick) s.json.push_back(againstTetgen(o, 7, quiet));
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
