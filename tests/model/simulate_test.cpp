// Model::simulate: B10 (a beam cut while it moves: the freed part falls with g, nothing jumps,
// volume is kept), the damped static limit against Model::solve, scenes read strictly, and the
// time series on disk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <regex>
#include <tuple>

#include "physics/dynamics/dynamics.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/report_json.h"
#include "polydg/model/scene.h"
#include "polydg/util/error.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// B3's beam [0,10] x [0,1] x [0,1], 20 cells along it.
Model beam() {
  MeshOptions options;
  options.cells = 20;
  MeshReport report;
  Model m = Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3(10, 1, 1))), options, report,
                               "beam.obj");
  EXPECT_TRUE(report.passed());
  return m;
}

/// B10's scene: the clamped beam under gravity (0, 0, -1), cut through x = 5.1 at t = 1.
json b10Scene(double duration, bool cut = true) {
  json s = json::parse(R"({"material": {"E": 1000, "nu": 0.3, "density": 1},
      "method": "ip", "degree": 1, "corotational": true, "integrator": "euler", "dt": 0.05,
      "gravity": [0, 0, -1], "fixed": [{"plane": [1, 0, 0, 0]}],
      "cuts": [{"time": 1.0, "plane": [1, 0, 0, 5.1], "remove_side": "none"}]})");
  s["duration"] = duration;
  if (!cut) s["cuts"] = json::array();
  return s;
}

/// The integral of the displacement and the volume of the elements whose centroid lies on
/// one side of x = 5.1, from the model's solution (the final displacement).
struct Half {
  Vec3 first = Vec3::Zero();  ///< int u
  double volume = 0.0;
  Vec3 centroid = Vec3::Zero();  ///< undeformed, volume-weighted
};
Half half(Model& model, bool freed) {
  const MomentCache& moments = model.moments(2);
  const Solution* u = model.solution();
  EXPECT_NE(u, nullptr);
  Half h;
  for (std::size_t i = 0; i < model.mesh().numElements(); ++i) {
    const ElementId e(i);
    const Vec3 c = moments.centroid(e);
    if ((c.x() > 5.1) != freed) continue;
    const double v = moments.volume(e);
    h.first += v * u->fields.meanDisplacement[e];
    h.volume += v;
    h.centroid += v * c;
  }
  h.centroid /= h.volume;
  return h;
}

TEST(Simulate, CutWhileMovingFreesAHalfThatFallsWithGravity) {
  // B10. The freed half's centre of mass z at t = 1 + k m dt for k = 1, 2, 3: backward Euler
  // moves it by g dt^2 n (n + 1) / 2 after n free steps, so its second difference over m steps
  // is -g (m dt)^2 exactly whatever it did before (the internal forces of a free piece sum to
  // zero).
  const double dt = 0.05;
  const int m = 10;
  double z[3];
  for (int k = 1; k <= 3; ++k) {
    Model model = beam();
    const SimulationReport r = model.simulate(parseScene(b10Scene(1.0 + k * m * dt), "b10"), {});
    ASSERT_EQ(r.cuts.size(), 1u);
    const SimulationCut& cut = r.cuts[0];
    EXPECT_TRUE(cut.report.check.passed) << cut.report.check.failure;
    EXPECT_LT(cut.report.check.volumeRelError, 1e-10);
    EXPECT_NEAR(model.volume(), 10.0, 1e-10 * 10);
    EXPECT_GT(cut.elementsAfter, cut.elementsBefore);
    EXPECT_EQ(cut.exact, cut.elementsAfter);  // no sliver here: every element took its parent's
    // The new solver computed the blocks of the column of 4 cells the cut split (8 pieces) and
    // of the columns on either side (8 cells); the old solver's served the other 68 elements.
    EXPECT_EQ(cut.solverElements, 16u);
    // Its latency by phase: the phases lie within the whole, the checks within the cut, and
    // the step after it completes the latency (its steps run on).
    EXPECT_LE(cut.cutSeconds + cut.solverSeconds + cut.transferSeconds, cut.seconds);
    EXPECT_GT(cut.cutSeconds, 0.0);
    EXPECT_GT(cut.solverSeconds, 0.0);
    EXPECT_LE(cut.checkSeconds, cut.cutSeconds);
    EXPECT_GT(cut.checkSeconds, 0.0);  // local checks by default
    ASSERT_TRUE(cut.nextStepSeconds.has_value());
    EXPECT_GT(*cut.nextStepSeconds, 0.0);
    const Half freed = half(model, true);
    EXPECT_NEAR(freed.volume, 4.9, 1e-10);
    z[k - 1] = freed.centroid.z() + freed.first.z() / freed.volume;
  }
  const double acceleration = -(z[2] - 2 * z[1] + z[0]) / std::pow(m * dt, 2);
  EXPECT_NEAR(acceleration, 1.0, 0.01);
}

TEST(Simulate, ACutKeepsThePreconditionerTheStepsHadComeTo) {
  // CG on B10's beam with steps long enough that block-Jacobi would need more than 80
  // iterations: the first step's solve goes on with the p-multigrid after 50, the steps keep
  // it, and after the cut the new solver starts with it (its first step builds it) instead of
  // finding out again with block-Jacobi.
  json scene = b10Scene(2.0);
  scene["dt"] = 0.5;
  scene["solver"] = "cg";
  Model model = beam();
  const SimulationReport r = model.simulate(parseScene(scene, "b10"), {});
  ASSERT_EQ(r.cuts.size(), 1u);
  ASSERT_EQ(r.steps.size(), 4u);
  EXPECT_GT(r.steps[0].step.iterations, 50);
  EXPECT_EQ(r.steps[0].solver, "cg (block-jacobi, then p-multigrid): preconditioner built");
  EXPECT_EQ(r.steps[1].solver, "cg (p-multigrid): preconditioner reused");
  for (std::size_t k = 0; k < r.steps.size(); ++k)
    EXPECT_EQ(r.steps[k].step.preconditioner, CgPreconditioner::PMultigrid) << "step " << k;
  EXPECT_EQ(r.steps[2].solver, "cg (p-multigrid): preconditioner built");  // after the cut
  EXPECT_EQ(r.steps[3].solver, "cg (p-multigrid): preconditioner reused");
  // The build is timed as a part of the solve, and the cut's latency names it.
  for (const auto& s : r.steps) {
    EXPECT_GE(s.step.preconditionerSeconds, 0.0);
    EXPECT_LE(s.step.preconditionerSeconds, s.step.solveSeconds);
  }
  EXPECT_GT(r.steps[2].step.preconditionerSeconds, 0.0);
  ASSERT_TRUE(r.cuts[0].nextStepPreconditionerSeconds.has_value());
  EXPECT_EQ(*r.cuts[0].nextStepPreconditionerSeconds, r.steps[2].step.preconditionerSeconds);
}

/// int u and the volume over the elements whose centroid x lies in [lo, hi).
std::pair<Vec3, double> band(Model& model, double lo, double hi) {
  const MomentCache& moments = model.moments(2);
  const Solution* u = model.solution();
  Vec3 first = Vec3::Zero();
  double volume = 0.0;
  for (std::size_t i = 0; i < model.mesh().numElements(); ++i) {
    const ElementId e(i);
    const double x = moments.centroid(e).x();
    if (x < lo || x >= hi) continue;
    first += moments.volume(e) * u->fields.meanDisplacement[e];
    volume += moments.volume(e);
  }
  return {first, volume};
}

TEST(Simulate, CutCarriesTheFieldsOverExactly) {
  // Cut at the end of the last step (t = 1): the displacement integrated over the elements the
  // cut split (the band 5 < x < 5.5) and over the others is the uncut simulation's to
  // round-off: the pieces took their parents' polynomials exactly. Nothing pops.
  Model cut = beam(), whole = beam();
  const SimulationReport r = cut.simulate(parseScene(b10Scene(1.0), "b10"), {});
  ASSERT_EQ(r.cuts.size(), 1u);
  EXPECT_FALSE(r.cuts[0].nextStepSeconds.has_value());  // the run ended with the cut
  whole.simulate(parseScene(b10Scene(1.0, false), "b10"), {});
  EXPECT_GT(cut.mesh().numElements(), whole.mesh().numElements());
  for (auto [lo, hi] : {std::pair{-1.0, 5.0}, std::pair{5.0, 5.5}, std::pair{5.5, 11.0}}) {
    const auto [a, va] = band(cut, lo, hi);
    const auto [b, vb] = band(whole, lo, hi);
    EXPECT_NEAR(va, vb, 1e-12);
    EXPECT_LT((a - b).norm(), 1e-10 * b.norm()) << "band " << lo << " " << hi;
    EXPECT_GT(b.norm(), 1e-3);  // it moved
  }
}

TEST(Simulate, RefinesByStressWithoutAPop) {
  // B10's beam under gravity, refined where the mean stress exceeds a threshold (scene "adapt"):
  // the clamped end refines, each element at most max_level times; the fields go to the
  // children exactly, so momentum and kinetic energy right after each refinement equal those
  // before.
  for (const char* split : {"octants", "halves"}) {
    Model model = beam();
    json scene = b10Scene(1.0, false);
    scene["adapt"] = {{"stress", 1.0}, {"split", split}, {"every", 5}, {"max_level", 2}};
    const SimulationReport r = model.simulate(parseScene(scene, "adapt"), {});
    ASSERT_FALSE(r.refinements.empty()) << split;
    std::size_t elements = r.elements;
    for (const SimulationRefinement& f : r.refinements) {
      EXPECT_EQ(f.elementsBefore, elements);
      EXPECT_EQ(f.elementsAfter,
                f.elementsBefore + f.marked * (std::string(split) == "octants" ? 7 : 1));
      EXPECT_EQ(f.exact, f.elementsAfter);
      EXPECT_LT(f.momentumChange, 1e-10);
      EXPECT_LT(f.kineticChange, 1e-10);
      // The DG elastic energy is the mesh's form: the penalty of a split face grows with the
      // children's smaller size, and corotation takes each child's own rotation (not asserted).
      elements = f.elementsAfter;
    }
    EXPECT_EQ(model.mesh().numElements(), elements);
    // At most max_level = 2 refinements of each element: 8^2 (or 2^2) children per cell.
    const std::size_t perCell = std::string(split) == "octants" ? 64 : 4;
    EXPECT_LE(model.mesh().numElements(), r.elements * perCell);
    EXPECT_TRUE(checkGeometry(model.mesh()).passed);
  }
}

TEST(Simulate, CoarsensBackWhenTheStressFalls) {
  // The beam bent by an end load until t = 2, damped: the clamped end refines while loaded and
  // every family of children merges back once its stresses fall below half the threshold. The
  // projection keeps momentum exactly and can only lose kinetic energy.
  Model model = beam();
  const json scene = json::parse(R"({"material": {"E": 1000, "nu": 0.3, "density": 1},
      "degree": 1, "dt": 0.1, "duration": 6.0, "damping": {"mass": 5},
      "fixed": [{"plane": [1, 0, 0, 0]}],
      "loads": [{"traction": [0, 0, -1], "on": {"plane": [1, 0, 0, 10]}, "until": 2.0}],
      "adapt": {"stress": 5, "every": 5, "max_level": 1, "coarsen": 0.5}})");
  const SimulationReport r = model.simulate(parseScene(scene, "coarsen"), {});
  std::size_t refinements = 0, coarsenings = 0;
  for (const SimulationRefinement& f : r.refinements) {
    EXPECT_LT(f.momentumChange, 1e-12);
    if (f.coarsened > 0) {
      ++coarsenings;
      EXPECT_LT(f.elementsAfter, f.elementsBefore);
      EXPECT_GE(f.kineticChange, -1e-12);  // a projection never adds kinetic energy
      EXPECT_LT(f.kineticChange, 1e-3);
    } else {
      ++refinements;
    }
  }
  EXPECT_GT(refinements, 0u);
  EXPECT_GT(coarsenings, 0u);
  EXPECT_EQ(model.mesh().numElements(), r.elements);  // every family merged back
  EXPECT_TRUE(checkGeometry(model.mesh()).passed);
}

TEST(Simulate, DampedSimulationSettlesToTheStaticSolve) {
  // The static limit: linear, heavily damped backward Euler under gravity against
  // Model::solve with the same clamp, load and discretization.
  Model dynamic = beam(), statics = beam();
  SolveOptions so;
  so.discretization.basis.degree = 1;
  so.material = {1000, 0.3, 1};
  so.gravity = Vec3(0, 0, -1);
  so.clamps = {FaceSelector::inPlane(0, 0.0)};
  statics.solve(so);
  json scene = json::parse(R"({"material": {"E": 1000, "nu": 0.3, "density": 1},
      "corotational": false, "dt": 5, "steps": 120, "damping": {"mass": 1},
      "gravity": [0, 0, -1], "fixed": [{"plane": [1, 0, 0, 0]}]})");
  const SimulationReport r = dynamic.simulate(parseScene(scene, "static"), {});
  const Eigen::VectorXd& a = dynamic.solution()->coefficients;
  const Eigen::VectorXd& b = statics.solution()->coefficients;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_LT((a - b).norm(), 1e-6 * b.norm());
  // At rest the energies balance as for the static solution: elastic = -gravity / 2.
  const BodyState& last = r.steps.back().state;
  EXPECT_NEAR(last.elastic, -0.5 * last.gravity, 1e-6 * last.elastic);
  EXPECT_LT(last.kinetic, 1e-12 * last.elastic);
}

TEST(Simulate, SceneKeyBzPenaltyReachesTheDiscretization) {
  // "bz_penalty": "fixed" in a scene gives BZ's fixed penalty: heavily damped, the body settles
  // to Model::solve's BZ fixed solution, which differs from the default (the superpenalty) by
  // far more than the tolerance.
  Model dynamic = beam(), statics = beam(), byDefault = beam();
  SolveOptions so;
  so.discretization.basis.degree = 1;
  so.discretization.method = Method::BZ;
  so.material = {1000, 0.3, 1};
  so.gravity = Vec3(0, 0, -1);
  so.clamps = {FaceSelector::inPlane(0, 0.0)};
  byDefault.solve(so);
  so.discretization.bzPenalty = BzPenalty::Fixed;
  statics.solve(so);
  json scene = json::parse(R"({"material": {"E": 1000, "nu": 0.3, "density": 1},
      "method": "bz", "bz_penalty": "fixed", "corotational": false, "dt": 5, "steps": 120,
      "damping": {"mass": 1}, "gravity": [0, 0, -1], "fixed": [{"plane": [1, 0, 0, 0]}]})");
  dynamic.simulate(parseScene(scene, "bz"), {});
  const Eigen::VectorXd& a = dynamic.solution()->coefficients;
  const Eigen::VectorXd& b = statics.solution()->coefficients;
  const Eigen::VectorXd& c = byDefault.solution()->coefficients;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_LT((a - b).norm(), 1e-6 * b.norm());
  EXPECT_GT((c - b).norm(), 1e-3 * b.norm());
}

/// The message of the InputError parsing `scene` throws ("" if none).
std::string refusal(const std::string& scene) {
  try {
    parseScene(json::parse(scene), "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Simulate, ScenesAreReadStrictly) {
  const std::string base = R"("material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.1)";
  EXPECT_EQ(refusal("{" + base + R"(, "steps": 3})"), "");
  // The issue's example, key for key.
  EXPECT_EQ(refusal(R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "method": "ip",
      "degree": 2, "corotational": true, "integrator": "euler", "dt": 0.1, "duration": 40,
      "gravity": [0, 0, -1], "damping": {"mass": 0.0, "stiffness": 0.0},
      "fixed": [{"plane": [1, 0, 0, 0]}, {"below": [0, 0, 1, 0.1]},
                {"box": [[0, 0, 0], [1, 1, 0.2]]}],
      "loads": [{"traction": [0, 0, -0.01], "on": {"plane": [1, 0, 0, 10]}, "until": 5.0}],
      "initial": {"velocity": [0, 0, 0], "angular_velocity": [0, 0, 0]},
      "output": {"every": 1},
      "cuts": [{"time": 1.0, "plane": [1, 0, 0, 5.1], "remove_side": "none"}]})"),
            "");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"{" + base + R"(, "steps": 3, "gravty": [0, 0, -1]})", "scene.json: gravty: unknown key"},
      {"{" + base + R"(, "steps": 3, "duration": 1})", "exactly one of \"duration\" and \"steps\""},
      {"{" + base + "}", "exactly one of \"duration\" and \"steps\""},
      {"{" + base + R"(, "duration": 0.25})", "duration: must be a whole number"},
      {"{" + base + R"(, "steps": 3, "integrator": "rk4"})",
       "integrator: 'rk4' is not one of euler, bdf2, newmark"},
      {"{" + base + R"(, "steps": 3, "fixed": [{"plane": [1, 0, 0]}]})", "fixed[0].plane"},
      {"{" + base + R"(, "steps": 3, "loads": [{"traction": [0, 0, 1], "on": {}}]})",
       "loads[0].on"},
      {"{" + base + R"(, "steps": 3, "cuts": [{"time": 5, "plane": [1, 0, 0, 1]}]})",
       "cuts[0].time: after the end of the simulation"},
      {"{" + base + R"(, "steps": 3, "cuts": [{"time": 0.1, "plane": [0, 0, 0, 1]}]})",
       "cuts[0].plane"},
      {"{" + base + R"(, "steps": 3, "initial": {"spin": [0, 0, 1]}})",
       "initial.spin: unknown key"},
      {R"({"material": {"E": -1, "nu": 0.3, "density": 1}, "dt": 0.1, "steps": 1})", "material.E"},
      {R"({"dt": 0.1, "steps": 1})", "material: missing"},
  };
  for (const auto& [scene, message] : bad) {
    const std::string got = refusal(scene);
    EXPECT_NE(got.find(message), std::string::npos) << scene << "\n -> " << got;
    EXPECT_NE(got.find("see the scene format in docs/guide.md"), std::string::npos) << got;
  }
}

TEST(Simulate, OneCheckRefusesTheSameValuesInFilesAndInCode) {
  // checkScene() is the one place: a file refuses a value at its key, and a scene made in code
  // with the same value is refused by Model::simulate() with the same words.
  const std::string base = R"("material": {"E": 1000, "nu": 0.3, "density": 1})";
  const std::vector<std::tuple<std::string, std::function<void(Scene&)>, std::string>> cases = {
      {R"("dt": 0, "steps": 3)", [](Scene& s) { s.dt = 0.0; },
       "dt: the time step must be a positive number"},
      {R"("dt": -0.1, "steps": 3)", [](Scene& s) { s.dt = -0.1; },
       "dt: the time step must be a positive number"},
      {R"("dt": 0.1, "steps": 0)", [](Scene& s) { s.steps = 0; }, "steps: must be"},
      {R"("dt": 0.1, "steps": 3, "degree": 4)", [](Scene& s) { s.discretization.basis.degree = 4; },
       "degree: must be 1, 2 or 3"},
      {R"("dt": 0.1, "steps": 3, "bz_penalty": "super")",
       [](Scene& s) { s.discretization.bzPenalty = BzPenalty::Super; }, "bz_penalty: "},
      {R"("dt": 0.1, "steps": 3, "damping": {"mass": -1})", [](Scene& s) { s.damping.mass = -1; },
       "damping.mass: must be a number >= 0"},
      {R"("dt": 0.1, "steps": 3, "output": {"every": 0})", [](Scene& s) { s.outputEvery = 0; },
       "output.every: "},
      {R"("dt": 0.1, "steps": 3, "material": {"nu": 0.5})",
       [](Scene& s) { s.material.poissonRatio = 0.5; }, "material.nu: "},
  };
  Model model = beam();
  for (const auto& [keys, edit, message] : cases) {
    std::string text = "{" + base + ", " + keys + "}";
    if (keys.find("material") != std::string::npos) text = "{" + keys + "}";
    const std::string got = refusal(text);
    EXPECT_NE(got.find("scene.json: " + message), std::string::npos) << text << "\n -> " << got;
    Scene scene = parseScene(json::parse("{" + base + R"(, "dt": 0.1, "steps": 3})"), "s");
    edit(scene);
    try {
      model.simulate(scene, {});
      ADD_FAILURE() << message << ": a scene made in code was not refused";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find(message), 0u) << e.what();
    }
  }
}

TEST(Simulate, SelectionsThatPickNothingAreRefusedBeforeAnyStep) {
  Model model = beam();
  json scene = b10Scene(0.1, false);
  scene["fixed"] = json::parse(R"([{"plane": [1, 0, 0, -3]}])");
  try {
    model.simulate(parseScene(scene, "s"), {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("selects no boundary face"), std::string::npos)
        << e.what();
  }
}

TEST(Simulate, WritesAParaViewTimeSeries) {
  const fs::path dir =
      fs::temp_directory_path() / ("polydg_simulate_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  Model model = beam();
  json scene = b10Scene(1.5);
  scene["output"] = {{"every", 4}};
  SimulateOptions options;
  options.outputDir = (dir / "out").string();
  int calls = 0;
  options.progress = [&](const SimulationProgress& p) { EXPECT_EQ(p.step, ++calls); };
  const SimulationReport r = model.simulate(parseScene(scene, "s"), options);
  EXPECT_EQ(calls, 30);
  // Frames at step 0, every 4 steps, right after the cut (step 20 is both) and at the end.
  std::vector<int> steps;
  for (const SimulationFrame& f : r.frames) steps.push_back(f.step);
  EXPECT_EQ(steps, (std::vector<int>{0, 4, 8, 12, 16, 20, 24, 28, 30}));
  std::ifstream in(dir / "out" / "scene.pvd");
  std::stringstream pvd;
  pvd << in.rdbuf();
  const std::string text = pvd.str();
  const std::regex dataset("<DataSet timestep=\"([^\"]+)\"[^>]*file=\"([^\"]+)\"");
  std::size_t n = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), dataset);
       it != std::sregex_iterator(); ++it, ++n) {
    ASSERT_LT(n, r.frames.size());
    EXPECT_EQ((*it)[2].str(), r.frames[n].file);
    EXPECT_NEAR(std::stod((*it)[1].str()), r.frames[n].t, 1e-12);
    // Each frame is a mesh polydg reads back, with its point data.
    const Model frame = Model::read((dir / "out" / r.frames[n].file).string());
    EXPECT_EQ(frame.mesh().numElements(), r.frames[n].step < 20 ? 80u : model.mesh().numElements());
  }
  EXPECT_EQ(n, r.frames.size());
  const json report = toJson(r);
  EXPECT_EQ(report["steps"].size(), 30u);
  for (const char* key : {"t", "kinetic", "elastic", "gravity", "momentum", "angular_momentum",
                          "cg_iterations", "seconds"})
    EXPECT_TRUE(report["steps"][0].contains(key)) << key;
  fs::remove_all(dir);
}

/// The elements an edit made, moved or changed (DynamicSolver's `changed`).
std::vector<char> changedBy(const OperationReport& edit, std::size_t elements) {
  std::vector<char> changed(elements, 0);
  for (ElementId e : edit.touched) changed[e.index()] = 1;
  for (const auto& [id, sources] : edit.lineage.changed) changed[id] = 1;
  return changed;
}

TEST(Simulate, ASolverMadeFromTheOneBeforeACutEqualsAFreshOne) {
  // The beam (40 x 4 x 4 cells) cut four times (across, along it, at a slant, along it again),
  // each time a solver made from the one before and a fresh one: the same elastic force and
  // the same step, bit for bit, with the blocks computed again only around the cut (or all
  // laid out anew once the unused ones outnumber those in use). Then a refinement, and a
  // coarsening that moves elements to other ids.
  MeshOptions options;
  options.cells = 40;
  MeshReport meshed;
  Model model = Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3(10, 1, 1))), options, meshed,
                                   "beam.obj");
  DynamicsOptions o;
  o.material = {1000, 0.3, 1};
  o.discretization.basis.degree = 1;
  DynamicLoads loads;
  loads.gravity = Vec3(0, 0, -1);
  loads.clamps = {FaceSelector::inPlane(0, 0.0)};
  auto solverOf = [&](Model& m) { return DynamicSolver(m.mesh(), m.moments(2), loads, o); };
  DynamicSolver kept = solverOf(model);
  EXPECT_EQ(kept.elementsComputed(), model.mesh().numElements());
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<std::string> rebuilt;
  auto check = [&](const OperationReport& edit, const std::string& what) {
    ASSERT_TRUE(edit.check.passed) << what;
    const std::size_t ne = model.mesh().numElements();
    DynamicSolver updated(model.mesh(), model.moments(2), loads, o, std::move(kept),
                          changedBy(edit, ne));
    DynamicSolver fresh = solverOf(model);
    // Computed again: the changed elements and their neighbours, and no other.
    const std::vector<char> changed = changedBy(edit, ne);
    std::vector<char> again = changed;
    for (const Face& f : model.mesh().faces())
      if (f.front.valid() && f.back.valid() &&
          (changed[f.front.index()] || changed[f.back.index()]))
        again[f.front.index()] = again[f.back.index()] = 1;
    const auto expected = static_cast<std::size_t>(std::count(again.begin(), again.end(), 1));
    EXPECT_LT(expected, ne) << what;
    if (updated.elementsComputed() == ne)
      rebuilt.push_back(what);  // the unused blocks had come to outnumber the used ones
    else
      EXPECT_EQ(updated.elementsComputed(), expected) << what;
    Eigen::VectorXd u(static_cast<Eigen::Index>(fresh.dofs())), v(u.size());
    for (Eigen::Index i = 0; i < u.size(); ++i) {
      u[i] = 0.05 * unit(rng);
      v[i] = 0.1 * unit(rng);
    }
    for (DynamicSolver* s : {&updated, &fresh}) s->setState(1.0, u, v);
    EXPECT_EQ(updated.elasticForce(), fresh.elasticForce()) << what;
    updated.step(0.05);
    fresh.step(0.05);
    EXPECT_EQ(updated.displacement(), fresh.displacement()) << what;
    EXPECT_EQ(updated.velocity(), fresh.velocity()) << what;
    kept = std::move(updated);
  };
  for (const auto& [plane, what] :
       {std::pair{Plane::make(Vec3(1, 0, 0), 5.1), "across"},
        std::pair{Plane::make(Vec3(0, 1, 0), 0.53), "along"},
        std::pair{Plane::make(Vec3(1, 0.4, 0.3).normalized(), 3.3), "at a slant"},
        std::pair{Plane::make(Vec3(0, 0, 1), 0.46), "along, again"}}) {
    CutRequest cut;
    cut.blade = Blade::plane(plane.normal, plane.offset);
    check(model.cut(cut), what);
  }
  RefineRequest refine;
  for (std::uint32_t e : {3u, 40u, 41u, 77u}) refine.elements.push_back(ElementId(e));
  check(model.refine(refine).operation, "refined");
  // Pairs of elements near the start merged: the last elements (pieces of the cuts) move into
  // the ids the merge frees, so the old solver's blocks under those ids are other elements'.
  CoarsenRequest coarsen;
  std::vector<char> used(model.mesh().numElements(), 0);
  for (const Face& f : model.mesh().faces()) {
    if (coarsen.groups.size() == 3) break;
    if (!f.front.valid() || !f.back.valid() || f.front.index() > 100 || f.back.index() > 100 ||
        used[f.front.index()] || used[f.back.index()])
      continue;
    used[f.front.index()] = used[f.back.index()] = 1;
    coarsen.groups.push_back({f.front, f.back});
  }
  ASSERT_EQ(coarsen.groups.size(), 3u);
  const OperationReport merged = model.coarsen(coarsen).operation;
  std::size_t moved = 0;  // elements that only changed id
  for (const auto& [id, sources] : merged.lineage.changed)
    moved += sources.size() == 1 &&
             !std::binary_search(merged.touched.begin(), merged.touched.end(), ElementId(id));
  EXPECT_GT(moved, 0u);
  check(merged, "merged");
  // Two cuts along the beam computed most blocks twice: the second time all were laid out anew.
  EXPECT_EQ(rebuilt, std::vector<std::string>{"along, again"});
  // Another material, the mesh unchanged: none of the old blocks fit, all are computed.
  const std::size_t ne = model.mesh().numElements();
  o.material = {2000, 0.3, 1};
  const DynamicSolver stiffer(model.mesh(), model.moments(2), loads, o, std::move(kept),
                              std::vector<char>(ne, 0));
  EXPECT_EQ(stiffer.elementsComputed(), ne);
}

TEST(Simulate, TorusRotatedRigidlyHasNoCorotatedForceAndKeepsItsVolumeSpinning) {
  // B7 on testdata's torus meshed at 8 cells (sliced elements, cut faces, non-convex cells).
  MeshOptions options;
  options.cells = 8;
  MeshReport meshed;
  Model model = Model::fromSurface(readSurface(std::string(POLYDG_TESTDATA_DIR) + "/torus.obj"),
                                   options, meshed, "torus.obj");
  ASSERT_TRUE(meshed.passed());
  const MomentCache& moments = model.moments(2);
  DynamicsOptions o;
  o.material = {1000, 0.3, 1};
  o.discretization.basis.degree = 1;
  const double dt = 2 * std::numbers::pi / 200;
  // (a) u = (R - I)(x - c), R 90 degrees about z: no elastic force with corotation.
  Eigen::Matrix3d r;
  r << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  double force[2];
  for (bool corotational : {false, true}) {
    o.corotational = corotational;
    DynamicSolver solver(model.mesh(), moments, {}, o);
    const Vec3 c = solver.referencePoint();
    const Eigen::VectorXd u = solver.affineField(r - Eigen::Matrix3d::Identity(), Vec3::Zero(), c);
    solver.setState(0, u, Eigen::VectorXd::Zero(u.size()));
    force[corotational] = solver.elasticForce().norm();
  }
  EXPECT_LT(force[1], 1e-10 * force[0]) << "linear " << force[0];
  // (b) omega = (0, 0, 1) about the centroid, one turn in 200 steps.
  Eigen::Matrix3d spin;
  spin << 0, -1, 0, 1, 0, 0, 0, 0, 0;
  for (Integrator integrator : {Integrator::BackwardEuler, Integrator::Newmark}) {
    double change[2];
    for (bool corotational : {false, true}) {
      o.corotational = corotational;
      o.integrator = integrator;
      DynamicSolver solver(model.mesh(), moments, {}, o);
      const Eigen::VectorXd v = solver.affineField(spin, Vec3::Zero(), solver.referencePoint());
      solver.setState(0, Eigen::VectorXd::Zero(v.size()), v);
      const double v0 = solver.deformedVolume();
      EXPECT_NEAR(v0, model.volume(), 1e-12 * v0);
      for (int k = 0; k < 200; ++k) solver.step(dt);
      change[corotational] = std::abs(solver.deformedVolume() / v0 - 1);
    }
    // Newmark keeps the volume to 0.1%. Backward Euler's straight steps stretch a spinning
    // body by (omega dt)^2 = 9.9e-4 per step, which the elastic forces hold near that size.
    const double dtOmega = dt;
    const double bound = integrator == Integrator::Newmark ? 1e-3 : 2 * dtOmega * dtOmega;
    EXPECT_LT(change[1], bound) << "linear " << change[0];
    EXPECT_GT(change[0], 1.0);
    RecordProperty(
        integrator == Integrator::Newmark ? "newmark_volume_change" : "euler_volume_change",
        std::to_string(change[1]));
  }
}

}  // namespace
}  // namespace polydg
