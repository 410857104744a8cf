#include "cli/bench/suites.h"

#include <algorithm>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cut/mesh_editor.h"
#include "mesh/primitives.h"
#include "polydg/cut/cut.h"
#include "util/stopwatch.h"

namespace polydg::bench {

namespace {

/// One cut of the cutting suite.
struct CutRow {
  Vec3 normal;
  double offset;
  std::string name;
};

/// Corner cuts of growing depth on a unit box (normal (+-1, +-1, +-1), each corner once, so the
/// cuts never overlap and the mesh keeps its size), then one through the middle.
std::vector<CutRow> cuttingRows(bool quick) {
  const std::vector<double> depths =
      quick ? std::vector<double>{0.05, 0.3}
            : std::vector<double>{0.01, 0.04, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9};
  std::vector<CutRow> rows;
  for (std::size_t k = 0; k < depths.size(); ++k) {
    const Vec3 s(k & 1 ? -1 : 1, k & 2 ? -1 : 1, k & 4 ? -1 : 1);
    const Vec3 corner(k & 1 ? 1 : 0, k & 2 ? 1 : 0, k & 4 ? 1 : 0);
    rows.push_back({s, s.dot(corner) + depths[k], "corner " + shortNumber(depths[k])});
  }
  const Vec3 n(1, 0.3, 0.1);
  rows.push_back({n, n.dot(Vec3(0.5, 0.5, 0.5)), "middle"});
  return rows;
}

}  // namespace

/// Time per cut against the elements it splits on a ~100k-element grid, with validation
/// `none` (the cut alone) and `local` (plus the checks of the touched region, element by element
/// and face by face), beside a full rebuild of the moment cache (what a non-incremental tool
/// would redo after every cut).
SuiteOutput cuttingSuite(const BenchOptions& o, bool quiet) {
  const int n = o.quick ? 15 : 47;
  SuiteOutput s{"cutting", nlohmann::json::object(), nlohmann::json::array(), {}};
  SeriesSet time;
  nlohmann::json runs = nlohmann::json::array();
  for (CheckLevel level : {CheckLevel::None, CheckLevel::Local}) {
    const std::string levelName = level == CheckLevel::None ? "none" : "local";
    MeshEditor editor(hexGridMesh(n, n, n, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))));
    const std::size_t elements0 = editor.mesh().numElements();
    CutOptions options;
    options.checks = level;
    for (const CutRow& row : cuttingRows(o.quick)) {
      const OperationReport r = editor.cut(Blade::plane(row.normal, row.offset), options);
      if (!r.check.passed)
        throw std::runtime_error("cutting suite: " + row.name + ": " + r.check.failure);
      const Stopwatch rebuildTime;
      MomentCache fresh(editor.mesh(), editor.moments().degree());
      fresh.update();
      const double rebuild = rebuildTime.seconds();
      nlohmann::json j{{"grid", n},
                       {"elements_before", elements0},
                       {"cut", row.name},
                       {"validation", levelName},
                       {"elements_split", r.elementsSplit},
                       {"pieces_created", r.piecesCreated},
                       {"elements", editor.mesh().numElements()},
                       {"faces_reintegrated", r.facesReintegrated},
                       {"faces_total", r.facesTotal},
                       {"t_cut", r.seconds},
                       {"t_full_rebuild", rebuild},
                       {"validation_passed", r.check.passed}};
      runs.push_back(j);
      s.rows.push_back(j);
      const double split = static_cast<double>(std::max<std::size_t>(r.elementsSplit, 1));
      time.add("cut, validation " + levelName, split, r.seconds);
      if (level == CheckLevel::None) time.add("full moment rebuild (2 cores)", split, rebuild);
      if (!quiet)
        std::cout << "cut " << row.name << " (validation " << levelName << "): " << r.elementsSplit
                  << " split, " << r.facesReintegrated << " of " << r.facesTotal
                  << " faces integrated, " << r.seconds << " s; full rebuild " << rebuild << " s"
                  << std::endl;
    }
  }
  s.json = {{"mesh", std::to_string(n) + "^3 hexahedra in the unit box"},
            {"note",
             "each row cuts a corner off the same mesh; t_cut includes sliver merging "
             "and the validation named; t_full_rebuild integrates every face"},
            {"runs", runs}};
  s.plots.push_back(
      {"cutting.svg",
       {"Plane cuts on " + std::to_string(n * n * n) + " hexahedra: time against elements split",
        {"elements split by the cut", AxisScale::Log},
        {"wall time [s]", AxisScale::Log},
        time.series()}});
  return s;
}

}  // namespace polydg::bench
