#include "cli/bench/suites.h"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/bench/problems.h"
#include "physics/solvers/condition_estimate.h"
#include "polydg/model/names.h"

namespace polydg::bench {

namespace {

/// Grid sizes of the accuracy suite per degree (at least three each; two with --quick).
std::vector<int> accuracySizes(int degree, BenchmarkMesh mesh, bool quick) {
  if (quick) return degree == 1 ? std::vector<int>{2, 4} : std::vector<int>{1, 2};
  if (mesh == BenchmarkMesh::Sliced) {
    switch (degree) {
      case 1: return {4, 8, 12};
      case 2: return {2, 4, 8};
      default: return {2, 4, 6};
    }
  }
  switch (degree) {
    case 1: return {4, 8, 16, 24};
    case 2: return {2, 4, 8, 12};
    default: return {2, 3, 4, 6, 8};
  }
}

/// The discretizations the suite compares: IP, BZ with its fixed penalty (~1/h, which stops
/// converging) and BZ with the superpenalty (~h^-(2p+1), BzPenalty::Super).
struct Variant {
  Method method;
  BzPenalty bzPenalty;
  std::string label;
};
const std::vector<Variant>& variants() {
  static const std::vector<Variant> v{{Method::IP, BzPenalty::Fixed, "IP"},
                                      {Method::BZ, BzPenalty::Fixed, "BZ fixed"},
                                      {Method::BZ, BzPenalty::Super, "BZ super"}};
  return v;
}

/// Runs up to this many DOFs also get the cost columns: a condition estimate of K (Lanczos with
/// a CHOLMOD factorization) and the iterations of CG with the p-multigrid preconditioner.
constexpr std::size_t kCostMaxDofs = 25000;

/// The cost columns of B1 on the hex grid or sliced cube of size n under `options`:
/// cond (conditionEstimate()), cg_iterations and cg_converged (CG, p-multigrid, relative
/// residual 1e-10, at most the solver's default iterations).
nlohmann::json costColumns(int n, StaticOptions options, BenchmarkMesh kind) {
  const ManufacturedProblem problem = benchmarkB1Problem();
  const PolyMesh mesh = benchmarkB1Mesh(kind, n);
  options.solver.kind = SolverKind::ConjugateGradient;
  StaticSolver solver(mesh, problem.material, options);
  solver.assemble(benchmarkB1Loads(problem));
  const ConditionEstimate c = conditionEstimate(solver.system().matrix, solver.system().blockSize);
  bool converged = true;
  try {
    solver.solve();
  } catch (const std::runtime_error&) {
    converged = false;  // reported, not fatal: the row says so
  }
  const LinearSolveReport& r = solver.report().solver;
  return {{"cond", c.cond},
          {"cg_iterations", r.iterations},
          {"cg_converged", converged && r.success},
          {"cg_residual", r.residual}};
}

/// B1's reference point (BENCHMARKS.md): continuous P2 tetrahedra with algebraic multigrid.
PlotSeries referenceLibrarySeries() {
  return {"reference: FEM P2 tets + AMG", {0.5, 8.0}, {9.4e-6, 1.2e-6}};
}

}  // namespace

SuiteOutput accuracySuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"accuracy", nlohmann::json::array(), nlohmann::json::array(), {}};
  std::vector<BenchmarkMesh> meshes{BenchmarkMesh::Hex};
  if (!o.skipSliced) meshes.push_back(BenchmarkMesh::Sliced);
  const int maxDegree = o.quick ? 2 : 3;
  SeriesSet l2;
  std::vector<std::string> labels;  // series labels with their last rates, in series order
  for (BenchmarkMesh mesh : meshes)
    for (const Variant& variant : variants())
      for (int p = 1; p <= maxDegree; ++p) {
        const std::string key = variant.label + " p=" + std::to_string(p) + " " +
                                (mesh == BenchmarkMesh::Hex ? "hex" : "sliced");
        std::optional<BenchmarkRun> previous;
        double lastRate = std::numeric_limits<double>::quiet_NaN();
        for (int n : accuracySizes(p, mesh, o.quick)) {
          StaticOptions so;
          so.discretization.method = variant.method;
          if (variant.method == Method::BZ) so.discretization.bzPenalty = variant.bzPenalty;
          so.discretization.basis.degree = p;
          const BenchmarkRun r = runBenchmarkB1(n, so, mesh);
          if (!quiet) printRun(r);
          nlohmann::json j = runJson(r);
          j["bz_penalty"] = variant.method == Method::BZ ? toString(variant.bzPenalty) : "";
          j["bz_factor"] = r.report.bzFactor;
          j["solver_converged"] = r.report.solver.success;
          if (r.report.dofs <= kCostMaxDofs) j.update(costColumns(n, so, mesh));
          if (previous) {
            const double dh = std::log(static_cast<double>(r.n) / previous->n);
            lastRate = std::log(previous->l2Error / r.l2Error) / dh;
            j["l2_rate"] = lastRate;
            j["h1_rate"] = std::log(previous->h1Error / r.h1Error) / dh;
          }
          s.json.push_back(j);
          s.rows.push_back(j);
          l2.add(key, r.report.integrateSeconds + r.report.assembleSeconds + r.report.solveSeconds,
                 r.l2Error);
          previous = r;
        }
        labels.push_back(key + ", L2 rate " + shortNumber(lastRate));
      }
  std::vector<PlotSeries> all = l2.series();
  for (std::size_t i = 0; i < all.size(); ++i) all[i].label = labels[i];
  for (BenchmarkMesh mesh : meshes) {
    const std::string kind = mesh == BenchmarkMesh::Hex ? "hex" : "sliced";
    std::vector<PlotSeries> series;
    for (const PlotSeries& p : all)
      if (p.label.find(" " + kind + ",") != std::string::npos) series.push_back(p);
    series.push_back(referenceLibrarySeries());
    s.plots.push_back({"accuracy_" + kind + ".svg",
                       {"B1 accuracy on " + kind + " meshes: L2 error against time",
                        {"wall time, integration + assembly + solve [s]", AxisScale::Log},
                        {"L2 error of u (legend: rate over the last halving of h)", AxisScale::Log},
                        series}});
  }
  return s;
}

}  // namespace polydg::bench
