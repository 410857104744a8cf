#include "cli/bench/suites.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/bench/external_commands.h"
#include "cli/bench/gmsh_case.h"
#include "cli/bench/mesh_cell_count.h"
#include "cli/bench/meshing_benchmark.h"
#include "cli/bench/stl_file.h"
#include "model/files.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/util/error.h"

namespace polydg::bench {

namespace fs = std::filesystem;

namespace {

/// Why a comparison on `bunny` with `program` cannot run (`install`: how to get the program),
/// or nothing: the bunny, the program and polydg's own executable are there.
std::optional<std::string> missingForComparison(const fs::path& bunny, const std::string& program,
                                                const std::string& install) {
  if (!fs::exists(bunny)) return bunny.string() + " not found; scripts/get-models.sh fetches it";
  if (!commandExists(program)) return program + " not installed; " + install;
  if (!polydgExecutable()) return "cannot find the polydg executable through /proc/self/exe";
  return std::nullopt;
}

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
  if (const std::optional<std::string> why = missingForComparison(
          bunny, "tetgen", "scripts/get-models.sh installs it (Debian's tetgen)"))
    return skipped(*why);
  const fs::path self = *polydgExecutable();
  const fs::path dir = fs::temp_directory_path() / ("polydg-tetgen-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy_file(bunny, dir / "bunny.off", fs::copy_options::overwrite_existing);
  const std::string polydg = shellQuoted(self.string()) + " mesh " +
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

/// The Gmsh comparison's name in the report.
constexpr const char* kGmshComparison = "gmsh HXT";
/// Gmsh's threads (-nt), as issue 35 measured it on two cores.
constexpr int kGmshThreads = 2;

/// One mesher's runs at one resolution of the Gmsh comparison.
struct ComparedMesher {
  std::string mesher;   ///< "polydg" or "gmsh HXT"
  std::string command;  ///< the whole command, its output going to `log`
  fs::path output, log;
  std::function<std::size_t(const fs::path&)> countCells;  ///< the cells of `output`
  std::vector<double> seconds;                             ///< per round
  std::vector<std::size_t> peakBytes;                      ///< per round
  std::string error;  ///< why it has no figures, if it has none
};

/// Why a mesher failed, from its log: Gmsh's first "Error" line, else the last line.
std::string failureLine(const fs::path& log) {
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Error", 0) == 0) return line;
  return lastLine(log);
}

/// Runs `m` once (its output removed first), measured; after a failure it is not run again.
void measureRound(ComparedMesher& m) {
  if (!m.error.empty()) return;
  fs::remove(m.output);
  if (const std::optional<CommandCost> cost = measureCommand(m.command)) {
    m.seconds.push_back(cost->seconds);
    m.peakBytes.push_back(cost->peakRssBytes);
    return;
  }
  m.error = m.mesher + " failed";
  if (const std::string why = failureLine(m.log); !why.empty()) m.error += ": " + why;
}

/// The row of one mesher at `cells` cells (grid cell edge `cellSize`) on the bunny of
/// `triangles` triangles: medians of the rounds, the cells of what it wrote in the last round,
/// cells per second and peak bytes per cell.
nlohmann::json comparisonRow(const ComparedMesher& m, std::size_t triangles, int cells,
                             double cellSize) {
  nlohmann::json row{{"comparison", kGmshComparison},
                     {"model", "bunny.off"},
                     {"triangles", triangles},
                     {"mesher", m.mesher},
                     {"cells", cells},
                     {"cell_size", cellSize}};
  std::string error = m.error;
  std::size_t elements = 0;
  if (error.empty()) {
    try {
      elements = m.countCells(m.output);
    } catch (const InputError& e) {
      error = e.what();
    }
    if (error.empty() && elements == 0) error = m.output.filename().string() + " holds no cells";
  }
  if (!error.empty()) {
    row["error"] = error;
    return row;
  }
  const double seconds = median(m.seconds);
  const double peak = median(std::vector<double>(m.peakBytes.begin(), m.peakBytes.end()));
  row["elements"] = elements;
  row["wall_seconds"] = seconds;
  row["peak_rss_bytes"] = static_cast<std::size_t>(peak);
  row["elements_per_second"] = static_cast<double>(elements) / seconds;
  row["bytes_per_element"] = peak / static_cast<double>(elements);
  row["round_seconds"] = m.seconds;
  row["round_peak_rss_bytes"] = m.peakBytes;
  return row;
}

/// One mesher's figures in the line printed per resolution ("cells" are polydg's elements and
/// Gmsh's tetrahedra).
std::string summary(const nlohmann::json& r) {
  const std::string mesher = r["mesher"].get<std::string>();
  if (r.contains("error")) return mesher + ": " + r["error"].get<std::string>();
  return mesher + " " + std::to_string(r["elements"].get<std::size_t>()) + " cells, " +
         shortNumber(r["wall_seconds"].get<double>()) + " s, peak " +
         std::to_string(std::llround(r["peak_rss_bytes"].get<double>() / 1e6)) + " MB, " +
         std::to_string(std::llround(r["elements_per_second"].get<double>())) + " cells/s, " +
         std::to_string(std::llround(r["bytes_per_element"].get<double>())) + " B/cell";
}

/// polydg's and Gmsh's runs at `cells` cells, alternately for `rounds` rounds in `dir` (which
/// holds bunny.geo and bunny.stl): their two rows. Gmsh's mesh size is limited to polydg's cell
/// edge, unless `gmshOwnSizes` (its sizes from the surface's triangles, as issue 35 ran it).
std::pair<nlohmann::json, nlohmann::json> compareWithGmsh(const fs::path& self,
                                                          const fs::path& bunny,
                                                          const TriangleSurface& surface, int cells,
                                                          int rounds, const fs::path& dir,
                                                          bool gmshOwnSizes = false) {
  const double h = polydgCellSize(surface, cells);
  const std::string n = std::to_string(cells) + (gmshOwnSizes ? "_own" : "");
  ComparedMesher polydg, gmsh;
  polydg.mesher = "polydg";
  polydg.output = dir / ("polydg_" + n + ".vtu");
  polydg.log = dir / ("polydg_" + n + ".log");
  polydg.command = shellQuoted(self.string()) + " mesh " + shellQuoted(bunny.string()) +
                   " --cells " + n + " -o " + shellQuoted(polydg.output.string()) +
                   " --no-dg --quiet > " + shellQuoted(polydg.log.string()) + " 2>&1";
  polydg.countCells = [](const fs::path& file) { return vtuCells(file); };
  gmsh.mesher = gmshOwnSizes ? std::string(kGmshComparison) + " (own sizes)" : kGmshComparison;
  gmsh.output = dir / ("gmsh_" + n + ".msh");
  gmsh.log = dir / ("gmsh_" + n + ".log");
  gmsh.command =
      gmshCommand(dir / "bunny.geo", gmsh.output, {gmshOwnSizes ? 0.0 : h, kGmshThreads}) + " > " +
      shellQuoted(gmsh.log.string()) + " 2>&1";
  gmsh.countCells = [](const fs::path& file) { return mshTetrahedra(file); };
  for (int r = 0; r < rounds; ++r) {
    measureRound(polydg);
    measureRound(gmsh);
  }
  const std::size_t triangles = surface.triangles.size();
  std::pair<nlohmann::json, nlohmann::json> rows{comparisonRow(polydg, triangles, cells, h),
                                                 comparisonRow(gmsh, triangles, cells, h)};
  fs::remove(polydg.output);
  fs::remove(gmsh.output);
  return rows;
}

/// The whole `polydg mesh --no-dg` command against Gmsh's HXT (`gmsh -3 -nt 2`, Debian's gmsh)
/// on the bunny of scripts/get-models.sh, at 64, 128 and 200 cells along the longest side
/// (quick: 64) with Gmsh's mesh size limit polydg's cell edge, run alternately `rounds` times
/// each: wall time, peak memory (measureCommand()), cells, cells per second and bytes per cell.
/// Gmsh reads the bunny as an ASCII STL written from the same surface. Skipped, with one line
/// saying why, when the bunny or the gmsh command is missing.
nlohmann::json againstGmsh(const BenchOptions& o, bool quiet) {
  const fs::path bunny = fs::path(o.dataDir) / "models" / "bunny.off";
  auto skipped = [&](const std::string& why) {
    if (!quiet) std::cout << "meshing against gmsh skipped: " << why << std::endl;
    return nlohmann::json{{"comparison", kGmshComparison}, {"skipped", why}};
  };
  if (const std::optional<std::string> why = missingForComparison(
          bunny, "gmsh", "Debian's gmsh package has it (apt-get install gmsh)"))
    return skipped(*why);
  const fs::path self = *polydgExecutable();
  TriangleSurface surface;
  try {
    surface = readSurface(bunny.string());
  } catch (const InputError& e) {
    return skipped(e.what());
  }
  const int rounds = o.quick ? 1 : 3;
  const std::vector<int> resolutions =
      o.quick ? std::vector<int>{64} : std::vector<int>{64, 128, 200};
  std::string version = commandOutput("gmsh --version 2>&1").value_or("");
  version.erase(version.find_last_not_of(" \t\r\n") + 1);
  const fs::path dir = fs::temp_directory_path() / ("polydg-gmsh-" + std::to_string(::getpid()));
  nlohmann::json rows = nlohmann::json::array();
  try {
    fs::remove_all(dir);
    fs::create_directories(dir);
    writeAsciiStl(dir / "bunny.stl", surface, "bunny");
    writeFileAtomically(dir / "bunny.geo", [](std::ostream& os) { os << gmshGeo("bunny.stl"); });
    // The last run: Gmsh with its own sizes, the configuration issue 35 quotes, beside the
    // finest grid.
    for (std::size_t run = 0; run <= resolutions.size(); ++run) {
      const bool own = run == resolutions.size();
      if (own && o.quick) break;
      const int cells = own ? resolutions.back() : resolutions[run];
      auto [ours, theirs] = compareWithGmsh(self, bunny, surface, cells, rounds, dir, own);
      if (!quiet)
        std::cout << "bunny (" << surface.triangles.size() << " triangles), N = " << cells
                  << " (h = " << shortNumber(ours["cell_size"].get<double>())
                  << "): " << summary(ours) << "; " << summary(theirs) << " (medians of " << rounds
                  << ", run alternately)" << std::endl;
      rows.push_back(std::move(ours));
      rows.push_back(std::move(theirs));
    }
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  return {{"comparison", kGmshComparison},
          {"model", "bunny.off"},
          {"triangles", surface.triangles.size()},
          {"rounds", rounds},
          {"gmsh_version", version},
          {"commands",
           {{"polydg", "polydg mesh bunny.off --cells N -o bunny.vtu --no-dg --quiet"},
            {"gmsh", "gmsh bunny.geo -3 -nt " + std::to_string(kGmshThreads) +
                         " -clmax H -format msh41 -o bunny.msh"},
            {"H", "the longest side of the bunny's bounding box / N (polydg's cell edge)"},
            {"gmsh_own_sizes", "the same without -clmax, beside polydg at the finest N"},
            {"bunny.stl", "bunny.off as ASCII STL, 17 significant digits"}}},
          {"geo", gmshGeo("bunny.stl")},
          {"rows", rows}};
}

/// The Gmsh comparison's plots: wall time and peak memory against the cells of the mesh.
std::vector<NamedPlot> gmshPlots(const nlohmann::json& rows) {
  SeriesSet time, memory;
  for (const nlohmann::json& r : rows) {
    if (r.contains("error")) continue;
    const std::string key = r["mesher"] == "polydg"
                                ? std::string("polydg mesh --no-dg")
                                : "Gmsh HXT (gmsh -3 -nt " + std::to_string(kGmshThreads) + ")";
    const double elements = r["elements"].get<double>();
    time.add(key, elements, r["wall_seconds"].get<double>());
    memory.add(key, elements, r["peak_rss_bytes"].get<double>() / 1e6);
  }
  const PlotAxis elements{"cells of the mesh (polydg: elements; Gmsh: tetrahedra)", AxisScale::Log};
  return {{"meshing_gmsh_time.svg",
           {"The bunny: wall time of the whole commands",
            elements,
            {"wall time [s] (median)", AxisScale::Log},
            time.series()}},
          {"meshing_gmsh_memory.svg",
           {"The bunny: peak memory of the whole commands",
            elements,
            {"peak resident memory [MB] (median)", AxisScale::Log},
            memory.series()}}};
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
  const nlohmann::json gmsh = againstGmsh(o, quiet);
  s.json.push_back(gmsh);
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
  if (gmsh.contains("rows")) {
    for (const nlohmann::json& row : gmsh["rows"]) s.rows.push_back(row);
    for (NamedPlot& plot : gmshPlots(gmsh["rows"])) s.plots.push_back(std::move(plot));
  }
  return s;
}

}  // namespace polydg::bench
