// The sfem suite (Zhang et al. 2017, section 5): the tet methods (physics/fem/) side by side
// with DG on the paper's meshes, boxes of cubes split into five tets:
//  1. Distortion under pressure: the unit cubic cantilever (5^3 cubes: 216 nodes, 625 tets;
//     E = 1, nu = 0.3; clamped at x = 0, pressure 1 on z = 1), nodes moved by up to alpha =
//     0 .. 0.4 of the spacing along each axis (seeded; nodes on the sides within them). Strain
//     energy and the tip's deflection (the largest |u| on x = 1) for L-FEM and LFS-FEM (in a linear
//     static solve C-FEM and CS-FEM are the same methods), and IP DG p = 1, 2 on the same tets,
//     against IP p = 3 on a 12^3 hex grid of the cube (the reference).
//  2. Distortion under large rotation: the paper's 405-tet beam (below, k = 1) falling under
//     gravity, distorted by alpha = 0 .. 0.4: node A's vertical displacement at 0.25 s and the
//     time of its first lowest point, per method, dt = 0.0025 for 0.5 s.
//  3. Volume under rotation: the 2 x 0.5 x 0.5 beam (18 x 4 x 4 cubes: 475 nodes, 1,440 tets),
//     clamped at x = 0, falling under gravity (E = 1e6, nu = 0.3, density 1000) for 2 s at
//     dt = 0.01: the largest relative volume change per method. Linear forces take the rotation
//     for a stretch and inflate the beam; warped ones do not.
//  4. Time per step (the paper's Table 1): the beam 0.9 x 0.3 x 0.3 m in 9k x 3k x 3k cubes
//     (k = 1..5: 405 to 50,625 tets), clamped, under gravity, C-FEM and CS-FEM: the mean wall
//     time of 10 backward Euler steps after 2, with assembly and solve apart; and IP DG p = 1
//     on a hex grid of the beam at about the same DOFs.
//  5. Speed against error on B1 (shared/BENCHMARKS.md, the accuracy suite's problem): the
//     relative L2 error against the solve's wall time for FEM and FS-FEM on 5-tet cubes (n = 4,
//     8, 16, 24) and IP p = 1, 2, 3 on hex grids.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "cli/bench/reference_error.h"
#include "cli/bench/suites.h"
#include "integrate/quadrature.h"
#include "mesh/primitives.h"
#include "model/tet_solve.h"
#include "physics/dynamics/dynamics.h"
#include "physics/fem/tet_dynamics.h"
#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/model.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg::bench {

namespace {

/// A box from the origin to `size` in cells[0] x cells[1] x cells[2] cubes of five tets (the
/// central tet and four corners, alternating with the cube's parity so that neighbours share
/// their faces' diagonals), oriented on the regular grid; then nodes moved by up to `alpha`
/// times the spacing along each axis that does not take them off the box's sides (uniform
/// random numbers from `seed`). A draw that inverts a tet (checkTetMesh) is drawn again from
/// the next seed; `seed` returns the one used.
TetMesh boxOfFiveTetCubes(const Vec3& size, const std::array<int, 3>& cells, double alpha,
                          unsigned& seed) {
  TetMesh mesh;
  const Vec3 h(size.x() / cells[0], size.y() / cells[1], size.z() / cells[2]);
  auto id = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + (cells[0] + 1) * (j + (cells[1] + 1) * k));
  };
  for (int k = 0; k <= cells[2]; ++k)
    for (int j = 0; j <= cells[1]; ++j)
      for (int i = 0; i <= cells[0]; ++i)
        mesh.vertices.emplace_back(i * h.x(), j * h.y(), k * h.z());
  // Corners by bits (x, y, z); an even cube cuts off corners 0, 3, 5, 6, an odd one 1, 2, 4, 7.
  static constexpr int kEven[5][4] = {
      {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}, {1, 2, 4, 7}};
  static constexpr int kOdd[5][4] = {
      {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}, {0, 3, 5, 6}};
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i) {
        const auto& split = (i + j + k) % 2 == 0 ? kEven : kOdd;
        for (const auto& tet : split) {
          std::array<std::uint32_t, 4> t;
          for (int c = 0; c < 4; ++c)
            t[c] = id(i + (tet[c] & 1), j + (tet[c] >> 1 & 1), k + (tet[c] >> 2));
          mesh.tets.push_back(t);
          if (sixVolume(mesh, mesh.tets.size() - 1) < 0)
            std::swap(mesh.tets.back()[2], mesh.tets.back()[3]);
        }
      }
  if (alpha == 0.0) return mesh;
  const std::vector<Vec3> regular = mesh.vertices;
  for (;; ++seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k <= cells[2]; ++k)
      for (int j = 0; j <= cells[1]; ++j)
        for (int i = 0; i <= cells[0]; ++i) {
          Vec3 shift(unit(random), unit(random), unit(random));
          // Along an axis only off the box's sides across it: nodes on a side move in its
          // plane, on an edge along it, corners not at all, so the box keeps its shape.
          const std::array<int, 3> index{i, j, k};
          for (int a = 0; a < 3; ++a)
            if (index[a] == 0 || index[a] == cells[a]) shift[a] = 0.0;
          mesh.vertices[id(i, j, k)] = regular[id(i, j, k)] + alpha * shift.cwiseProduct(h);
        }
    try {
      checkTetMesh(mesh);
      return mesh;
    } catch (const InputError&) {
      // an inverted tet: the next draw
    }
  }
}

constexpr double kDistortions[] = {0.0, 0.1, 0.2, 0.3, 0.4};

/// The pressure cantilever's solve options, for DG and the tet methods alike (solveOnTets
/// ignores the degree).
SolveOptions pressureOptions(int degree) {
  SolveOptions o;
  o.material = {1.0, 0.3, 1.0};
  o.discretization.basis.degree = degree;
  o.clamps = {FaceSelector::inPlane(0, 0.0)};
  o.tractions = {{FaceSelector::inPlane(2, 1.0), Vec3(0, 0, -1)}};
  return o;
}

/// Experiment 1: energy and tip deflection against distortion, per method.
void runPressure(const BenchOptions& b, SuiteOutput& s, const Log& log, SeriesSet& plot) {
  // The reference: IP p = 3 on a hex grid of the cube.
  const int referenceCells = b.quick ? 4 : 12;
  MeshOptions meshing;
  meshing.cells = referenceCells;
  MeshReport meshed;
  Model reference =
      Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3::Ones())), meshing, meshed);
  const Stopwatch referenceWatch;
  const SolveReport ref = reference.solve(pressureOptions(3));
  const double referenceEnergy = ref.solve.energy;
  log("pressure: reference IP p = 3 on " + std::to_string(referenceCells) + "^3 hexahedra (" +
      std::to_string(ref.solve.dofs) + " DOFs): energy " + shortNumber(referenceEnergy) +
      ", largest |u| " + shortNumber(ref.maxDisplacement) + " (" +
      shortNumber(referenceWatch.seconds()) + " s)");
  nlohmann::json rows = nlohmann::json::array();
  for (double alpha : kDistortions) {
    unsigned seed = 2017;
    const TetMesh mesh = boxOfFiveTetCubes(Vec3::Ones(), {5, 5, 5}, alpha, seed);
    auto record = [&](const std::string& method, double energy, double tip, std::size_t dofs,
                      double seconds) {
      const double error = std::abs(energy - referenceEnergy) / referenceEnergy;
      rows.push_back({{"alpha", alpha},
                      {"seed", seed},
                      {"method", method},
                      {"dofs", dofs},
                      {"energy", energy},
                      {"energy_error", error},
                      {"tip_deflection", tip},
                      {"seconds", seconds}});
      s.rows.push_back({{"benchmark", "sfem pressure"},
                        {"case", method},
                        {"alpha", alpha},
                        {"dofs", dofs},
                        {"energy", energy},
                        {"energy_error", error},
                        {"tip_deflection", tip},
                        {"seconds", seconds}});
      plot.add(method, alpha, error);
      log("pressure alpha " + shortNumber(alpha) + " " + method + ": energy " +
          shortNumber(energy) + " (error " + shortNumber(error) + "), tip " + shortNumber(tip));
    };
    for (TetMethod method : {TetMethod::Fem, TetMethod::FsFem}) {
      const Stopwatch watch;
      const TetSolveReport r = solveOnTets(mesh, method, pressureOptions(1));
      double tip = 0.0;
      for (std::size_t v = 0; v < mesh.numVertices(); ++v)
        if (mesh.vertices[v].x() == 1.0)
          tip = std::max(tip, r.displacement.segment<3>(3 * v).norm());
      record(method == TetMethod::Fem ? "L-FEM" : "LFS-FEM", r.energy, tip, r.dofs,
             watch.seconds());
    }
    for (int degree : {1, 2}) {
      const Stopwatch watch;
      Model dg(toPolyMesh(mesh));
      const SolveReport r = dg.solve(pressureOptions(degree));
      record("IP p=" + std::to_string(degree), r.solve.energy, r.maxDisplacement, r.solve.dofs,
             watch.seconds());
    }
  }
  s.json["pressure"] = {{"reference",
                         {{"method", "IP p=3"},
                          {"hex_cells", referenceCells},
                          {"dofs", ref.solve.dofs},
                          {"energy", referenceEnergy},
                          {"max_displacement", ref.maxDisplacement}}},
                        {"runs", rows}};
}

/// Experiment 3: the falling beam's largest volume change, per method.
void runRotation(const BenchOptions& b, SuiteOutput& s, const Log& log) {
  unsigned seed = 0;
  const TetMesh mesh = boxOfFiveTetCubes(
      Vec3(2.0, 0.5, 0.5), b.quick ? std::array{6, 2, 2} : std::array{18, 4, 4}, 0.0, seed);
  std::vector<std::uint32_t> clamped;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v)
    if (mesh.vertices[v].x() == 0.0) clamped.push_back(static_cast<std::uint32_t>(v));
  nlohmann::json rows = nlohmann::json::array();
  for (TetMethod method : {TetMethod::Fem, TetMethod::FsFem}) {
    const TetDiscretization d(mesh, method);
    for (bool corotational : {false, true}) {
      const std::string name = method == TetMethod::Fem ? (corotational ? "C-FEM" : "L-FEM")
                                                        : (corotational ? "CS-FEM" : "LFS-FEM");
      TetDynamicsOptions o;
      o.material = {1e6, 0.3, 1000.0};
      o.corotational = corotational;
      o.gravity = Vec3(0, 0, -9.81);
      o.clamped = clamped;
      TetDynamics beam(d, o);
      const double rest = beam.volume();
      double largest = 0.0, lowest = 0.0;
      const int steps = b.quick ? 50 : 200;
      const Stopwatch watch;
      for (int n = 0; n < steps; ++n) {
        beam.step(0.01);
        largest = std::max(largest, std::abs(beam.volume() / rest - 1.0));
        const Eigen::VectorXd u = beam.displacement();
        for (Eigen::Index i = 2; i < u.size(); i += 3) lowest = std::min(lowest, u[i]);
      }
      const double perStep = watch.seconds() / steps;
      rows.push_back({{"method", name},
                      {"tets", mesh.numTets()},
                      {"largest_volume_change", largest},
                      {"lowest_displacement", lowest},
                      {"seconds_per_step", perStep}});
      s.rows.push_back({{"benchmark", "sfem rotation"},
                        {"case", name},
                        {"largest_volume_change", largest},
                        {"lowest_displacement", lowest},
                        {"seconds", perStep}});
      log("rotation " + name + ": largest volume change " + shortNumber(largest) +
          ", lowest point " + shortNumber(lowest) + " m, " + shortNumber(perStep * 1e3) +
          " ms a step");
    }
  }
  s.json["rotation"] = rows;
}

/// The relative L2 error of nodal displacements u (node-major) on `mesh` against `exact`, the
/// linear interpolant integrated by each tet's rule exact for quadratics.
double tetL2Error(const TetMesh& mesh, const Eigen::VectorXd& u, const VectorField& exact) {
  double error = 0.0, norm = 0.0;
  std::vector<QuadraturePoint> rule;
  for (const auto& c : mesh.tets) {
    const Vec3& x0 = mesh.vertices[c[0]];
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = mesh.vertices[c[k + 1]] - x0;
    const Eigen::Matrix3d inverse = edges.inverse();
    rule.clear();
    appendTetrahedronRule(x0, mesh.vertices[c[1]], mesh.vertices[c[2]], mesh.vertices[c[3]], 2,
                          rule);
    for (const QuadraturePoint& q : rule) {
      const Vec3 xi = inverse * (q.point - x0);
      const Eigen::Vector4d shape(1.0 - xi.sum(), xi.x(), xi.y(), xi.z());
      Vec3 uh = Vec3::Zero();
      for (int k = 0; k < 4; ++k) uh += shape[k] * u.segment<3>(3 * c[k]);
      const Vec3 value = exact(q.point);
      error += q.weight * (uh - value).squaredNorm();
      norm += q.weight * value.squaredNorm();
    }
  }
  return std::sqrt(error / norm);
}

/// Experiment 5: L2 error against wall time, every method and degree, on B1.
void runSpeedAgainstError(const BenchOptions& b, SuiteOutput& s, const Log& log, SeriesSet& plot) {
  const ManufacturedProblem problem = benchmarkB1Problem();
  // The tet methods take B1's loads and boundary values; the exact solution is the DG solve's
  // own error measure, so the tets' error is measured here.
  SolveOptions onTets = manufacturedSolveOptions(problem, 1);
  onTets.exactDisplacement = {};
  onTets.exactGradient = {};
  nlohmann::json rows = nlohmann::json::array();
  auto record = [&](const std::string& method, int n, std::size_t dofs, double error,
                    double seconds) {
    rows.push_back(
        {{"method", method}, {"n", n}, {"dofs", dofs}, {"l2_error", error}, {"seconds", seconds}});
    s.rows.push_back({{"benchmark", "sfem speed against error"},
                      {"case", method},
                      {"n", n},
                      {"dofs", dofs},
                      {"l2_error", error},
                      {"seconds", seconds}});
    plot.add(method, seconds, error);
    log("speed against error " + method + " n = " + std::to_string(n) + ": " +
        std::to_string(dofs) + " DOFs, L2 error " + shortNumber(error) + ", " +
        shortNumber(seconds) + " s");
  };
  const std::vector<int> tetSizes =
      b.quick ? std::vector<int>{4, 8} : std::vector<int>{4, 8, 16, 24};
  for (TetMethod method : {TetMethod::Fem, TetMethod::FsFem})
    for (int n : tetSizes) {
      unsigned seed = 0;
      const TetMesh mesh = boxOfFiveTetCubes(Vec3::Ones(), {n, n, n}, 0.0, seed);
      const Stopwatch watch;  // the solve from the mesh: domains, loads, assembly, solve
      const TetSolveReport r = solveOnTets(mesh, method, onTets);
      const double seconds = watch.seconds();
      record(method == TetMethod::Fem ? "FEM" : "FS-FEM", n, r.dofs,
             tetL2Error(mesh, r.displacement, problem.displacement), seconds);
    }
  const std::vector<std::vector<int>> hexSizes =
      b.quick ? std::vector<std::vector<int>>{{2, 4}, {2}, {2}}
              : std::vector<std::vector<int>>{{4, 8, 16, 24}, {2, 4, 8, 12}, {2, 4, 6, 8}};
  for (int degree = 1; degree <= 3; ++degree)
    for (int n : hexSizes[static_cast<std::size_t>(degree - 1)]) {
      MeshOptions meshing;
      meshing.cells = n;
      MeshReport meshed;
      Model model =
          Model::fromSurface(boxSurface(Box3(Vec3::Zero(), Vec3::Ones())), meshing, meshed);
      const Stopwatch watch;  // the solve from the mesh: moments, basis, assembly, solve
      const SolveReport r = model.solve(manufacturedSolveOptions(problem, degree));
      const double seconds = watch.seconds();
      record("IP p=" + std::to_string(degree), n, r.solve.dofs, r.error->l2 / r.error->l2Exact,
             seconds);
    }
  s.json["speed_against_error"] = rows;
}

/// The paper's beam under gravity at size k (its Table 1: 9k x 3k x 3k cubes of five tets, 0.9
/// x 0.3 x 0.3 m), clamped at x = 0, E = 1e6, nu = 0.3, density 1000, distorted by `alpha`.
struct GravityBeam {
  TetMesh mesh;
  std::vector<std::uint32_t> clamped;
  std::uint32_t tipNode = 0;  ///< node A: the free end's lowest corner on y = 0
  unsigned seed = 0;
};

GravityBeam gravityBeam(int k, double alpha) {
  GravityBeam b;
  b.seed = 42;
  b.mesh = boxOfFiveTetCubes(Vec3(0.9, 0.3, 0.3), {9 * k, 3 * k, 3 * k}, alpha, b.seed);
  for (std::size_t v = 0; v < b.mesh.numVertices(); ++v) {
    const Vec3& p = b.mesh.vertices[v];
    if (p.x() == 0.0) b.clamped.push_back(static_cast<std::uint32_t>(v));
    if (p.x() == 0.9 && p.y() == 0.0 && p.z() == 0.0) b.tipNode = static_cast<std::uint32_t>(v);
  }
  return b;
}

TetDynamicsOptions beamDynamics(const GravityBeam& b, bool corotational) {
  TetDynamicsOptions o;
  o.material = {1e6, 0.3, 1000.0};
  o.corotational = corotational;
  o.gravity = Vec3(0, 0, -9.81);
  o.clamped = b.clamped;
  return o;
}

const char* methodName(TetMethod method, bool corotational) {
  if (method == TetMethod::Fem) return corotational ? "C-FEM" : "L-FEM";
  return corotational ? "CS-FEM" : "LFS-FEM";
}

/// Experiment 2: node A of the 405-tet beam under gravity, distorted by alpha = 0 .. 0.4: its
/// vertical displacement at t = 0.25 s and the time of its first lowest point (half the first
/// period), per method; the shift of that time against the regular mesh's is the frequency
/// shift the paper plots.
void runDistortedBeam(const BenchOptions& b, SuiteOutput& s, const Log& log) {
  nlohmann::json rows = nlohmann::json::array();
  const double dt = 0.0025;
  const int steps = b.quick ? 100 : 200;  // 0.25 s, or 0.5 s
  std::map<std::string, double> regular;  // each method's half period at alpha = 0
  const std::vector<double> alphas =
      b.quick ? std::vector<double>{0.0, 0.4}
              : std::vector<double>(std::begin(kDistortions), std::end(kDistortions));
  for (double alpha : alphas) {
    const GravityBeam beam = gravityBeam(1, alpha);
    for (TetMethod method : {TetMethod::Fem, TetMethod::FsFem}) {
      const TetDiscretization d(beam.mesh, method);
      for (bool corotational : {false, true}) {
        TetDynamics body(d, beamDynamics(beam, corotational));
        double atQuarter = 0.0, lowest = 0.0, lowestTime = 0.0;
        bool rising = false;
        for (int n = 1; n <= steps; ++n) {
          body.step(dt);
          const double z = body.displacement()[3 * beam.tipNode + 2];
          if (n == 100) atQuarter = z;
          if (!rising && z < lowest) {
            lowest = z;
            lowestTime = n * dt;
          } else if (z > lowest) {
            rising = true;  // past the first lowest point
          }
        }
        const std::string name = methodName(method, corotational);
        if (alpha == 0.0) regular[name] = lowestTime;
        const double shift = regular[name] > 0.0 ? lowestTime / regular[name] - 1.0 : 0.0;
        rows.push_back({{"alpha", alpha},
                        {"seed", beam.seed},
                        {"method", name},
                        {"uz_A_at_0.25s", atQuarter},
                        {"first_lowest_uz_A", lowest},
                        {"first_lowest_time", lowestTime},
                        {"half_period_shift", shift}});
        s.rows.push_back({{"benchmark", "sfem distorted beam"},
                          {"case", name},
                          {"alpha", alpha},
                          {"uz_A", atQuarter},
                          {"first_lowest_time", lowestTime}});
        log("distorted beam alpha " + shortNumber(alpha) + " " + name + ": u_z(A) at 0.25 s " +
            shortNumber(atQuarter) + " m, first lowest " + shortNumber(lowest) + " m at " +
            shortNumber(lowestTime) + " s (shift " + shortNumber(shift) + ")");
      }
    }
  }
  s.json["distorted_beam"] = rows;
}

/// The beam of experiment 4 with DG at about `dofs` DOFs: IP p = 1, corotated, backward Euler,
/// on an n x m x m hex grid (12 DOFs an element; m from cubic cells, n then from the DOFs), the
/// tet beam's material, clamp and gravity; wall time per step as for the tets.
nlohmann::json dgStepRow(std::size_t dofs, const Log& log, SeriesSet& plot) {
  const int m = std::max(1, static_cast<int>(std::lround(std::cbrt(dofs / 36.0))));
  const int n = std::max(1, static_cast<int>(std::lround(dofs / (12.0 * m * m))));
  const PolyMesh hex = hexGridMesh(n, m, m, Box3(Vec3::Zero(), Vec3(0.9, 0.3, 0.3)));
  MomentCache moments(hex, 2);
  moments.update();
  DynamicsOptions o;
  o.material = {1e6, 0.3, 1000.0};
  o.corotational = true;
  DynamicSolver body(hex, moments, {{FaceSelector::inPlane(0, 0.0)}, {}, Vec3(0, 0, -9.81)}, o);
  for (int n = 0; n < 2; ++n) body.step(0.01);
  const int steps = 10;
  double assemble = 0.0, solve = 0.0;
  int iterations = 0;
  const Stopwatch watch;
  for (int n = 0; n < steps; ++n) {
    const StepReport r = body.step(0.01);
    assemble += r.rotationSeconds + r.assemblySeconds;
    solve += r.solveSeconds;
    iterations += r.iterations;
  }
  const double perStep = watch.seconds() / steps;
  plot.add("IP p = 1 (hexahedra)", static_cast<double>(body.dofs()) / 3.0, perStep * 1e3);
  log("time per step IP p = 1, " + std::to_string(hex.numElements()) + " hexahedra (" +
      std::to_string(body.dofs()) + " DOFs): " + shortNumber(perStep * 1e3) + " ms (assembly " +
      shortNumber(assemble / steps * 1e3) + ", solve " + shortNumber(solve / steps * 1e3) + ", " +
      shortNumber(static_cast<double>(iterations) / steps) + " CG iterations)");
  return {{"method", "IP p = 1"},
          {"elements", hex.numElements()},
          {"dofs", body.dofs()},
          {"seconds_per_step", perStep},
          {"assemble_seconds", assemble / steps},
          {"solve_seconds", solve / steps}};
}

/// Experiment 4 (the paper's Table 1): wall time per step against the number of tets, and DG
/// at about the same DOFs (plotted at DOFs / 3, the nodes the tets would need).
void runTimePerStep(const BenchOptions& b, SuiteOutput& s, const Log& log, SeriesSet& plot) {
  nlohmann::json rows = nlohmann::json::array();
  for (int k = 1; k <= (b.quick ? 2 : 5); ++k) {
    const GravityBeam beam = gravityBeam(k, 0.0);
    for (TetMethod method : {TetMethod::Fem, TetMethod::FsFem}) {
      const TetDiscretization d(beam.mesh, method);
      TetDynamics body(d, beamDynamics(beam, true));
      for (int n = 0; n < 2; ++n) body.step(0.01);  // warm-up: the solver's first analysis
      const int steps = 10;
      double assemble = 0.0, solve = 0.0;
      int iterations = 0;
      const Stopwatch watch;
      for (int n = 0; n < steps; ++n) {
        iterations += body.step(0.01).iterations;
        assemble += body.assembleSeconds();
        solve += body.solveSeconds();
      }
      const double perStep = watch.seconds() / steps;
      const std::string name = methodName(method, true);
      rows.push_back({{"method", name},
                      {"nodes", beam.mesh.numVertices()},
                      {"tets", beam.mesh.numTets()},
                      {"domains", d.domains().size()},
                      {"seconds_per_step", perStep},
                      {"assemble_seconds", assemble / steps},
                      {"solve_seconds", solve / steps},
                      {"cg_iterations", static_cast<double>(iterations) / steps}});
      s.rows.push_back({{"benchmark", "sfem time per step"},
                        {"case", name},
                        {"tets", beam.mesh.numTets()},
                        {"seconds", perStep}});
      plot.add(name, static_cast<double>(beam.mesh.numVertices()), perStep * 1e3);
      log("time per step " + name + ", " + std::to_string(beam.mesh.numTets()) +
          " tets: " + shortNumber(perStep * 1e3) + " ms (assembly " +
          shortNumber(assemble / steps * 1e3) + ", solve " + shortNumber(solve / steps * 1e3) +
          ", " + shortNumber(static_cast<double>(iterations) / steps) + " CG iterations)");
    }
    nlohmann::json dg = dgStepRow(3 * beam.mesh.numVertices(), log, plot);
    s.rows.push_back({{"benchmark", "sfem time per step"},
                      {"case", "IP p = 1"},
                      {"dofs", dg["dofs"]},
                      {"seconds", dg["seconds_per_step"]}});
    rows.push_back(std::move(dg));
  }
  s.json["time_per_step"] = rows;
}

}  // namespace

SuiteOutput sfemSuite(const BenchOptions& options, bool quiet) {
  SuiteOutput s;
  s.name = "sfem";
  const Log log = [quiet](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };
  SeriesSet errors, speed, steps;
  runPressure(options, s, log, errors);
  runRotation(options, s, log);
  runDistortedBeam(options, s, log);
  runTimePerStep(options, s, log, steps);
  runSpeedAgainstError(options, s, log, speed);
  s.plots.push_back({"sfem_pressure.svg",
                     {"Cubic cantilever under pressure: strain energy error against distortion",
                      {"distortion alpha", AxisScale::Linear},
                      {"|E - E_ref| / E_ref", AxisScale::Log},
                      errors.series()}});
  s.plots.push_back({"sfem_time_per_step.svg",
                     {"Corotated beam under gravity: wall time per backward Euler step",
                      {"nodes (DG: DOFs / 3)", AxisScale::Log},
                      {"ms per step", AxisScale::Log},
                      steps.series()}});
  s.plots.push_back({"sfem_speed.svg",
                     {"Sine solution on the unit cube: L2 error against wall time",
                      {"wall time of the solve [s]", AxisScale::Log},
                      {"relative L2 error", AxisScale::Log},
                      speed.series()}});
  return s;
}

}  // namespace polydg::bench
