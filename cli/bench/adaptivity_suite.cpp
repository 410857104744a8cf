// The adaptivity suite: B11 (thesis Fig. 4.9's bent bar refined by principal stress, 1-to-8 and
// 1-to-2, beside the thesis's counts), B12 (a steep Gaussian bump, p = 1-3: uniform grids
// against `solve --adapt` by the error estimate, DOFs to reach each uniform grid's L2 error, and
// the estimator's effectivity on every mesh), B13 (octree slicing against the uniform grid) and
// the estimator against reference solves on an L-prism and the torus. All run through Model,
// as `polydg solve --adapt` and `polydg mesh --adaptive` do.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli/bench/reference_error.h"
#include "cli/bench/suites.h"
#include "mesh/primitives.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg::bench {

namespace {

/// Thesis Fig. 4.9: the bar's element counts after refinement.
constexpr std::size_t kThesisOctants = 274, kThesisHalves = 77;

nlohmann::json roundJson(const AdaptRound& r) {
  return {{"elements", r.elements},
          {"dofs", r.dofs},
          {"estimate", r.estimate},
          {"energy_norm", r.energyNorm},
          {"l2_error", r.l2Error},
          {"energy_error", r.energyError},
          {"effectivity", r.energyError > 0.0 ? r.estimate / r.energyError : 0.0},
          {"largest_stress", r.largestStress},
          {"marked", r.marked},
          {"elements_after", r.elementsAfter},
          {"stop", r.stop},
          {"solve_seconds", r.solveSeconds},
          {"estimate_seconds", r.estimateSeconds},
          {"refine_seconds", r.refineSeconds}};
}

Model unitCube(int n) { return Model(hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones()))); }

/// B11: the bent bar of thesis Fig. 4.9 refined by principal stress, 1-to-8 and 1-to-2, beside
/// the thesis's element counts.
void runB11(const BenchOptions& o, SuiteOutput& s, const Log& log) {
  nlohmann::json b11 = nlohmann::json::array();
  const std::vector<double> taus =
      o.quick ? std::vector<double>{0.5} : std::vector<double>{0.25, 0.5, 0.75};
  for (RefineSplit split : {RefineSplit::Octants, RefineSplit::Halves})
    for (double tau : taus) {
      Model model(hexGridMesh(9, 2, 2, Box3(Vec3::Zero(), Vec3(9, 2, 2))));
      SolveOptions so;
      so.discretization.basis.degree = 1;
      so.material.youngsModulus = 1000.0;
      so.material.poissonRatio = 0.3;
      so.clamps = {FaceSelector::inPlane(0, 0.0)};
      so.tractions = {{FaceSelector::inPlane(0, 9.0), Vec3(0, 0, -1)}};
      AdaptOptions a;
      a.criterion = AdaptCriterion::Stress;
      a.split = split;
      a.stressFraction = tau;
      a.maxRounds = o.quick ? 2 : 3;
      so.adapt = a;
      const Stopwatch watch;
      const SolveReport r = model.solve(so);
      nlohmann::json rounds = nlohmann::json::array();
      for (const AdaptRound& round : r.rounds) rounds.push_back(roundJson(round));
      const std::size_t elements = model.mesh().numElements();
      const std::size_t thesis = split == RefineSplit::Octants ? kThesisOctants : kThesisHalves;
      const std::string name = nameOf(refineSplitNames(), split);
      b11.push_back({{"split", name},
                     {"tau", tau},
                     {"elements", elements},
                     {"thesis_elements", thesis},
                     {"rounds", rounds},
                     {"seconds", watch.seconds()}});
      s.rows.push_back({{"benchmark", "B11"},
                        {"case", name + " tau " + shortNumber(tau)},
                        {"elements", elements},
                        {"dofs", r.solve.dofs},
                        {"reference", thesis},
                        {"l2_error", nullptr},
                        {"effectivity", nullptr}});
      log("B11 " + name + " tau " + shortNumber(tau) + ": " + std::to_string(elements) +
          " elements after " + std::to_string(r.rounds.size() - 1) + " rounds (thesis " +
          std::to_string(thesis) + ")");
    }
  s.json["B11"] = b11;
}

/// B13: octree slicing of a sphere against the uniform grid, one after the other.
void runB13(const BenchOptions& o, SuiteOutput& s, const Log& log) {
  const TriangleSurface sphere = icosphere(Vec3::Zero(), 1.0, o.quick ? 4 : 6);
  nlohmann::json b13 = nlohmann::json::array();
  for (bool adaptive : {false, true}) {
    MeshOptions options;
    options.cells = o.quick ? 32 : 128;
    options.adaptive = adaptive;
    MeshReport report;
    const Stopwatch watch;
    const Model model = Model::fromSurface(sphere, options, report);
    const double seconds = watch.seconds();
    const MeshingReport& m = report.meshing;
    b13.push_back({{"mesh", adaptive ? "octree" : "uniform"},
                   {"triangles", sphere.triangles.size()},
                   {"cells", options.cells},
                   {"elements", model.mesh().numElements()},
                   {"faces", m.faces},
                   {"volume", m.outputVolume},
                   {"volume_relative_error", m.volumeRelError},
                   {"passed", report.passed()},
                   {"levels", report.levels},
                   {"elements_per_level", report.elementsPerLevel},
                   {"refine_seconds", report.refineSeconds},
                   {"seconds", seconds}});
    s.rows.push_back({{"benchmark", "B13"},
                      {"case", adaptive ? "octree" : "uniform"},
                      {"elements", model.mesh().numElements()},
                      {"dofs", nullptr},
                      {"reference", nullptr},
                      {"l2_error", nullptr},
                      {"effectivity", nullptr}});
    log(std::string("B13 ") + (adaptive ? "octree" : "uniform") + ": " +
        std::to_string(model.mesh().numElements()) + " elements, " + std::to_string(m.faces) +
        " faces, volume error " + shortNumber(m.volumeRelError) + ", " + shortNumber(seconds) +
        " s");
  }
  s.json["B13"] = b13;
}

/// A B12 run on a uniform grid: its DOFs and L2 error.
struct UniformPoint {
  std::size_t dofs;
  double l2;
};

/// The effectivities of a suite's meshes, lowest and highest.
struct EffectivityRange {
  double lowest = 1e300, highest = 0.0;
  void add(double e) {
    lowest = std::min(lowest, e);
    highest = std::max(highest, e);
  }
};

/// B12's uniform grids for degree p (quick: 4, 8; else 8, 16 and, below p = 3, 32).
std::vector<int> b12Grids(const BenchOptions& o, int p) {
  if (o.quick) return {4, 8};
  return p < 3 ? std::vector<int>{8, 16, 32} : std::vector<int>{8, 16};
}

/// B12 on uniform grids of degree base's p: each run's figures (returned), rows, log line and
/// point of `plot`; `points` receives the DOFs and L2 error of each run.
nlohmann::json runB12Uniform(const BenchOptions& o, const SolveOptions& base, SuiteOutput& s,
                             SeriesSet& plot, std::vector<UniformPoint>& points,
                             EffectivityRange& range, const Log& log) {
  const int p = base.discretization.basis.degree;
  const std::string degree = "p = " + std::to_string(p);
  nlohmann::json uniform = nlohmann::json::array();
  for (int n : b12Grids(o, p)) {
    Model model = unitCube(n);
    const Stopwatch watch;
    const SolveReport r = model.solve(base);
    const double seconds = watch.seconds();
    const double effectivity = r.estimate->total / r.energyError->total();
    range.add(effectivity);
    uniform.push_back({{"n", n},
                       {"dofs", r.solve.dofs},
                       {"l2_error", r.error->l2},
                       {"energy_error", r.energyError->total()},
                       {"estimate", r.estimate->total},
                       {"effectivity", effectivity},
                       {"seconds", seconds}});
    s.rows.push_back({{"benchmark", "B12"},
                      {"case", degree + " uniform n " + std::to_string(n)},
                      {"elements", model.mesh().numElements()},
                      {"dofs", r.solve.dofs},
                      {"reference", nullptr},
                      {"l2_error", r.error->l2},
                      {"effectivity", effectivity}});
    points.push_back({r.solve.dofs, r.error->l2});
    plot.add("uniform " + degree, static_cast<double>(r.solve.dofs), r.error->l2);
    log("B12 " + degree + " uniform n " + std::to_string(n) + ": " + std::to_string(r.solve.dofs) +
        " DOFs, L2 error " + shortNumber(r.error->l2) + ", effectivity " +
        shortNumber(effectivity) + ", " + shortNumber(seconds) + " s");
  }
  return uniform;
}

/// B12 adaptive from n = 4 with degree base's p, up to a fifth of the finest uniform grid's
/// DOFs, against the uniform runs (`uniform`, `uniformPoints`): B12's report for that degree.
nlohmann::json runB12Adaptive(const BenchOptions& o, const SolveOptions& base,
                              nlohmann::json uniform,
                              const std::vector<UniformPoint>& uniformPoints, SuiteOutput& s,
                              SeriesSet& plot, EffectivityRange& all, const Log& log) {
  const int p = base.discretization.basis.degree;
  const std::string degree = "p = " + std::to_string(p);
  Model model = unitCube(4);
  SolveOptions so = base;
  AdaptOptions a;
  a.criterion = AdaptCriterion::Error;
  a.bulk = 0.5;
  a.maxRounds = o.quick ? 2 : 12;
  a.maxDofs = uniformPoints.back().dofs / 5;
  so.adapt = a;
  const Stopwatch watch;
  const SolveReport r = model.solve(so);
  nlohmann::json rounds = nlohmann::json::array();
  EffectivityRange range;
  for (const AdaptRound& round : r.rounds) {
    rounds.push_back(roundJson(round));
    const double effectivity = round.estimate / round.energyError;
    range.add(effectivity);
    all.add(effectivity);
    plot.add("adaptive " + degree, static_cast<double>(round.dofs), round.l2Error);
    s.rows.push_back({{"benchmark", "B12"},
                      {"case", degree + " adaptive"},
                      {"elements", round.elements},
                      {"dofs", round.dofs},
                      {"reference", nullptr},
                      {"l2_error", round.l2Error},
                      {"effectivity", effectivity}});
    log("B12 " + degree + " adaptive: " + std::to_string(round.elements) + " elements, " +
        std::to_string(round.dofs) + " DOFs, L2 error " + shortNumber(round.l2Error) +
        ", effectivity " + shortNumber(effectivity));
  }
  // DOFs the adaptive run needed to reach each uniform grid's L2 error.
  nlohmann::json reach = nlohmann::json::array();
  for (const UniformPoint& u : uniformPoints) {
    nlohmann::json j{{"uniform_dofs", u.dofs}, {"uniform_l2_error", u.l2}};
    j["adaptive_dofs"] = nullptr;
    for (const AdaptRound& round : r.rounds)
      if (round.l2Error <= u.l2) {
        j["adaptive_dofs"] = round.dofs;
        j["dof_ratio"] = static_cast<double>(u.dofs) / static_cast<double>(round.dofs);
        break;
      }
    reach.push_back(j);
  }
  return {{"degree", p},
          {"uniform", std::move(uniform)},
          {"adaptive", rounds},
          {"adaptive_seconds", watch.seconds()},
          {"dofs_to_reach_uniform_error", reach},
          {"effectivity_range", {range.lowest, range.highest}}};
}

/// The estimator on problems without a closed form, against a reference solve of the same
/// degree on the mesh split twice into octants: a sliced L-prism (its re-entrant edge a stress
/// singularity) pulled round its corner, and the sliced torus hanging under gravity.
nlohmann::json runReferenceChecks(const BenchOptions& o, SuiteOutput& s, EffectivityRange& all,
                                  const Log& log) {
  nlohmann::json out = nlohmann::json::array();
  for (const ReferenceProblem& c : referenceProblems()) {
    MeshOptions meshing;
    meshing.cells = c.cells;
    MeshReport meshed;
    const std::filesystem::path path = std::filesystem::path(o.dataDir) / c.file;
    if (!std::filesystem::exists(path))
      throw InputError(path.string() +
                       " not found; pass the folder that holds polydg's bundled models "
                       "(share/polydg of the build or installation) with --data");
    const Model model = Model::fromSurface(readSurface(path.string()), meshing, meshed);
    for (int p = 1; p <= (o.quick ? 1 : 3); ++p) {
      SolveOptions so = c.options;
      so.discretization.basis.degree = p;
      const Stopwatch watch;
      const ReferenceCheck r = checkAgainstReference(model.mesh(), so, 2, p);
      all.add(r.effectivity());
      out.push_back({{"problem", c.name},
                     {"cells", c.cells},
                     {"degree", p},
                     {"elements", r.elements},
                     {"dofs", r.dofs},
                     {"reference_elements", r.referenceElements},
                     {"reference_dofs", r.referenceDofs},
                     {"estimate", r.estimate},
                     {"error", r.error},
                     {"effectivity", r.effectivity()},
                     {"seconds", watch.seconds()}});
      s.rows.push_back({{"benchmark", "estimator"},
                        {"case", c.name + " p = " + std::to_string(p)},
                        {"elements", r.elements},
                        {"dofs", r.dofs},
                        {"reference", r.referenceDofs},
                        {"l2_error", nullptr},
                        {"effectivity", r.effectivity()}});
      log("estimator " + c.name + " p = " + std::to_string(p) + ": " + std::to_string(r.elements) +
          " elements, effectivity " + shortNumber(r.effectivity()) + " against " +
          std::to_string(r.referenceDofs) + " reference DOFs");
    }
  }
  return out;
}

}  // namespace

SuiteOutput adaptivitySuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"adaptivity", nlohmann::json::object(), nlohmann::json::array(), {}};
  const Log log = [&](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };
  s.json["setup"] = {
      {"B11",
       "bar [0,9]x[0,2]x[0,2] of 36 unit hexahedra, E = 1000, nu = 0.3, clamped on x = 0, "
       "traction (0,0,-1) on x = 9, IP p = 1; refine where the element's mean stress has a "
       "principal value above tau * the unrefined mesh's largest, each element split once at "
       "most (max level 1), until none does or 3 rounds"},
      {"B12",
       "unit cube, E = 1, nu = 0.3, u = 0.01 (1,1,1) exp(-|x-c|^2/(2 w^2)), w = 0.05, IP p = "
       "1-3; uniform n^3 hex grids against solve --adapt from n = 4 (Doerfler bulk 0.5, 1-to-8)"},
      {"estimator",
       "L-prism sliced at 5 cells, E = 1000, nu = 0.3, clamped on y = 2, traction (0,10,0) on "
       "x = 2; torus sliced at 6 cells, density 1, gravity (0,0,-10), clamped where x <= -1; "
       "IP p = 1-3, error against the same degree on the mesh split twice into octants"}};
  runB11(o, s, log);
  runB13(o, s, log);
  const ManufacturedProblem problem = benchmarkB12Problem();
  SeriesSet plot;
  EffectivityRange all;
  nlohmann::json b12 = nlohmann::json::array();
  for (int p = 1; p <= 3; ++p) {
    SolveOptions base = manufacturedSolveOptions(problem, p);
    base.estimate = true;
    std::vector<UniformPoint> uniformPoints;
    nlohmann::json uniform = runB12Uniform(o, base, s, plot, uniformPoints, all, log);
    b12.push_back(runB12Adaptive(o, base, std::move(uniform), uniformPoints, s, plot, all, log));
  }
  s.json["B12"] = std::move(b12);
  s.plots.push_back({"adaptivity_b12.svg",
                     {"B12 steep bump: L2 error against DOFs (IP, p = 1-3)",
                      {"DOFs", AxisScale::Log},
                      {"L2 error", AxisScale::Log},
                      plot.series()}});
  s.json["estimator_references"] = runReferenceChecks(o, s, all, log);
  s.json["effectivity_range"] = {all.lowest, all.highest};
  return s;
}

}  // namespace polydg::bench
