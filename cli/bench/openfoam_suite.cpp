#include "cli/bench/suites.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/bench/check_mesh_output.h"
#include "cli/bench/external_commands.h"
#include "cli/bench/foam_boundary.h"
#include "cli/bench/snappy_case.h"
#include "cli/bench/surface_distance.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/util/error.h"

namespace polydg::bench {

namespace {

namespace fs = std::filesystem;

/// OpenFOAM's tools need WM_PROJECT_DIR (Debian's installs its etc/ under /usr/share/openfoam);
/// one set by the user (a sourced OpenFOAM installation) is kept.
constexpr const char* kFoamEnvironment =
    "WM_PROJECT_DIR=\"${WM_PROJECT_DIR:-/usr/share/openfoam}\" ";

constexpr const char* kFoamTools[] = {"blockMesh", "surfaceFeatureExtract", "snappyHexMesh",
                                      "checkMesh"};

/// A model of the suite: its name (a word, the STL's and patch's name), file and resolutions.
struct SuiteModel {
  std::string name;
  fs::path file;
  std::vector<int> cells;
};

/// One mesher's case of one model at one resolution, as measured.
struct MesherRun {
  MesherRun(std::string mesher_, fs::path caseDir_)
      : mesher(std::move(mesher_)), caseDir(std::move(caseDir_)) {}
  std::string mesher;
  fs::path caseDir;
  std::string command;          ///< the whole timed command line
  std::vector<double> seconds;  ///< per round
  std::string error;            ///< why it has no figures, if it has none
};

/// An OpenFOAM tool run on `caseDir`, its output in CASE/log.TOOL.
std::string foamTool(const std::string& tool, const fs::path& caseDir,
                     const std::string& options = "") {
  return std::string(kFoamEnvironment) + tool + " -case " + shellQuoted(caseDir.string()) +
         options + " > " + shellQuoted((caseDir / ("log." + tool)).string()) + " 2>&1";
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs `run.command` once, timed; after a failure (the error set) it is not run again.
void runRound(MesherRun& run, const std::function<void()>& clean,
              const std::vector<fs::path>& logs) {
  if (!run.error.empty()) return;
  clean();
  const double seconds = commandSeconds(run.command);
  if (seconds >= 0) {
    run.seconds.push_back(seconds);
    return;
  }
  run.error = run.mesher + " failed";
  for (const fs::path& log : logs)
    if (fs::exists(log)) run.error += "; " + log.filename().string() + ": " + lastLine(log);
}

nlohmann::json optionalJson(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

/// The row of one mesher's case: the medians, checkMesh's figures, and the case's boundary
/// measured against the input surface.
nlohmann::json measure(const MesherRun& run, const SuiteModel& model, int n,
                       const TriangleSurface& surface, const SurfaceDistance& distance) {
  nlohmann::json row{{"model", model.name}, {"n", n}, {"mesher", run.mesher}};
  if (!run.error.empty()) {
    row["error"] = run.error;
    return row;
  }
  // checkMesh's exit status says no more than its output, which says what failed.
  commandSeconds(foamTool("checkMesh", run.caseDir));
  const CheckMeshSummary check = parseCheckMesh(readText(run.caseDir / "log.checkMesh"));
  const Box3 box = bounds(surface);
  const double exact = polydg::enclosedVolume(surface);
  FoamBoundary boundary;
  try {
    boundary = readFoamBoundary(run.caseDir);
  } catch (const InputError& e) {
    row["error"] = e.what();
    return row;
  }
  const double volume = enclosedVolume(boundary, box.center());
  const double largest = distance.largestDistance(boundarySamples(boundary));
  row["wall_seconds"] = median(run.seconds);
  row["round_seconds"] = run.seconds;
  row["cells"] = check.cells ? nlohmann::json(*check.cells) : nlohmann::json(nullptr);
  row["boundary_faces"] = boundary.faces.size();
  row["volume"] = volume;
  row["volume_rel_error"] = std::abs(volume - exact) / std::abs(exact);
  row["max_boundary_distance"] = largest;
  row["max_boundary_distance_rel"] = largest / box.diagonal().norm();
  row["checkmesh_verdict"] = check.verdict;
  row["checkmesh_failed_checks"] = check.failedChecks;
  row["max_non_orthogonality"] = optionalJson(check.maxNonOrthogonality);
  row["max_skewness"] = optionalJson(check.maxSkewness);
  row["max_aspect_ratio"] = optionalJson(check.maxAspectRatio);
  row["checkmesh_total_volume"] = optionalJson(check.totalVolume);
  row["checkmesh_failures"] = check.failures;
  return row;
}

nlohmann::json point(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

nlohmann::json setupJson(const SnappySetup& s, int n) {
  return {{"model", s.surface},
          {"n", n},
          {"block_cells", s.blockCells},
          {"block_min", point(s.blockMin)},
          {"block_max", point(s.blockMax)},
          {"cell_size", s.cellSize},
          {"surface_level", s.surfaceLevel},
          {"included_angle", s.includedAngle},
          {"location_in_mesh", point(s.locationInMesh)},
          {"location_depth", s.depth}};
}

/// Both meshers on `model` at `n` cells, alternately for `rounds` rounds in `work`: polydg mesh
/// and export, then blockMesh, surfaceFeatureExtract and snappyHexMesh; the two rows.
std::vector<nlohmann::json> compareAt(const SuiteModel& model, int n, int rounds,
                                      const TriangleSurface& surface,
                                      const SurfaceDistance& distance, const fs::path& self,
                                      const fs::path& work, nlohmann::json& setups) {
  const fs::path dir = work / (model.name + "_" + std::to_string(n));
  const fs::path vtu = dir / "polydg.vtu";
  fs::create_directories(dir);
  MesherRun polydg{"polydg", dir / "polydg_case"};
  polydg.command = shellQuoted(self.string()) + " mesh " + shellQuoted(model.file.string()) +
                   " --cells " + std::to_string(n) + " --no-dg -o " + shellQuoted(vtu.string()) +
                   " --quiet > " + shellQuoted((dir / "log.polydg").string()) + " 2>&1 && " +
                   shellQuoted(self.string()) + " export " + shellQuoted(vtu.string()) +
                   " --format openfoam -o " + shellQuoted(polydg.caseDir.string()) +
                   " --quiet >> " + shellQuoted((dir / "log.polydg").string()) + " 2>&1";
  MesherRun snappy{"snappyHexMesh", dir / "snappy_case"};
  snappy.command = foamTool("blockMesh", snappy.caseDir) + " && " +
                   foamTool("surfaceFeatureExtract", snappy.caseDir) + " && " +
                   foamTool("snappyHexMesh", snappy.caseDir, " -overwrite");
  try {
    const SnappySetup setup = snappySetup(surface, distance, n, model.name);
    writeSnappyCase(snappy.caseDir, surface, setup);
    setups.push_back(setupJson(setup, n));
  } catch (const InputError& e) {
    snappy.error = e.what();
  }
  const fs::path polyMesh = snappy.caseDir / "constant" / "polyMesh";
  for (int r = 0; r < rounds; ++r) {
    runRound(polydg, [&] { fs::remove(vtu); }, {dir / "log.polydg"});
    runRound(snappy,
             [&] {
               fs::remove_all(polyMesh);
               fs::remove_all(snappy.caseDir / "constant" / "extendedFeatureEdgeMesh");
             },
             {snappy.caseDir / "log.blockMesh", snappy.caseDir / "log.surfaceFeatureExtract",
              snappy.caseDir / "log.snappyHexMesh"});
  }
  return {measure(polydg, model, n, surface, distance),
          measure(snappy, model, n, surface, distance)};
}

std::string figure(const nlohmann::json& v, const char* format) {
  if (!v.is_number()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, v.get<double>());
  return text;
}

/// One line per mesher as the suite goes (the table comes at the end).
void printProgress(const nlohmann::json& r, int rounds) {
  std::cout << r["model"].get<std::string>() << ", " << r["n"]
            << " cells: " << r["mesher"].get<std::string>();
  if (r.contains("error"))
    std::cout << ": " << r["error"].get<std::string>();
  else
    std::cout << " " << shortNumber(r["wall_seconds"].get<double>()) << " s (median of " << rounds
              << "), " << r["cells"]
              << " cells, checkMesh: " << r["checkmesh_verdict"].get<std::string>();
  std::cout << std::endl;
}

void printTable(const nlohmann::json& rows) {
  std::printf("%-6s %4s %-13s %8s %8s %9s %9s %9s %-22s %7s %7s %7s\n", "model", "N", "mesher",
              "wall s", "cells", "vol err", "max dist", "/ diag", "checkMesh", "nonorth", "skew",
              "aspect");
  for (const nlohmann::json& r : rows) {
    if (r.contains("error")) {
      std::printf("%-6s %4d %-13s %s\n", r["model"].get<std::string>().c_str(), r["n"].get<int>(),
                  r["mesher"].get<std::string>().c_str(), r["error"].get<std::string>().c_str());
      continue;
    }
    std::printf("%-6s %4d %-13s %8s %8s %9s %9s %9s %-22s %7s %7s %7s\n",
                r["model"].get<std::string>().c_str(), r["n"].get<int>(),
                r["mesher"].get<std::string>().c_str(), figure(r["wall_seconds"], "%.3f").c_str(),
                figure(r["cells"], "%.0f").c_str(), figure(r["volume_rel_error"], "%.2e").c_str(),
                figure(r["max_boundary_distance"], "%.2e").c_str(),
                figure(r["max_boundary_distance_rel"], "%.2e").c_str(),
                r["checkmesh_verdict"].get<std::string>().c_str(),
                figure(r["max_non_orthogonality"], "%.1f").c_str(),
                figure(r["max_skewness"], "%.2f").c_str(),
                figure(r["max_aspect_ratio"], "%.2f").c_str());
  }
  std::fflush(stdout);
}

/// The plots: wall time, volume error and boundary distance against the mesh's cells, a series
/// per model and mesher (zero errors drawn at machine epsilon, as the meshing suite does).
std::vector<NamedPlot> plots(const nlohmann::json& rows) {
  SeriesSet time, volume, distance;
  constexpr double eps = std::numeric_limits<double>::epsilon();
  for (const nlohmann::json& r : rows) {
    if (r.contains("error") || !r["cells"].is_number()) continue;
    const std::string key = r["model"].get<std::string>() + ": " + r["mesher"].get<std::string>();
    const double cells = r["cells"].get<double>();
    time.add(key, cells, r["wall_seconds"].get<double>());
    volume.add(key, cells, std::max(r["volume_rel_error"].get<double>(), eps));
    distance.add(key, cells, std::max(r["max_boundary_distance_rel"].get<double>(), eps));
  }
  const PlotAxis cells{"cells of the mesh", AxisScale::Log};
  return {{"openfoam_time.svg",
           {"Wall time of the whole commands: polydg against snappyHexMesh",
            cells,
            {"wall time [s] (median)", AxisScale::Log},
            time.series()}},
          {"openfoam_volume_error.svg",
           {"Volume of the mesh against the surface's",
            cells,
            {"|volume - surface volume| / surface volume (0 drawn at 2.2e-16)", AxisScale::Log},
            volume.series()}},
          {"openfoam_distance.svg",
           {"Largest distance of the mesh's boundary from the surface",
            cells,
            {"distance / bounding box diagonal (0 drawn at 2.2e-16)", AxisScale::Log},
            distance.series()}}};
}

}  // namespace

SuiteOutput openfoamSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"openfoam", nlohmann::json::object(), nlohmann::json::array(), {}};
  auto skipped = [&](const std::string& why) {
    if (!quiet) std::cout << "openfoam suite skipped: " << why << std::endl;
    s.json["skipped"] = why;
    return s;
  };
  for (const char* tool : kFoamTools)
    if (!commandExists(tool))
      return skipped(std::string(tool) +
                     " not installed; scripts/setup.sh installs OpenFOAM (Debian's openfoam)");
  const std::optional<fs::path> self = polydgExecutable();
  if (!self) return skipped("cannot find the polydg executable through /proc/self/exe");
  const fs::path torus = fs::path(o.dataDir) / "torus.obj";
  if (!fs::exists(torus))
    throw InputError(torus.string() +
                     " not found; pass the folder that holds polydg's bundled models "
                     "(share/polydg of the build or installation) with --data");
  std::vector<SuiteModel> models{
      {"torus", torus, o.quick ? std::vector<int>{12} : std::vector<int>{12, 24}}};
  const fs::path bunny = fs::path(o.dataDir) / "models" / "bunny.off";
  s.json["skipped_models"] = nlohmann::json::array();
  if (!o.quick) {
    if (fs::exists(bunny)) {
      models.push_back({"bunny", bunny, {32, 64}});
    } else {
      const std::string why = bunny.string() + " not found; scripts/get-models.sh fetches it";
      if (!quiet) std::cout << "openfoam suite: bunny skipped: " << why << std::endl;
      s.json["skipped_models"].push_back({{"model", "bunny"}, {"why", why}});
    }
  }
  const int rounds = o.quick ? 1 : 3;
  const fs::path work =
      fs::temp_directory_path() / ("polydg-openfoam-" + std::to_string(::getpid()));
  fs::remove_all(work);
  nlohmann::json setups = nlohmann::json::array();
  try {
    for (const SuiteModel& model : models) {
      const TriangleSurface surface = readSurface(model.file.string());
      const SurfaceDistance distance(surface);
      for (int n : model.cells) {
        for (nlohmann::json& row :
             compareAt(model, n, rounds, surface, distance, *self, work, setups)) {
          if (!quiet) printProgress(row, rounds);
          s.rows.push_back(std::move(row));
        }
      }
    }
  } catch (...) {
    fs::remove_all(work);
    throw;
  }
  fs::remove_all(work);
  s.json["rounds"] = rounds;
  s.json["commands"] = {
      {"polydg",
       "polydg mesh MODEL --cells N --no-dg -o x.vtu --quiet && polydg export x.vtu --format "
       "openfoam -o polydg_case --quiet"},
      {"snappyHexMesh",
       "blockMesh -case CASE && surfaceFeatureExtract -case CASE && snappyHexMesh -case CASE "
       "-overwrite"},
      {"environment", "WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam}"},
      {"checked_by", "checkMesh -case CASE"}};
  s.json["snappy_setup"] = setups;
  s.json["rows"] = s.rows;
  if (!quiet) printTable(s.rows);
  s.plots = plots(s.rows);
  return s;
}

}  // namespace polydg::bench
