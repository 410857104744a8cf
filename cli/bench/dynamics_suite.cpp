#include "cli/bench/suites.h"

#include "cli/bench/problems.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "mesh/primitives.h"
#include "physics/dynamics/dynamics.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/model/scene.h"
#include "polydg/physics/dg/post_process.h"
#include "util/stopwatch.h"

namespace polydg::bench {

namespace {

constexpr double kPi = std::numbers::pi;

/// E = 1000, nu = 0.3, density 1: the material of B6, B7 and B10.
const Material kMaterial{1000.0, 0.3, 1.0};

/// B6: B3's beam [0,10] x [0,1] x [0,1] on a 20 x 2 x 2 hex grid, p = 2.
constexpr int kB6Nx = 20, kB6Nyz = 2, kB6Degree = 2;
constexpr double kB6Length = 10.0;
/// B6's Euler-Bernoulli first period, 2 pi / (1.8751^2 sqrt(EI / (rho A L^4))).
constexpr double kB6Period = 19.58;
constexpr int kStepsPerPeriod = 200;
/// B6's plot: at most about this many points per curve (the CSV has every step).
constexpr int kPlotPoints = 400;

/// B7: the unit cube on a 4^3 hex grid, p = 1, one turn of omega = (0, 0, 1) in 200 steps.
constexpr int kB7Cells = 4;
constexpr int kB7StepsPerTurn = 200;

/// Speed: warm-up steps (the first builds the solver's matrix pattern and preconditioner),
/// then timed steps.
constexpr int kWarmupSteps = 2;

const Integrator kIntegrators[] = {Integrator::BackwardEuler, Integrator::Bdf2,
                                   Integrator::Newmark};

/// The integrator's key in the JSON and CSV: its scene name.
std::string key(Integrator i) { return nameOf(integratorNames(), i); }

/// The integrator's name in plot legends.
std::string label(Integrator i) {
  switch (i) {
    case Integrator::BackwardEuler: return "backward Euler";
    case Integrator::Bdf2: return "BDF2";
    case Integrator::Newmark: return "Newmark";
  }
  return "?";
}

DynamicsOptions dynamicsOptions(int degree, bool corotational, Integrator integrator) {
  DynamicsOptions o;
  o.material = kMaterial;
  o.discretization.basis.degree = degree;
  o.corotational = corotational;
  o.integrator = integrator;
  return o;
}

std::string gridName(int nx, int ny, int nz) {
  return std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz);
}

/// B6's tip deflection: the mean u_z over the beam's end x = 10.
double tipDeflection(const PolyMesh& mesh, const DgBasis& basis, const Eigen::VectorXd& u) {
  return meanBoundaryDisplacement(mesh, basis, u, FaceSelector::inPlane(0, kB6Length), 2);
}

/// B6: free vibration of the cantilever released from its static deflection under the end
/// traction, linear model, each integrator.
nlohmann::json b6Part(bool quick, SuiteOutput& s,
                      const std::function<void(const std::string&)>& log) {
  const PolyMesh mesh =
      hexGridMesh(kB6Nx, kB6Nyz, kB6Nyz, Box3(Vec3::Zero(), Vec3(kB6Length, 1, 1)));
  MomentCache moments(mesh, 2 * kB6Degree);
  moments.update();
  StaticOptions so;
  so.discretization.basis.degree = kB6Degree;
  LoadCase statics;
  statics.dirichlet.push_back({FaceSelector::inPlane(0, 0.0), {}});
  statics.tractions.push_back({FaceSelector::inPlane(0, kB6Length), Vec3(0, 0, -0.01)});
  const Eigen::VectorXd u0 = solveStatic(mesh, kMaterial, statics, so, &moments).coefficients;

  const int periods = quick ? 1 : 10;
  const int steps = periods * kStepsPerPeriod;
  const double dt = kB6Period / kStepsPerPeriod;
  const int stride = std::max(1, steps / kPlotPoints);
  const DynamicLoads loads{{FaceSelector::inPlane(0, 0.0)}, {}, Vec3::Zero()};
  SeriesSet energyPlot;
  nlohmann::json runs = nlohmann::json::array();
  std::size_t dofs = 0;
  for (Integrator integrator : kIntegrators) {
    const Stopwatch wall;
    DynamicSolver solver(mesh, moments, loads, dynamicsOptions(kB6Degree, false, integrator));
    dofs = solver.dofs();
    solver.setState(0.0, u0, Eigen::VectorXd::Zero(u0.size()));
    const BodyState s0 = solver.state();
    const double e0 = s0.kinetic + s0.elastic;
    double previous = tipDeflection(mesh, solver.basis(), u0);
    const double tip0 = previous;
    double worst = 0.0, lowest = 1.0, highest = 1.0, energy = 1.0;
    long iterations = 0;
    std::vector<double> crossings;
    auto record = [&](int step, double t) {
      s.rows.push_back(
          {{"part", "b6"}, {"integrator", key(integrator)}, {"t", t}, {"energy", energy}});
      if (step % stride == 0 || step == steps) energyPlot.add(label(integrator), t, energy);
    };
    record(0, 0.0);
    for (int k = 1; k <= steps; ++k) {
      const double t0 = solver.time();
      iterations += solver.step(dt).iterations;
      const double z = tipDeflection(mesh, solver.basis(), solver.displacement());
      if ((previous < 0) != (z < 0)) crossings.push_back(t0 + dt * previous / (previous - z));
      previous = z;
      const BodyState b = solver.state();
      energy = (b.kinetic + b.elastic) / e0;
      worst = std::max(worst, std::abs(energy - 1.0));
      lowest = std::min(lowest, energy);
      highest = std::max(highest, energy);
      record(k, solver.time());
    }
    // Zero crossings are half a period apart: the mean over all of them.
    const nlohmann::json period =
        crossings.size() >= 2
            ? nlohmann::json(2 * (crossings.back() - crossings.front()) / (crossings.size() - 1))
            : nlohmann::json(nullptr);
    runs.push_back({{"integrator", key(integrator)},
                    {"solver", toString(solver.solverKind())},
                    {"period", period},
                    {"period_over_euler_bernoulli",
                     period.is_null() ? period : nlohmann::json(period.get<double>() / kB6Period)},
                    {"zero_crossings", crossings.size()},
                    {"tip_initial", tip0},
                    {"energy_final", energy},
                    {"energy_min", lowest},
                    {"energy_max", highest},
                    {"energy_worst_change", worst},
                    {"iterations", iterations},
                    {"wall_seconds", wall.seconds()}});
    log("B6 " + key(integrator) + ": period " +
        (period.is_null() ? std::string("(too few crossings)")
                          : shortNumber(period.get<double>())) +
        " (Euler-Bernoulli " + shortNumber(kB6Period) + "), energy " + shortNumber(energy) +
        " of the initial after " + std::to_string(steps) + " steps (worst change " +
        shortNumber(worst) + "), " + shortNumber(wall.seconds()) + " s");
  }
  s.plots.push_back({"dynamics_energy.svg",
                     {"B6 free vibration, linear, p = 2, dt = T/200: energy against time",
                      {"t", AxisScale::Linear},
                      {"(kinetic + elastic) / initial", AxisScale::Linear},
                      energyPlot.series()}});
  return {
      {"setup", "B3's beam [0,10]x[0,1]x[0,1], " + gridName(kB6Nx, kB6Nyz, kB6Nyz) +
                    " hexahedra, p = 2, E = 1000, nu = 0.3, density 1, clamped on x = 0, linear "
                    "model, no damping; released at rest from the static solution under the end "
                    "traction (0, 0, -0.01) on x = 10; period from the zero crossings of the tip's "
                    "mean u_z (over the end face, by face quadrature)"},
      {"elements", mesh.numElements()},
      {"dofs", dofs},
      {"degree", kB6Degree},
      {"dt", dt},
      {"steps", steps},
      {"euler_bernoulli_period", kB6Period},
      {"runs", runs}};
}

/// B7 (b): the free unit cube spinning about z, linear against corotational, each integrator.
nlohmann::json b7Part(bool quick, SuiteOutput& s,
                      const std::function<void(const std::string&)>& log) {
  const PolyMesh mesh = hexGridMesh(kB7Cells, kB7Cells, kB7Cells, Box3(Vec3::Zero(), Vec3::Ones()));
  MomentCache moments(mesh, 2);
  moments.update();
  const int steps = quick ? kB7StepsPerTurn / 4 : kB7StepsPerTurn;
  const double dt = 2 * kPi / kB7StepsPerTurn;
  Eigen::Matrix3d spin;  // omega x (x - c), omega = (0, 0, 1)
  spin << 0, -1, 0, 1, 0, 0, 0, 0, 0;
  SeriesSet volumePlot, momentumPlot;
  nlohmann::json runs = nlohmann::json::array();
  std::size_t dofs = 0;
  for (Integrator integrator : kIntegrators)
    for (bool corotational : {false, true}) {
      const std::string model = corotational ? "corotational" : "linear";
      const std::string name = label(integrator) + ", " + model;
      const Stopwatch wall;
      DynamicSolver solver(mesh, moments, {}, dynamicsOptions(1, corotational, integrator));
      dofs = solver.dofs();
      const Eigen::VectorXd v = solver.affineField(spin, Vec3::Zero(), solver.referencePoint());
      solver.setState(0.0, Eigen::VectorXd::Zero(v.size()), v);
      const double v0 = solver.deformedVolume();
      const BodyState s0 = solver.state();
      const double l0 = s0.angularMomentum.z(), e0 = s0.kinetic + s0.elastic;
      double worstVolume = 0.0, worstMomentum = 0.0, linearMomentum = 0.0;
      long iterations = 0, solves = 0;
      auto record = [&](double t, double volume, double lz) {
        s.rows.push_back({{"part", "b7"},
                          {"integrator", key(integrator)},
                          {"corotational", corotational},
                          {"t", t},
                          {"volume", volume},
                          {"volume_change", std::abs(volume - 1.0)},
                          {"angular_momentum_z", lz}});
        volumePlot.add(name, t, std::abs(volume - 1.0));
        momentumPlot.add(name, t, lz / l0);
      };
      record(0.0, 1.0, l0);
      double volume = 1.0;
      BodyState b = s0;
      for (int k = 1; k <= steps; ++k) {
        const StepReport r = solver.step(dt);
        iterations += r.iterations;
        solves += r.solves;
        volume = solver.deformedVolume() / v0;
        b = solver.state();
        worstVolume = std::max(worstVolume, std::abs(volume - 1.0));
        worstMomentum = std::max(worstMomentum, std::abs(b.angularMomentum.z() / l0 - 1.0));
        linearMomentum = std::max(linearMomentum, b.momentum.norm());
        record(solver.time(), volume, b.angularMomentum.z());
      }
      runs.push_back({{"integrator", key(integrator)},
                      {"corotational", corotational},
                      {"solver", toString(solver.solverKind())},
                      {"volume_change_final", std::abs(volume - 1.0)},
                      {"volume_change_max", worstVolume},
                      {"angular_momentum_z_initial", l0},
                      {"angular_momentum_z_final", b.angularMomentum.z()},
                      {"angular_momentum_change_max", worstMomentum},
                      {"momentum_max", linearMomentum},
                      {"energy_final", (b.kinetic + b.elastic) / e0},
                      {"solves_per_step", static_cast<double>(solves) / steps},
                      {"iterations", iterations},
                      {"wall_seconds", wall.seconds()}});
      log("B7 " + key(integrator) + " " + model + ": volume change " +
          shortNumber(std::abs(volume - 1.0)) + ", angular momentum change " +
          shortNumber(b.angularMomentum.z() / l0 - 1.0) + " after " + std::to_string(steps) +
          " steps, " + shortNumber(static_cast<double>(solves) / steps) + " solves per step");
    }
  const std::string turn = quick ? "a quarter turn" : "one turn";
  s.plots.push_back({"dynamics_volume.svg",
                     {"B7 spinning cube, p = 1, " + turn + " in " + std::to_string(steps) +
                          " steps: volume change",
                      {"t", AxisScale::Linear},
                      {"|deformed volume / initial - 1|", AxisScale::Log},
                      volumePlot.series()}});
  s.plots.push_back({"dynamics_momentum.svg",
                     {"B7 spinning cube, p = 1, " + turn + " in " + std::to_string(steps) +
                          " steps: angular momentum",
                      {"t", AxisScale::Linear},
                      {"angular momentum z / initial", AxisScale::Linear},
                      momentumPlot.series()}});
  return {
      {"setup", "the unit cube, " + gridName(kB7Cells, kB7Cells, kB7Cells) +
                    " hexahedra, p = 1, E = 1000, nu = 0.3, density 1, free, no gravity; initial "
                    "velocity omega x (x - c), omega = (0, 0, 1), c the centroid; dt = 2 pi / 200; "
                    "volume = sum over elements of int det(I + grad u), relative to the initial; "
                    "angular momentum about c"},
      {"elements", mesh.numElements()},
      {"dofs", dofs},
      {"degree", 1},
      {"dt", dt},
      {"steps", steps},
      {"runs", runs}};
}

/// A peer's published time per step (issue 31's anchors), shown beside polydg's: their
/// machines and methods differ, so they are labelled as published, never as measured here.
struct PublishedStep {
  const char* source;
  const char* method;
  const char* machine;
  double dofs;  ///< 0: the source gives elements only
  double elements;
  double secondsPerStep;
};

/// Zhang et al. 2017 (shared/papers/zhang2017-smoothed-fem-corotational.txt), Table 1, rows
/// (1)-(5): DOFs 3 x nodes, time per step in ms; the other two as issue 31 quotes them.
constexpr PublishedStep kPublished[] = {
    {"Zhang et al. 2017, Table 1 (1)", "corotational FS-FEM on tetrahedra, implicit Euler, CG",
     "2.3 GHz dual-core CPU", 480, 410, 1.43e-3},
    {"Zhang et al. 2017, Table 1 (2)", "corotational FS-FEM on tetrahedra, implicit Euler, CG",
     "2.3 GHz dual-core CPU", 2790, 3240, 7.50e-3},
    {"Zhang et al. 2017, Table 1 (3)", "corotational FS-FEM on tetrahedra, implicit Euler, CG",
     "2.3 GHz dual-core CPU", 8400, 10940, 25.12e-3},
    {"Zhang et al. 2017, Table 1 (4)", "corotational FS-FEM on tetrahedra, implicit Euler, CG",
     "2.3 GHz dual-core CPU", 18750, 25920, 56.08e-3},
    {"Zhang et al. 2017, Table 1 (5)", "corotational FS-FEM on tetrahedra, implicit Euler, CG",
     "2.3 GHz dual-core CPU", 35310, 50620, 107.13e-3},
    {"Sase et al. 2015", "corotational FEM on tetrahedra with element removal", "GPU", 0, 19600,
     20e-3},
    {"Dick et al. 2011", "corotated hexahedral FEM, multigrid", "GPU", 0, 269000, 1.0 / 11.0},
};

nlohmann::json publishedSteps(SeriesSet& timePlot) {
  nlohmann::json out = nlohmann::json::array();
  for (const PublishedStep& p : kPublished) {
    nlohmann::json j{{"source", p.source},         {"method", p.method},
                     {"machine", p.machine},       {"elements", p.elements},
                     {"t_step", p.secondsPerStep}, {"steps_per_second", 1.0 / p.secondsPerStep},
                     {"published", true}};
    if (p.dofs > 0) {
      j["dofs"] = p.dofs;
      timePlot.add("published: Zhang et al. 2017, 2.3 GHz dual-core CPU", p.dofs, p.secondsPerStep);
    }
    out.push_back(j);
  }
  return out;
}

/// Time per step against DOFs: the B10-like clamped beam under gravity, p = 1, corotational.
nlohmann::json speedPart(bool quick, SuiteOutput& s,
                         const std::function<void(const std::string&)>& log) {
  // nx = 10 k, ny = nz = k (cubic cells): 12 * 10 k^3 = 7,680, 87,480 and 960,000 DOFs.
  const std::vector<int> sizes = quick ? std::vector<int>{4} : std::vector<int>{4, 9, 20};
  const int timedSteps = quick ? 3 : 10;
  const double dt = 0.01;
  const DynamicLoads loads{{FaceSelector::inPlane(0, 0.0)}, {}, Vec3(0, 0, -1)};
  SeriesSet timePlot, phasePlot;
  nlohmann::json runs = nlohmann::json::array();
  for (int k : sizes) {
    const PolyMesh mesh = hexGridMesh(10 * k, k, k, Box3(Vec3::Zero(), Vec3(10, 1, 1)));
    const std::string grid = gridName(10 * k, k, k);
    const Stopwatch integrate;
    MomentCache moments(mesh, 2);
    moments.update();
    const double integrateSeconds = integrate.seconds();
    for (Integrator integrator : kIntegrators) {
      const Stopwatch setup;
      DynamicSolver solver(mesh, moments, loads, dynamicsOptions(1, true, integrator));
      const double setupSeconds = setup.seconds();
      const double dofs = static_cast<double>(solver.dofs());
      log("speed " + grid + " (" + std::to_string(solver.dofs()) + " DOFs) " + key(integrator) +
          ": set up in " + shortNumber(setupSeconds) + " s, stepping");
      double firstStep = 0.0;
      for (int w = 0; w < kWarmupSteps; ++w) {
        const Stopwatch step;
        solver.step(dt);
        if (w == 0) firstStep = step.seconds();
      }
      double wall = 0.0, rotation = 0.0, assembly = 0.0, solve = 0.0, residual = 0.0;
      long iterations = 0, solves = 0, rebuilds = 0;
      for (int n = 0; n < timedSteps; ++n) {
        const Stopwatch step;
        const StepReport r = solver.step(dt);
        wall += step.seconds();
        rotation += r.rotationSeconds;
        assembly += r.assemblySeconds;
        solve += r.solveSeconds;
        iterations += r.iterations;
        solves += r.solves;
        rebuilds += r.preconditionerRebuilt || r.refactorized;
        residual = std::max(residual, r.residual);
      }
      const double n = timedSteps;
      const double perStep = wall / n;
      nlohmann::json j{{"part", "speed"},
                       {"integrator", key(integrator)},
                       {"grid", grid},
                       {"elements", mesh.numElements()},
                       {"dofs", solver.dofs()},
                       {"solver", toString(solver.solverKind())},
                       {"steps", timedSteps},
                       {"t_step", perStep},
                       {"t_rotation", rotation / n},
                       {"t_assembly", assembly / n},
                       {"t_solve", solve / n},
                       {"t_other", (wall - rotation - assembly - solve) / n},
                       {"iterations", iterations / n},
                       {"solves", solves / n},
                       {"steps_per_second", 1.0 / perStep},
                       {"preconditioner_rebuilds", rebuilds},
                       {"residual_max", residual},
                       {"t_first_step", firstStep},
                       {"t_setup", setupSeconds},
                       {"t_integrate", integrateSeconds}};
      runs.push_back(j);
      s.rows.push_back(j);
      timePlot.add(label(integrator), dofs, perStep);
      phasePlot.add(label(integrator) + ": rotation", dofs, rotation / n);
      phasePlot.add(label(integrator) + ": assembly", dofs, assembly / n);
      phasePlot.add(label(integrator) + ": solve", dofs, solve / n);
      log("speed " + grid + " " + key(integrator) + ": " + shortNumber(perStep) +
          " s per step (rotation " + shortNumber(rotation / n) + ", assembly " +
          shortNumber(assembly / n) + ", solve " + shortNumber(solve / n) + "), " +
          shortNumber(iterations / n) + " CG iterations in " + shortNumber(solves / n) +
          " solves per step");
    }
  }
  const nlohmann::json published = publishedSteps(timePlot);
  for (const nlohmann::json& p : published)
    log("published: " + p["source"].get<std::string>() + " (" + p["machine"].get<std::string>() +
        "): " + shortNumber(p["t_step"].get<double>()) + " s per step at " +
        (p.contains("dofs") ? shortNumber(p["dofs"].get<double>()) + " DOFs"
                            : shortNumber(p["elements"].get<double>()) + " elements"));
  s.plots.push_back({"dynamics_speed.svg",
                     {"Clamped beam under gravity, p = 1, corotational: wall time per step "
                      "(polydg measured here; Zhang et al. 2017 as published)",
                      {"DOFs", AxisScale::Log},
                      {"seconds per step", AxisScale::Log},
                      timePlot.series()}});
  s.plots.push_back({"dynamics_speed_phases.svg",
                     {"Clamped beam under gravity, p = 1, corotational: phases of a step",
                      {"DOFs", AxisScale::Log},
                      {"seconds per step", AxisScale::Log},
                      phasePlot.series()}});
  return {{"setup",
           "B10's beam without the cut: [0,10]x[0,1]x[0,1] as 10k x k x k hexahedra, p = 1, "
           "corotational, E = 1000, nu = 0.3, density 1, clamped on x = 0, gravity (0, 0, -1), "
           "from rest, dt = 0.01; " +
               std::to_string(kWarmupSteps) + " warm-up steps, then " + std::to_string(timedSteps) +
               " timed steps; times are wall seconds per step (means), t_other the step's time "
               "outside rotation, assembly and solve (the state update); `published`: peers' "
               "figures as their sources give them, other machines and methods"},
          {"runs", runs},
          {"published", published}};
}

/// Cut latency: B10's beam on a 10k x k x k hex grid (p = 1, corotational, backward Euler, dt =
/// 0.01, clamped at x = 0 under gravity (0, 0, -1)) cut at its third step by planes that touch
/// more and more of it; each cut's phases from the request to the next completed step.
nlohmann::json cutLatencyPart(bool quick, SuiteOutput& s,
                              const std::function<void(const std::string&)>& log) {
  const int k = quick ? 4 : 13;
  const PolyMesh mesh = hexGridMesh(10 * k, k, k, Box3(Vec3::Zero(), Vec3(10, 1, 1)));
  const std::string grid = gridName(10 * k, k, k);
  struct CutPlane {
    const char* what;
    std::array<double, 4> plane;
  };
  // Off the grid planes: a column of cells, a layer along the beam, a diagonal band.
  const CutPlane blades[] = {
      {"column", {1, 0, 0, 5.05}}, {"layer", {0, 1, 0, 0.53}}, {"diagonal", {0, 1, 1, 1.03}}};
  nlohmann::json runs = nlohmann::json::array();
  for (const CutPlane& blade : blades) {
    Model model(mesh);
    const nlohmann::json scene = {{"material",
                                   {{"E", kMaterial.youngsModulus},
                                    {"nu", kMaterial.poissonRatio},
                                    {"density", kMaterial.density}}},
                                  {"integrator", "euler"},
                                  {"dt", 0.01},
                                  {"steps", 4},
                                  {"gravity", {0, 0, -1}},
                                  {"fixed", {{{"plane", {1, 0, 0, 0}}}}},
                                  {"cuts", {{{"time", 0.02}, {"plane", blade.plane}}}}};
    const SimulationReport r = model.simulate(parseScene(scene, "cut latency"), {});
    const SimulationCut& cut = r.cuts.at(0);
    const double touched =
        static_cast<double>(cut.report.elementsSplit) / static_cast<double>(cut.elementsBefore);
    const double step = 0.5 * (r.steps[0].seconds + r.steps[1].seconds);
    const double next = cut.nextStepSeconds.value_or(0.0);
    const double build = cut.nextStepPreconditionerSeconds.value_or(0.0);
    nlohmann::json j{{"part", "cut_latency"},
                     {"grid", grid},
                     {"blade", blade.what},
                     {"plane", blade.plane},
                     {"elements", cut.elementsBefore},
                     {"dofs", 12 * cut.elementsBefore},
                     {"elements_split", cut.report.elementsSplit},
                     {"touched_fraction", touched},
                     {"t_cut", cut.cutSeconds},
                     {"t_check", cut.checkSeconds},
                     {"t_solver", cut.solverSeconds},
                     {"solver_elements", cut.solverElements},
                     {"t_transfer", cut.transferSeconds},
                     {"t_next_step", next},
                     {"t_next_step_preconditioner", build},
                     {"t_latency", cut.seconds + next},
                     {"t_step_before", step}};
    runs.push_back(j);
    s.rows.push_back(j);
    log("cut latency " + grid + ", " + blade.what + " (" + shortNumber(100 * touched) +
        "% of the elements split): " + shortNumber(cut.seconds + next) + " s (cut " +
        shortNumber(cut.cutSeconds) + ", solver " + shortNumber(cut.solverSeconds) + " for " +
        std::to_string(cut.solverElements) + " elements, transfer " +
        shortNumber(cut.transferSeconds) + ", next step " + shortNumber(next) +
        " (preconditioner " + shortNumber(build) + "); a step before it " + shortNumber(step) +
        ")");
  }
  return {{"setup", "B10's beam [0,10]x[0,1]x[0,1], " + grid +
                        " hex grid, p = 1, corotational, backward Euler, dt = 0.01; one plane "
                        "cut at t = 0.02 (local checks); times are wall seconds"},
          {"runs", runs}};
}

}  // namespace

SuiteOutput dynamicsSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"dynamics", nlohmann::json::object(), nlohmann::json::array(), {}};
  const std::function<void(const std::string&)> log = [&](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };
  s.json["b6"] = b6Part(o.quick, s, log);
  s.json["b7"] = b7Part(o.quick, s, log);
  s.json["speed"] = speedPart(o.quick, s, log);
  s.json["cut_latency"] = cutLatencyPart(o.quick, s, log);
  return s;
}

}  // namespace polydg::bench
