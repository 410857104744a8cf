#include "cli/bench/suites.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mesh/primitives.h"
#include "polydg/mesh/surface.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"

namespace polydg::bench {

namespace {

namespace fs = std::filesystem;

/// Cells along the longest side of each real model's bounding box (--quick: kQuickCells).
constexpr int kModelCells = 16;
constexpr int kQuickCells = 8;

/// The clamp holds the boundary faces in the lowest kClampFraction of the model's height.
constexpr double kClampFraction = 0.05;

/// A real model of the suite: its name, file and up axis (the bunny is y-up, as scanned at
/// Stanford; the torus lies flat, z-up). The body stands on its base under gravity, as B2's
/// cube stands on a face: clamping the lowest part along another axis can hold the body by a
/// small tip (the bunny's z-min cap is an ear tip of area 0.011, from which the whole bunny
/// hangs).
struct SuiteModel {
  std::string name, path;
  int up = 2;
};

/// A real model as meshed and solved: its name, variant ("sliced" or "cut"), degree, and the
/// figures of its static solve.
struct ModelRun {
  std::string model, variant;
  int degree = 1;
  std::size_t elements = 0;
  StaticReport report;
};

/// The two cuts through a body with bounding box `box`: a plane across x at 3/4 of the width
/// (tilted, the plus side removed) and a finite square slit around the centre (half the width
/// and depth, tilted, both sides kept: the body stays one piece around it).
std::vector<CutRequest> cutsThrough(const Box3& box) {
  const Vec3 c = box.center(), e = box.sizes();
  CutRequest plane;
  const Vec3 normal = Vec3(1.0, 0.2, 0.1).normalized();
  plane.blade = Blade::plane(normal, normal.dot(c + Vec3(0.25 * e.x(), 0.0, 0.0)));
  plane.removeSide = 1;
  CutRequest slit;
  std::vector<Vec3> corners;
  for (const auto& [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const double dx = 0.25 * sx * e.x(), dy = 0.25 * sy * e.y();
    corners.push_back(c + Vec3(dx, dy, 0.1 * dx + 0.05 * dy));
  }
  slit.blade = Blade::fromPolygon(corners);
  return {plane, slit};
}

/// B2's material, gravity along -`up`, the lowest part of `box` along `up` clamped, CG with
/// the p-multigrid.
SolveOptions clampedUnderGravity(const Box3& box, int up, int degree) {
  SolveOptions so;
  so.discretization.method = Method::IP;
  so.discretization.basis.degree = degree;
  so.material = benchmarkB2Material();
  so.gravity = -Vec3::Unit(up);
  so.clamps.push_back(FaceSelector::below(
      Plane::make(Vec3::Unit(up), box.min()[up] + kClampFraction * box.sizes()[up])));
  so.solver = SolverKind::ConjugateGradient;
  return so;
}

/// B2's setup (clamped on x = 0, gravity) on the n x n x n unit cube, CG with the p-multigrid.
StaticReport cubeRun(int n, int degree) {
  Model cube(hexGridMesh(n, n, n, Box3(Vec3::Zero(), Vec3::Ones())));
  SolveOptions so;
  so.discretization.method = Method::IP;
  so.discretization.basis.degree = degree;
  so.material = benchmarkB2Material();
  so.gravity = Vec3(0, 0, -1);
  so.clamps.push_back(FaceSelector::inPlane(0, 0.0));
  so.solver = SolverKind::ConjugateGradient;
  return cube.solve(so).solve;
}

nlohmann::json rowJson(const std::string& model, const std::string& variant, int degree,
                       std::size_t elements, const StaticReport& r) {
  return {{"model", model},
          {"variant", variant},
          {"degree", degree},
          {"elements", elements},
          {"dofs", r.dofs},
          {"iterations", r.solver.iterations},
          {"residual", r.solver.residual},
          {"eta", r.eta},
          {"basis_fallbacks", r.basisFallbacks},
          {"t_setup", r.integrateSeconds + r.assembleSeconds + r.solver.factorSeconds},
          {"t_preconditioner", r.solver.factorSeconds},
          {"t_solve", r.solver.solveSeconds}};
}

}  // namespace

SuiteOutput multigridSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"multigrid", nlohmann::json::object(), nlohmann::json::array(), {}};
  s.json["rows"] = nlohmann::json::array();
  std::vector<SuiteModel> models;
  const fs::path bunny = fs::path(o.dataDir) / "models" / "bunny.off";
  if (fs::exists(bunny)) {
    models.push_back({"bunny", bunny.string(), 1});
  } else {
    const std::string note = bunny.string() + " not found: run scripts/get-models.sh " +
                             (fs::path(o.dataDir) / "models").string() + " to fetch it";
    s.json["missing"] = note;
    if (!quiet) std::cout << note << std::endl;
  }
  models.push_back({"torus", (fs::path(o.dataDir) / "torus.obj").string(), 2});
  const int cells = o.quick ? kQuickCells : kModelCells;
  SeriesSet ratios;
  for (const auto& [name, path, up] : models) {
    const TriangleSurface surface = readSurface(path);
    const Box3 box = bounds(surface);
    for (const char* variant : {"sliced", "cut"})
      for (int p = 1; p <= 2; ++p) {
        MeshOptions mo;
        mo.cells = cells;
        mo.dgChecks = false;
        MeshReport meshed;
        Model model = Model::fromSurface(surface, mo, meshed, path);
        if (std::string(variant) == "cut")
          for (const CutRequest& cut : cutsThrough(box))
            if (const OperationReport cr = model.cut(cut); !cr.check.passed)
              throw std::runtime_error(name + ": the " + cr.op +
                                       " failed its validation: " + cr.check.failure);
        const std::size_t elements = model.mesh().numElements();
        const StaticReport r = model.solve(clampedUnderGravity(box, up, p)).solve;
        // The unit cube of about as many elements.
        const int n =
            std::max(2, static_cast<int>(std::lround(std::cbrt(static_cast<double>(elements)))));
        const StaticReport cube = cubeRun(n, p);
        nlohmann::json row = rowJson(name, variant, p, elements, r);
        const double ratio = static_cast<double>(r.solver.iterations) /
                             static_cast<double>(std::max(1, cube.solver.iterations));
        row["up_axis"] = std::string(1, "xyz"[up]);
        row["cube_n"] = n;
        row["cube_dofs"] = cube.dofs;
        row["cube_iterations"] = cube.solver.iterations;
        row["iteration_ratio"] = ratio;
        s.rows.push_back(row);
        s.json["rows"].push_back(row);
        ratios.add(std::string(variant) + ", p = " + std::to_string(p), name == "bunny" ? 1.0 : 2.0,
                   ratio);
        if (!quiet)
          std::cout << name << " " << variant << " p=" << p << ": " << elements << " elements, "
                    << r.dofs << " DOFs, " << r.solver.iterations << " CG iterations (cube " << n
                    << "^3, " << cube.dofs << " DOFs: " << cube.solver.iterations << "; ratio "
                    << shortNumber(ratio) << "), eta " << shortNumber(r.eta) << ", fallbacks "
                    << r.basisFallbacks << ", setup "
                    << shortNumber(r.integrateSeconds + r.assembleSeconds + r.solver.factorSeconds)
                    << " s, solve " << shortNumber(r.solver.solveSeconds) << " s" << std::endl;
      }
  }
  s.plots.push_back({"multigrid.svg",
                     {"CG iterations on real models over the unit cube's (same degree and size)",
                      {"model", AxisScale::Linear, {"bunny", "torus"}},
                      {"iterations / cube's", AxisScale::Linear},
                      ratios.series()}});
  return s;
}

}  // namespace polydg::bench
