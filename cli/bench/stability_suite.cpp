#include "cli/bench/suites.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "cli/bench/stability.h"

namespace polydg::bench {

namespace {

nlohmann::json conditionJson(const StabilityConditionRun& r) {
  const ConditionEstimate& c = r.estimate;
  return {{"degree", r.degree},
          {"elements", r.elements},
          {"dofs", r.dofs},
          {"eta", r.eta},
          {"cond", c.positiveDefinite ? nlohmann::json(c.cond) : nlohmann::json(nullptr)},
          {"lambda_min", c.lambdaMin},
          {"lambda_max", c.lambdaMax},
          {"positive_definite", c.positiveDefinite},
          {"cond_jacobi", r.jacobiEstimate.positiveDefinite ? nlohmann::json(r.jacobiEstimate.cond)
                                                            : nlohmann::json(nullptr)},
          // Beyond 1/eps the smallest eigenvalue is below the round-off of K's entries: the
          // estimate says "singular to double precision", not a precise number.
          {"beyond_double_precision", c.cond * std::numeric_limits<double>::epsilon() > 1.0}};
}

/// B4 sliver: condition estimates with and without the sliver merged, against the regular
/// mesh's, per degree; `summary` receives whether the merged ones stay within 100 times.
void runSliver(const BenchOptions& o, SuiteOutput& s, nlohmann::json& summary, const Log& log) {
  const std::vector<double> ratios =
      o.quick ? std::vector<double>{1, 2e-2, 1e-4, 1e-12}
              : std::vector<double>{1,    1e-1, 5e-2, 2e-2, 1e-2,  1e-3,  1e-4, 1e-5,
                                    1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  nlohmann::json sliver = nlohmann::json::array(), regular = nlohmann::json::object();
  SeriesSet sliverPlot;
  bool mergedWithin100 = true;
  nlohmann::json mergedBeyond100 = nlohmann::json::array();  // {degree, volume_ratio}
  for (int p : {1, 2}) {
    const double regularCond = runSliverCase(1.0, false, p).estimate.cond;
    regular[std::to_string(p)] = regularCond;
    for (bool merged : {false, true})
      for (double r : ratios) {
        const StabilityConditionRun run = runSliverCase(r, merged, p);
        nlohmann::json j = conditionJson(run);
        j["volume_ratio"] = r;
        j["merged"] = merged;
        j["regular_cond"] = regularCond;
        j["cond_over_regular"] = run.estimate.cond / regularCond;
        if (merged && !(run.estimate.cond <= 100 * regularCond)) {
          mergedWithin100 = false;
          mergedBeyond100.push_back({{"degree", p}, {"volume_ratio", r}});
        }
        sliver.push_back(j);
        j["case"] = "sliver";
        s.rows.push_back(j);
        sliverPlot.add("p=" + std::to_string(p) + (merged ? " merged" : " not merged"), r,
                       run.estimate.cond);
        log("sliver p=" + std::to_string(p) + (merged ? " merged" : "") + " ratio " +
            shortNumber(r) + ": cond " + shortNumber(run.estimate.cond));
      }
  }
  s.json["sliver"] = sliver;
  s.json["sliver_regular_cond"] = regular;
  summary["merged_sliver_within_100x_of_regular"] = mergedWithin100;
  summary["merged_sliver_beyond_100x"] = mergedBeyond100;
  s.plots.push_back({"stability_sliver.svg",
                     {"B4 sliver: stiffness condition estimate (IP, clamped)",
                      {"sliver volume / neighbour volume", AxisScale::Log},
                      {"condition estimate (Lanczos)", AxisScale::Log},
                      sliverPlot.series()}});
}

/// B4 thin neck: condition estimates of one non-convex element as its neck thins; `summary`
/// receives their range.
void runThinNeck(const BenchOptions& o, SuiteOutput& s, nlohmann::json& summary, const Log& log) {
  const std::vector<double> necks =
      o.quick ? std::vector<double>{1e-1, 1e-9}
              : std::vector<double>{1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9};
  nlohmann::json neck = nlohmann::json::array();
  SeriesSet neckPlot;
  double neckMin = std::numeric_limits<double>::infinity(), neckMax = 0.0;
  for (int p : {1, 2})
    for (double e : necks) {
      const StabilityConditionRun run = runThinNeckCase(e, p);
      nlohmann::json j = conditionJson(run);
      j["eps"] = e;
      neck.push_back(j);
      j["case"] = "thin_neck";
      s.rows.push_back(j);
      neckPlot.add("p=" + std::to_string(p), e, run.estimate.cond);
      neckMin = std::min(neckMin, run.estimate.cond);
      neckMax = std::max(neckMax, run.estimate.cond);
      log("thin neck p=" + std::to_string(p) + " eps " + shortNumber(e) + ": cond " +
          shortNumber(run.estimate.cond));
    }
  s.json["thin_neck"] = neck;
  summary["thin_neck_cond_min"] = neckMin;
  summary["thin_neck_cond_max"] = neckMax;
  s.plots.push_back({"stability_thin_neck.svg",
                     {"B4 thin neck: one non-convex element, clamped on x = 0",
                      {"neck height eps", AxisScale::Log},
                      {"condition estimate (Lanczos)", AxisScale::Log},
                      neckPlot.series()}});
}

/// B4 near-incompressible: B3's tip deflection as nu approaches 1/2, against the reference;
/// `summary` receives the worst relative error.
void runIncompressible(const BenchOptions& o, SuiteOutput& s, nlohmann::json& summary,
                       const Log& log) {
  const std::vector<double> nus = {0.3, 0.49, 0.499, 0.4999};
  nlohmann::json incompressible = nlohmann::json::array();
  SeriesSet tipPlot;
  double worstTip = 0.0;
  for (int p : {1, 2}) {
    double tip03 = 0.0;
    for (double nu : nus) {
      const IncompressibleRun run = runIncompressibleCase(nu, p, o.quick);
      if (nu == 0.3) tip03 = run.tip;
      const LockingSetup setup = lockingSetup(p, o.quick);
      nlohmann::json j{
          {"nu", nu},
          {"degree", p},
          {"mesh", std::to_string(setup.mesh.nx) + "x" + std::to_string(setup.mesh.ny) + "x" +
                       std::to_string(setup.mesh.nz)},
          {"dofs", run.report.dofs},
          {"eta", run.report.eta},
          {"tip", run.tip},
          {"reference", run.reference},
          {"rel_error", run.relError},
          {"tip_over_nu_0_3", run.tip / tip03},
          {"within_5_percent", std::abs(run.relError) <= 0.05},
          {"t_solve", run.report.solveSeconds}};
      incompressible.push_back(j);
      j["case"] = "incompressible";
      s.rows.push_back(j);
      worstTip = std::max(worstTip, std::abs(run.relError));
      tipPlot.add("IP p=" + std::to_string(p) + " (" + j["mesh"].get<std::string>() + ")", 0.5 - nu,
                  run.tip);
      tipPlot.add("reference (Timoshenko)", 0.5 - nu, run.reference);
      log("incompressible p=" + std::to_string(p) + " nu " + shortNumber(nu) + ": tip " +
          shortNumber(run.tip) + " (reference " + shortNumber(run.reference) + ")");
    }
  }
  s.json["incompressible"] = incompressible;
  summary["incompressible_worst_rel_error"] = worstTip;
  summary["incompressible_within_5_percent"] = worstTip <= 0.05;
  s.plots.push_back({"stability_incompressible.svg",
                     {"B4 near-incompressible cantilever (B3): tip deflection",
                      {"1/2 - nu", AxisScale::Log},
                      {"tip deflection", AxisScale::Linear},
                      tipPlot.series()}});
}

/// B4 scale and position: B1 and B3 scaled and moved, against the unscaled run and the
/// round-off bound; `summary` receives the worst changes.
void runScale(const BenchOptions& o, SuiteOutput& s, nlohmann::json& summary, const Log& log) {
  const double eps = std::numeric_limits<double>::epsilon();
  nlohmann::json scale = nlohmann::json::array();
  SeriesSet scalePlot;
  double worstChange = 0.0, worstChangeOverBound = 0.0;
  const std::vector<Vec3> offsets{Vec3::Zero(), Vec3(1e6, -1e6, 1e6)};
  for (ScaleProblem problem : {ScaleProblem::B1, ScaleProblem::B3}) {
    const std::string name = problem == ScaleProblem::B1 ? "B1" : "B3";
    const double base = runScaleCase(problem, 1.0, Vec3::Zero(), 2, o.quick).value;
    const double cond = scaleProblemCondition(problem, 2, o.quick);
    for (const Vec3& offset : offsets)
      for (double sc : {1e-6, 1.0, 1e6}) {
        const ScaleRun run = runScaleCase(problem, sc, offset, 2, o.quick);
        const double change = std::abs(run.value / base - 1.0);
        const double relError = problem == ScaleProblem::B1 ? run.value : run.value / base - 1.0;
        nlohmann::json j{{"problem", name},
                         {"degree", run.degree},
                         {"scale", sc},
                         {"offset", {offset.x(), offset.y(), offset.z()}},
                         {"rel_error", relError},
                         {"value", run.value},
                         {"change", change},
                         {"coordinate_resolution", run.coordinateResolution},
                         {"cond", cond},
                         {"roundoff_bound", cond * std::max(run.coordinateResolution, eps)}};
        scale.push_back(j);
        j["case"] = "scale";
        s.rows.push_back(j);
        worstChange = std::max(worstChange, change);
        worstChangeOverBound = std::max(worstChangeOverBound,
                                        change / (cond * std::max(run.coordinateResolution, eps)));
        scalePlot.add(name + (offset.isZero() ? ", offset 0" : ", offset (1e6,-1e6,1e6)"), sc,
                      std::max(change, eps));
        log("scale " + name + " x" + shortNumber(sc) + " offset " + shortNumber(offset.x()) +
            ": rel_error " + shortNumber(relError) + ", change " + shortNumber(change));
      }
  }
  s.json["scale"] = scale;
  summary["scale_worst_change"] = worstChange;
  summary["scale_worst_change_over_roundoff_bound"] = worstChangeOverBound;
  s.plots.push_back({"stability_scale.svg",
                     {"B4 scale and position: change against the unscaled run",
                      {"scale", AxisScale::Log},
                      {"relative change (exact 0 drawn at 2.2e-16)", AxisScale::Log},
                      scalePlot.series()}});
}

}  // namespace

SuiteOutput stabilitySuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"stability", nlohmann::json::object(), nlohmann::json::array(), {}};
  s.json["cond_method"] = kConditionMethod;
  s.json["setup"] = {{"sliver",
                      "3x3x3 unit cubes, centre cell split at x = 1 + volume_ratio; IP, E = 1, "
                      "nu = 0.3, u = 0 weakly on the whole boundary; merged: mergeSlivers with "
                      "the sliver rule at 0.01 of a cell (the meshing default): volume below "
                      "0.01 of a cell, or 6 volume / surface area below 0.01^(1/3) = 0.215 of "
                      "a cell (slabs thinner than 0.084 of a cell)"},
                     {"thin_neck",
                      "one element: blocks [0,1]^3 and [2,3]x[0,1]^2 joined by the neck "
                      "[1,2]x[0,eps]x[0,1]; IP, clamped on x = 0"},
                     {"incompressible",
                      "B3 on the locking-test meshes: p = 1 160x4x8 with penalty doubling, "
                      "p = 2 40x4x4; reference = Euler-Bernoulli + Timoshenko shear at nu"},
                     {"scale",
                      "B1 (n = 4 hex, p = 2; rel_error = L2 error / L2 norm of u) and B3 (40x4x4, "
                      "p = 2; rel_error = tip / (scale * unscaled tip) - 1), lengths times scale, "
                      "translated by offset"}};
  const Log log = [&](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };
  nlohmann::json summary = nlohmann::json::object();
  runSliver(o, s, summary, log);
  runThinNeck(o, s, summary, log);
  runIncompressible(o, s, summary, log);
  runScale(o, s, summary, log);
  s.json["summary"] = summary;
  return s;
}

}  // namespace polydg::bench
