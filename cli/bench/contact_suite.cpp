#include "cli/bench/suites.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <system_error>
#include <vector>

#include "physics/contact/obstacles.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/scene.h"
#include "polydg/physics/contact/embedding.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg::bench {

namespace {

namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;

/// B9's body: a sphere of radius 0.5 about (0, 0, 1), E = 1e6, nu = 0.3, density 1000.
constexpr double kRadius = 0.5;
const Vec3 kCentre(0, 0, 1);
const Material kMaterial{1e6, 0.3, 1000.0};
const Vec3 kGravity(0, 0, -9.81);
/// The drops' time step, damping ("damping": {"mass": 2, "stiffness": 0.01}) and penalty
/// stiffness (pressure per unit penetration).
constexpr double kDt = 0.004;
constexpr double kMassDamping = 2.0, kStiffnessDamping = 0.01;
constexpr double kContactStiffness = 5e8;
/// B9: at rest the penetration must be below 1% of the radius.
constexpr double kPenetrationLimit = 0.01 * kRadius;

/// Parts 1 and 3: the fine sphere sliced with 4 cells along its bounding box's longest side.
constexpr int kEmbedCells = 4;
/// Part 4: B9's sphere as an icosphere of 3 levels (1,280 triangles), 6 cells.
constexpr int kB9Levels = 3, kB9Cells = 6;
/// The bowl of B9: inner radius 2, walls 0.2 thick, the inside bottom at z = 0 (the spheres'
/// centre at z = 2, where the rim is).
constexpr double kBowlInner = 2.0, kBowlThickness = 0.2;
const Vec3 kBowlCentre(0, 0, kBowlInner);

/// Repetitions whose median is reported (after one untimed warm-up each).
constexpr int kUpdateRepetitions = 20, kQueryRepetitions = 10;
/// Part 2's query points: directions uniform over the bowl's lower hemisphere, radii uniform
/// this far inside the inner and outside the outer sphere (so most points are in the band).
constexpr double kQueryShellMargin = 0.1;
/// Part 2's check of the field: points at least this far below the rim plane, where the nearest
/// surface is one of the two hemispheres.
constexpr double kRimClearance = 0.3;
constexpr std::uint64_t kSeed = 20261203;
/// Part 3's goal (the issue): collision handling and the surface update each below 10% of a
/// step in contact.
constexpr double kStepShareGoal = 0.1;
/// Part 4: "the energy never grows" allows this much growth, relative to the weight times the
/// radius (round-off of sums of energies of that size).
constexpr double kEnergyRoundoff = 1e-9;

/// The sizes of a run: the benchmark's, or --quick's smoke test.
struct Sizes {
  int rings = 0, segments = 0;  ///< the fine sphere, uvSphere(): 2 segments (rings - 1) triangles
  std::size_t queryPoints = 0;
  double stepDuration = 0.0;  ///< part 3's drop
  double dropDuration = 0.0;  ///< part 4's drops
  int bowlSegments = 0;       ///< bowlSurface(): segments^2 triangles
  /// Part 2's bowl fields: voxel min(bowl diagonal, body diagonal) / each of these.
  std::vector<double> voxelDivisors;
  /// Part 4's bowl field: the same with this divisor; 0 leaves the voxel to simulate().
  double dropVoxelDivisor = 0.0;
};

/// simulate()'s default voxel divisor (model/scene.h, SceneObstacle::voxel), and the one the
/// issue's benchmark asked for (twice as fine).
constexpr double kSimulateVoxelDivisor = 100.0, kIssueVoxelDivisor = 200.0;

Sizes sizes(bool quick) {
  // 74,884 and 1,860 triangles. The sphere falls 0.5 before it touches, slowed by the mass
  // damping (z'' = -g - 2 z'): at t = 0.356 s, so the quick drops of 0.4 s are in contact for
  // about 12 steps. Quick's bowl fields have voxels 5 times as large as simulate's (a 125th of
  // the voxels: seconds less to build).
  if (quick)
    return {31, 31, 10'000, 0.4, 0.4, 32, {kSimulateVoxelDivisor / 5}, kSimulateVoxelDivisor / 5};
  return {194, 194, 100'000, 0.5, 2.5, 128, {kSimulateVoxelDivisor, kIssueVoxelDivisor}, 0.0};
}

/// A scratch folder for the surfaces the scenes read, removed with everything in it.
class ScratchFolder {
 public:
  ScratchFolder() {
    path_ = fs::temp_directory_path() / ("polydg_bench_contact_" + std::to_string(getpid()));
    std::error_code ec;
    fs::remove_all(path_, ec);
    fs::create_directories(path_, ec);
    if (ec) throw InputError("cannot create " + path_.string() + ": " + ec.message());
  }
  ~ScratchFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Writes `surface` as an OBJ file (v and f lines, 17 significant digits: readSurface() reads
/// the same doubles back). Written here because mesh/ has no surface writer (surface_io.h only
/// reads), and the scenes name their surfaces by file.
std::string writeObj(const fs::path& file, const TriangleSurface& surface) {
  std::ofstream os(file);
  os.precision(17);
  for (const Vec3& v : surface.vertices)
    os << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : surface.triangles)
    os << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  os.close();
  if (!os) throw InputError("cannot write " + file.string());
  return file.string();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Median wall seconds of `repetitions` runs of `work`, after one untimed run.
double medianSeconds(int repetitions, const std::function<void()>& work) {
  work();
  std::vector<double> seconds;
  for (int r = 0; r < repetitions; ++r) {
    const Stopwatch watch;
    work();
    seconds.push_back(watch.seconds());
  }
  return median(seconds);
}

/// The model of `surface` sliced with `cells` cells, its provenance's source `source` (the file
/// "embed": true and the surface contact points read). Throws CheckFailure if the mesh fails a
/// check.
Model sphereModel(const TriangleSurface& surface, int cells, const std::string& source) {
  MeshOptions options;
  options.cells = cells;
  MeshReport report;
  Model model = Model::fromSurface(surface, options, report, source);
  if (!report.passed())
    throw CheckFailure("contact suite: the sphere's mesh failed a check: " +
                       report.failures().front());
  return model;
}

/// B9's scene: the sphere from rest under gravity, damped, penalty contact on its surface's
/// vertices (the provenance's source) against `obstacle`, backward Euler, p = 1.
Scene dropScene(double duration, const SceneObstacle& obstacle) {
  Scene scene;
  scene.material = kMaterial;
  scene.discretization.basis.degree = 1;
  scene.integrator = Integrator::BackwardEuler;
  scene.dt = kDt;
  scene.steps = static_cast<int>(std::lround(duration / kDt));
  scene.gravity = kGravity;
  scene.damping.mass = kMassDamping;
  scene.damping.stiffness = kStiffnessDamping;
  scene.obstacles.push_back(obstacle);
  scene.contact.stiffness = kContactStiffness;
  scene.contact.points = ContactPoints::Surface;
  return scene;
}

SceneObstacle ground() {
  SceneObstacle o;
  o.below = Plane::make(Vec3(0, 0, 1), 0.0);
  return o;
}

/// The distance field options simulate() gives an obstacle (model/simulate.cpp; its default
/// divisor is kSimulateVoxelDivisor): voxel min(obstacle diagonal, body diagonal) / divisor,
/// bands 3 voxels outside and max(3 voxels, a quarter of the body's diagonal) inside.
DistanceFieldOptions bowlField(const TriangleSurface& obstacle, double bodyDiagonal,
                               double divisor) {
  DistanceFieldOptions o;
  o.voxel = std::min(bounds(obstacle).diagonal().norm(), bodyDiagonal) / divisor;
  o.exteriorBand = 3.0 * o.voxel;
  o.interiorBand = std::max(3.0 * o.voxel, 0.25 * bodyDiagonal);
  return o;
}

/// Part 1: the embedding of the fine sphere's vertices for p = 1 and 2: setup, W, the update.
/// Returns the median update seconds for p = 1 (part 3 compares it with a step).
double embeddingPart(Model& model, const TriangleSurface& surface, SuiteOutput& s,
                     nlohmann::json& part, const Log& log) {
  nlohmann::json runs = nlohmann::json::array();
  double updateP1 = 0.0;
  for (int p : {1, 2}) {
    const DgBasis basis(model.mesh(), model.moments(2 * p), BasisOptions{p});
    const Stopwatch wall;
    const SurfaceEmbedding embedding(model.mesh(), basis, surface.vertices);
    const double wallSeconds = wall.seconds();
    // Any nonzero coefficients: the update reads W and U the same way whatever their values.
    std::mt19937_64 random(kSeed);
    std::uniform_real_distribution<double> uniform(-1e-3, 1e-3);
    Eigen::VectorXd u(static_cast<Eigen::Index>(basis.numElements() * 3) * basis.size());
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = uniform(random);
    double checksum = 0.0;
    const double update = medianSeconds(
        kUpdateRepetitions, [&] { checksum += embedding.displacements(u).cwiseAbs().sum(); });
    if (p == 1) updateP1 = update;
    const nlohmann::json j{{"part", "embedding"},
                           {"degree", p},
                           {"points", embedding.numPoints()},
                           {"samples", embedding.numSamples()},
                           {"outside", embedding.outside()},
                           {"setup_seconds", embedding.setupSeconds()},
                           {"setup_wall_seconds", wallSeconds},
                           {"weight_nonzeros", embedding.weightNonzeros()},
                           {"weights_per_point", static_cast<double>(embedding.weightNonzeros()) /
                                                     static_cast<double>(embedding.numPoints())},
                           {"stored_nonzeros", embedding.storedNonzeros()},
                           {"update_seconds", update},
                           {"update_repetitions", kUpdateRepetitions},
                           {"update_checksum", checksum}};
    runs.push_back(j);
    s.rows.push_back(j);
    log("embedding p = " + std::to_string(p) + ": " + std::to_string(embedding.numPoints()) +
        " points, set up in " + shortNumber(embedding.setupSeconds()) + " s, W " +
        std::to_string(embedding.weightNonzeros()) + " nonzeros, update " +
        shortNumber(update * 1e3) + " ms (median of " + std::to_string(kUpdateRepetitions) + ")");
  }
  part["runs"] = runs;
  return updateP1;
}

/// Part 2: 100k points against the ground and the bowl's distance fields.
nlohmann::json queryPart(const Sizes& z, double bodyDiagonal, const TriangleSurface& bowl,
                         SuiteOutput& s, const Log& log) {
  const double outer = kBowlInner + kBowlThickness;
  std::mt19937_64 random(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> points(z.queryPoints);
  for (Vec3& x : points) {
    // Uniform on the lower hemisphere (Archimedes: the height is uniform), radius uniform.
    const double h = -unit(random), phi = 2 * kPi * unit(random);
    const double r =
        kBowlInner - kQueryShellMargin + (kBowlThickness + 2 * kQueryShellMargin) * unit(random);
    const double ring = std::sqrt(1 - h * h);
    x = kBowlCentre + r * Vec3(ring * std::cos(phi), ring * std::sin(phi), h);
  }
  // The triangles' largest distance from the spheres their vertices lie on (the chord sag of
  // triangles spanning 2 pi / segments in both directions), which max_distance_error includes.
  const double sag = outer * kPi * kPi / (z.bowlSegments * z.bowlSegments);
  std::vector<ObstacleQuery> out(points.size());
  nlohmann::json runs = nlohmann::json::array();
  auto measure = [&](const Obstacle& o, const std::string& name, double divisor) {
    const double seconds = medianSeconds(kQueryRepetitions, [&] { o.query(points, 0.0, out); });
    const double band = o.fieldOptions().exteriorBand;
    std::size_t inside = 0, inBand = 0, checked = 0, beyondWithNormal = 0;
    double distanceError = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const bool hasNormal = out[i].normal != Vec3::Zero();
      inside += out[i].distance < 0.0;
      inBand += hasNormal;
      if (o.isHalfSpace() || points[i].z() >= kBowlCentre.z() - kRimClearance) continue;
      // The exact signed distance to the shell where a hemisphere is the nearest surface.
      const double r = (points[i] - kBowlCentre).norm();
      const double exact = std::max(kBowlInner - r, r - outer);
      // Where the field gives a normal (a distance without one says only "no contact").
      if (exact < band && hasNormal) {
        distanceError = std::max(distanceError, std::abs(out[i].distance - exact));
        ++checked;
      }
      // Farther out than the band even from the facets: no normal (obstacles.h, query()).
      beyondWithNormal += exact > band + sag && hasNormal;
    }
    nlohmann::json j{
        {"part", "query"},
        {"obstacle", name},
        {"points", points.size()},
        {"seed", kSeed},
        {"setup_seconds", o.setupSeconds()},
        {"active_voxels", o.activeVoxels()},
        {"voxel", o.fieldOptions().voxel},
        {"exterior_band", band},
        {"interior_band", o.fieldOptions().interiorBand},
        {"query_seconds", seconds},
        {"query_repetitions", kQueryRepetitions},
        {"seconds_per_million_points", seconds * 1e6 / static_cast<double>(points.size())},
        {"inside", inside},
        {"in_band", inBand}};
    if (!o.isHalfSpace()) {
      j["voxel_divisor"] = divisor;
      j["triangles"] = bowl.triangles.size();
      j["checked_points"] = checked;
      j["max_distance_error"] = distanceError;
      j["facet_sag"] = sag;
      j["beyond_band_with_normal"] = beyondWithNormal;
    }
    runs.push_back(j);
    s.rows.push_back(j);
    log("queries " + name + ": " + std::to_string(points.size()) + " points in " +
        shortNumber(seconds * 1e3) + " ms (median of " + std::to_string(kQueryRepetitions) + ")" +
        (o.isHalfSpace()
             ? std::string()
             : ", field of " + std::to_string(o.activeVoxels()) + " voxels (voxel " +
                   shortNumber(o.fieldOptions().voxel) + ", diagonal / " + shortNumber(divisor) +
                   ") built in " + shortNumber(o.setupSeconds()) + " s, distance error " +
                   shortNumber(distanceError) + " against the spheres (facets' sag " +
                   shortNumber(sag) + "), " + std::to_string(beyondWithNormal) +
                   " points beyond the band with a normal"));
  };
  measure(Obstacle::halfSpace(Plane::make(Vec3(0, 0, 1), 0.0)), "ground", 0.0);
  for (double divisor : z.voxelDivisors)
    measure(Obstacle::fromSurface(bowl, bowlField(bowl, bodyDiagonal, divisor)), "bowl", divisor);
  return {
      {"setup",
       "random points (seed " + std::to_string(kSeed) +
           "): directions uniform over the bowl's lower hemisphere, radii uniform in [inner - " +
           shortNumber(kQueryShellMargin) + ", outer + " + shortNumber(kQueryShellMargin) +
           "] about its centre (0, 0, 2); the ground z <= 0 (exact) and the bowl (inner "
           "radius 2, thickness 0.2, " +
           std::to_string(bowl.triangles.size()) +
           " triangles) as OpenVDB's narrow-band distance field with simulate's bands and "
           "voxel min(bowl diagonal, body diagonal) / voxel_divisor for the fine sphere (body "
           "diagonal " +
           shortNumber(bodyDiagonal) + "; simulate's default divisor is " +
           shortNumber(kSimulateVoxelDivisor) + ", the issue asked for " +
           shortNumber(kIssueVoxelDivisor) +
           "); query seconds are the median wall time of one query of all points at t = 0; "
           "max_distance_error against the exact distance to the shell's spheres, over "
           "points within the exterior band of them that get a normal and at least " +
           shortNumber(kRimClearance) +
           " below the rim: it includes the faceting of the bowl, whose triangles lie up to "
           "facet_sag = outer pi^2 / segments^2 inside the spheres; beyond_band_with_normal counts "
           "the points below that line farther than exterior_band + facet_sag from the shell that "
           "still got a normal (query() promises none beyond the band)"},
      {"runs", runs}};
}

/// Mean wall seconds of a simulation's steps. A step is what simulate() times as
/// SimulationStep::seconds plus the contact measure of its end state (timed after it); collision
/// is collisionSeconds: the obstacle queries and contact point positions in the step
/// (StepReport::contactQuerySeconds) and in that measure.
struct StepMeans {
  int steps = 0;
  double step = 0.0, collision = 0.0, inStep = 0.0, measure = 0.0;

  void add(const SimulationStep& s) {
    const double measured = s.collisionSeconds - s.step.contactQuerySeconds;
    ++steps;
    step += s.seconds + measured;
    collision += s.collisionSeconds;
    inStep += s.step.contactQuerySeconds;
    measure += measured;
  }
  StepMeans mean() const {
    if (steps == 0) return *this;
    const double n = steps;
    return {steps, step / n, collision / n, inStep / n, measure / n};
  }
};

/// The means over the steps in contact (contacts during the step or at its end) and the others.
std::pair<StepMeans, StepMeans> stepMeans(const SimulationReport& report) {
  StepMeans inContact, noContact;
  for (const SimulationStep& step : report.steps)
    (step.step.contacts > 0 || step.contact.contacts > 0 ? inContact : noContact).add(step);
  return {inContact.mean(), noContact.mean()};
}

/// Part 3: a step of the drop onto the ground with the fine surface embedded and its vertices
/// as contact points, against the collision handling and the surface update.
nlohmann::json stepPart(Model& model, const Sizes& z, double updateSeconds, SuiteOutput& s,
                        const Log& log) {
  Scene scene = dropScene(z.stepDuration, ground());
  scene.embed.enabled = true;  // the provenance's source: the fine sphere's OBJ file
  log("step: the drop onto the ground with the fine surface, " + std::to_string(scene.steps) +
      " steps");
  const SimulationReport report = model.simulate(scene, {});
  const auto [c, noContact] = stepMeans(report);
  SeriesSet timePlot;
  for (std::size_t k = 0; k < report.steps.size(); ++k) {
    const SimulationStep& step = report.steps[k];
    const double t = static_cast<double>(k + 1) * kDt;
    const double wall = step.seconds + step.collisionSeconds - step.step.contactQuerySeconds;
    timePlot.add("step (wall, with the contact measure)", t, wall);
    timePlot.add("collision (queries, point positions)", t, step.collisionSeconds);
    s.rows.push_back({{"part", "step_series"},
                      {"t", t},
                      {"contacts", step.contact.contacts},
                      {"step_seconds", wall},
                      {"collision_seconds", step.collisionSeconds},
                      {"collision_in_step_seconds", step.step.contactQuerySeconds}});
  }
  const std::string updateLabel = "surface update (part 1, p = 1)";
  timePlot.add(updateLabel, kDt, updateSeconds);
  timePlot.add(updateLabel, static_cast<double>(report.steps.size()) * kDt, updateSeconds);
  const bool measured = c.steps > 0;
  const double collisionShare = measured ? c.collision / c.step : 0.0;
  const double updateShare = measured ? updateSeconds / c.step : 0.0;
  const bool met = measured && collisionShare < kStepShareGoal && updateShare < kStepShareGoal;
  s.plots.push_back({"contact_step_time.svg",
                     {"Drop onto the ground, " + std::to_string(report.embedding.points) +
                          " contact points: wall time per step",
                      {"t", AxisScale::Linear},
                      {"seconds", AxisScale::Log},
                      timePlot.series()}});
  const nlohmann::json j{
      {"part", "step"},
      {"elements", report.elements},
      {"dofs", report.dofs},
      {"points", report.embedding.points},
      {"triangles", report.embedding.triangles},
      {"contact_points", report.embedding.contactPoints},
      {"weight_nonzeros", report.embedding.weightNonzeros},
      {"embedding_setup_seconds", report.embedding.setupSeconds},
      {"steps", report.steps.size()},
      {"contact_steps", c.steps},
      {"t_step_contact", measured ? nlohmann::json(c.step) : nullptr},
      {"t_collision_contact", measured ? nlohmann::json(c.collision) : nullptr},
      {"t_collision_contact_in_step", measured ? nlohmann::json(c.inStep) : nullptr},
      {"t_collision_contact_measure", measured ? nlohmann::json(c.measure) : nullptr},
      {"t_step_free", noContact.step},
      {"t_collision_free", noContact.collision},
      {"t_surface_update", updateSeconds},
      {"collision_over_step", measured ? nlohmann::json(collisionShare) : nullptr},
      {"update_over_step", measured ? nlohmann::json(updateShare) : nullptr},
      {"goal", kStepShareGoal},
      {"goal_met", met},
      {"wall_seconds", report.wallSeconds}};
  s.rows.push_back(j);
  log(measured ? "step in contact (" + std::to_string(c.steps) + " of " +
                     std::to_string(report.steps.size()) + " steps): " + shortNumber(c.step * 1e3) +
                     " ms, collision " + shortNumber(c.collision * 1e3) + " ms (" +
                     shortNumber(100 * collisionShare) + "%), surface update " +
                     shortNumber(updateSeconds * 1e3) + " ms (" + shortNumber(100 * updateShare) +
                     "%): goal (both below " + shortNumber(100 * kStepShareGoal) + "%) " +
                     (met ? "met" : "NOT met") + "; " + shortNumber(report.wallSeconds) + " s"
               : "step: no step was in contact; nothing to compare");
  nlohmann::json part = j;
  part.erase("part");
  part["setup"] =
      "B9's drop onto the ground z <= 0 with the fine sphere (parts 1, 2) embedded and its "
      "vertices as contact points: E = 1e6, nu = 0.3, density 1000, gravity (0, 0, -9.81), "
      "dt = 0.004, damping mass 2 and stiffness 0.01, contact stiffness 5e8, backward Euler, "
      "p = 1, corotational. Means over the steps with contacts (during the step or at its end; "
      "_free: the others): t_step the step (SimulationStep::seconds) and the contact measure "
      "of its end state, t_collision collisionSeconds (obstacle queries and contact point "
      "positions, _in_step within the step's solves, _measure in that measure); "
      "t_surface_update is part 1's median update for p = 1 (the simulation writes no frames, "
      "so it makes none); the goal: collision and update each below 10% of t_step";
  return part;
}

/// What a drop's steps show: the total energy against the start and from step to step, the
/// deepest penetration, and the steps in contact.
struct DropHistory {
  double total0 = 0.0;  ///< the total energy at the start
  double stepIncrease = -std::numeric_limits<double>::infinity(), stepIncreaseT = 0.0;
  double growth = -std::numeric_limits<double>::infinity(), growthT = 0.0;
  double deepest = 0.0, firstContact = -1.0;
  int contactSteps = 0;
  bool finite = true;
};

/// Scans the steps of a drop onto `obstacle`: each step is a row of `s` and a point of the
/// plots.
DropHistory scanDrop(const SimulationReport& report, const char* obstacle, SuiteOutput& s,
                     SeriesSet& penetrationPlot, SeriesSet& energyPlot) {
  DropHistory h;
  const BodyState& b0 = report.initial;
  h.total0 = b0.kinetic + b0.elastic + b0.gravity;
  // Against the start, and (a stricter reading, for damped steps) against the step before.
  double previous = h.total0;
  for (std::size_t k = 0; k < report.steps.size(); ++k) {
    const SimulationStep& step = report.steps[k];
    const BodyState& b = step.state;
    const double t = static_cast<double>(k + 1) * kDt;
    const double total = b.kinetic + b.elastic + b.gravity + step.contact.energy;
    h.finite = h.finite && std::isfinite(total) && std::isfinite(step.contact.deepest);
    if (total - h.total0 > h.growth) h.growth = total - h.total0, h.growthT = t;
    if (total - previous > h.stepIncrease) h.stepIncrease = total - previous, h.stepIncreaseT = t;
    previous = total;
    h.deepest = std::max(h.deepest, step.contact.deepest);
    if (step.contact.contacts > 0) {
      ++h.contactSteps;
      if (h.firstContact < 0) h.firstContact = t;
    }
    s.rows.push_back({{"part", "b9"},
                      {"obstacle", obstacle},
                      {"t", t},
                      {"contacts", step.contact.contacts},
                      {"deepest", step.contact.deepest},
                      {"kinetic", b.kinetic},
                      {"elastic", b.elastic},
                      {"gravity", b.gravity},
                      {"contact_energy", step.contact.energy},
                      {"total", total},
                      {"com_z", b.centreOfMass.z()},
                      {"step_seconds", step.seconds},
                      {"collision_seconds", step.collisionSeconds}});
    penetrationPlot.add(obstacle, t, step.contact.deepest);
    energyPlot.add(obstacle, t, total);
  }
  return h;
}

/// The summary of a drop onto `obstacle` (B9's criteria: final penetration below the limit,
/// energy that never grows beyond round-off of `energyScale`).
nlohmann::json dropSummary(const SimulationReport& report, const char* obstacle,
                           const DropHistory& h, double duration, double energyScale) {
  const SimulationStep& last = report.steps.back();
  const double finalPenetration = last.contact.deepest;
  const bool grows = h.growth > kEnergyRoundoff * energyScale;
  return {{"part", "b9_summary"},
          {"obstacle", obstacle},
          {"elements", report.elements},
          {"dofs", report.dofs},
          {"contact_points", report.embedding.contactPoints},
          {"steps", report.steps.size()},
          {"duration", duration},
          {"contact_steps", h.contactSteps},
          {"first_contact_t", h.firstContact >= 0 ? nlohmann::json(h.firstContact) : nullptr},
          {"final_penetration", finalPenetration},
          {"penetration_limit", kPenetrationLimit},
          {"final_below_limit", finalPenetration < kPenetrationLimit},
          {"max_penetration", h.deepest},
          {"final_contacts", last.contact.contacts},
          {"final_kinetic", last.state.kinetic},
          {"final_com_z", last.state.centreOfMass.z()},
          {"initial_total", h.total0},
          {"max_energy_growth", h.growth},
          {"max_energy_growth_t", h.growthT},
          {"max_step_energy_increase", h.stepIncrease},
          {"max_step_energy_increase_t", h.stepIncreaseT},
          {"energy_scale", energyScale},
          {"energy_growth_allowed", kEnergyRoundoff * energyScale},
          {"energy_never_grows", !grows},
          {"energies_finite", h.finite},
          {"wall_seconds", report.wallSeconds}};
}

/// The log line of a drop onto `obstacle`.
std::string dropLine(const SimulationReport& report, const char* obstacle, const DropHistory& h,
                     double energyScale) {
  const double finalPenetration = report.steps.back().contact.deepest;
  const bool grows = h.growth > kEnergyRoundoff * energyScale;
  return "B9 " + std::string(obstacle) + ": final penetration " + shortNumber(finalPenetration) +
         " (limit " + shortNumber(kPenetrationLimit) + ": " +
         (finalPenetration < kPenetrationLimit ? "below" : "ABOVE") + "), deepest " +
         shortNumber(h.deepest) + ", " + std::to_string(h.contactSteps) +
         " steps in contact from t = " + shortNumber(h.firstContact) + ", energy growth at most " +
         shortNumber(h.growth) + " J (allowed " + shortNumber(kEnergyRoundoff * energyScale) +
         "; largest increase over a step " + shortNumber(h.stepIncrease) +
         " J at t = " + shortNumber(h.stepIncreaseT) + ")" + (grows ? ": ENERGY GROWS" : "") +
         ", " + shortNumber(report.wallSeconds) + " s";
}

/// Part 4: B9's drops onto the ground and into the bowl with the coarse sphere.
nlohmann::json b9Part(const Sizes& z, const fs::path& scratch, const std::string& bowlFile,
                      const TriangleSurface& bowlSurface, SuiteOutput& s, const Log& log) {
  const TriangleSurface sphere = icosphere(kCentre, kRadius, kB9Levels);
  const std::string sphereFile = writeObj(scratch / "b9_sphere.obj", sphere);
  SeriesSet penetrationPlot, energyPlot;
  nlohmann::json runs = nlohmann::json::array();
  const double duration = z.dropDuration;
  for (const char* obstacle : {"ground", "bowl"}) {
    const bool bowl = std::string(obstacle) == "bowl";
    SceneObstacle o = ground();
    Model model = sphereModel(sphere, kB9Cells, sphereFile);
    if (bowl) {
      o.below.reset();
      o.mesh = bowlFile;
      if (z.dropVoxelDivisor > 0.0)
        o.voxel =
            bowlField(bowlSurface, meshBounds(model.mesh()).diagonal().norm(), z.dropVoxelDivisor)
                .voxel;
    }
    const double mass = model.volume() * kMaterial.density;
    const double energyScale = mass * kGravity.norm() * kRadius;
    const Scene scene = dropScene(duration, o);
    log("B9 " + std::string(obstacle) + ": " + std::to_string(scene.steps) + " steps");
    const SimulationReport report = model.simulate(scene, {});
    const DropHistory history = scanDrop(report, obstacle, s, penetrationPlot, energyPlot);
    nlohmann::json j = dropSummary(report, obstacle, history, duration, energyScale);
    if (bowl) {
      j["obstacle_setup_seconds"] = report.embedding.obstacleSetupSeconds.front();
      // null: simulate's default.
      j["voxel_divisor"] =
          z.dropVoxelDivisor > 0.0 ? nlohmann::json(z.dropVoxelDivisor) : nlohmann::json(nullptr);
      j["obstacle_voxels"] = report.embedding.obstacleVoxels.front();
    }
    runs.push_back(j);
    s.rows.push_back(j);
    log(dropLine(report, obstacle, history, energyScale));
  }
  penetrationPlot.add("1% of the radius", 0.0, kPenetrationLimit);
  penetrationPlot.add("1% of the radius", duration, kPenetrationLimit);
  s.plots.push_back({"contact_penetration.svg",
                     {"B9 drop (sphere r = 0.5, p = 1): deepest penetration",
                      {"t", AxisScale::Linear},
                      {"deepest penetration", AxisScale::Linear},
                      penetrationPlot.series()}});
  s.plots.push_back({"contact_energy.svg",
                     {"B9 drop: kinetic + elastic + gravity + contact energy",
                      {"t", AxisScale::Linear},
                      {"total energy (J)", AxisScale::Linear},
                      energyPlot.series()}});
  return {{"setup",
           "B9: sphere r = 0.5 about (0, 0, 1) as an icosphere of " +
               std::to_string(sphere.triangles.size()) + " triangles sliced with " +
               std::to_string(kB9Cells) +
               " cells, its vertices as contact points; E = 1e6, nu = 0.3, density 1000, gravity "
               "(0, 0, -9.81), dt = 0.004, damping mass 2 and stiffness 0.01, contact stiffness "
               "5e8, backward Euler, p = 1, corotational; onto the ground z <= 0, then into the "
               "bowl (inner radius 2, thickness 0.2, inside bottom at z = 0: the sphere falls 0.5 "
               "before touching either) as a distance field with simulate's default voxel (quick: "
               "5 times as large); total "
               "= kinetic + elastic + gravity (-F_g . U, 0 at the start) + contact (penalty) "
               "energy; the energy may not grow beyond " +
               shortNumber(kEnergyRoundoff) + " of weight x radius"},
          {"runs", runs}};
}

}  // namespace

SuiteOutput contactSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"contact", nlohmann::json::object(), nlohmann::json::array(), {}};
  const Log log = [&](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };
  const Sizes z = sizes(o.quick);
  const ScratchFolder scratch;

  const TriangleSurface fine = uvSphere(kCentre, kRadius, z.rings, z.segments);
  const std::string fineFile = writeObj(scratch.path() / "sphere.obj", fine);
  const Stopwatch meshing;
  Model model = sphereModel(fine, kEmbedCells, fineFile);
  const double meshSeconds = meshing.seconds();
  const double bodyDiagonal = meshBounds(model.mesh()).diagonal().norm();
  log("sphere: " + std::to_string(fine.triangles.size()) + " triangles, " +
      std::to_string(model.mesh().numElements()) + " elements (" + std::to_string(kEmbedCells) +
      " cells), meshed in " + shortNumber(meshSeconds) + " s");

  nlohmann::json embedding{
      {"setup", "uvSphere of radius 0.5 about (0, 0, 1) with " + std::to_string(z.rings) +
                    " rings and " + std::to_string(z.segments) +
                    " segments, sliced with 4 cells along its bounding box; MLS embedding of its "
                    "vertices (support 2); update = displacements(U) of all points for random "
                    "nonzero U (seed " +
                    std::to_string(kSeed) + "), median of " + std::to_string(kUpdateRepetitions) +
                    " after one warm-up"},
      {"triangles", fine.triangles.size()},
      {"vertices", fine.vertices.size()},
      {"elements", model.mesh().numElements()},
      {"cells", kEmbedCells},
      {"mesh_seconds", meshSeconds}};
  const double update = embeddingPart(model, fine, s, embedding, log);
  s.json["embedding"] = embedding;

  const TriangleSurface bowl =
      bowlSurface(kBowlCentre, kBowlInner, kBowlInner + kBowlThickness, z.bowlSegments);
  const std::string bowlFile = writeObj(scratch.path() / "bowl.obj", bowl);
  s.json["queries"] = queryPart(z, bodyDiagonal, bowl, s, log);
  s.json["step"] = stepPart(model, z, update, s, log);
  s.json["b9"] = b9Part(z, scratch.path(), bowlFile, bowl, s, log);
  s.json["quick"] = o.quick;
  return s;
}

}  // namespace polydg::bench
