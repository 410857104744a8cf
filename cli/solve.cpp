// polydg solve: static linear elasticity on a simulation mesh (VTU) with the DG methods
// (polydg bench is in bench.cpp).
//
// Sample runs:
//   polydg solve beam.vtu -o beam_out.vtu --method ip --degree 2 --E 1000 --nu 0.3
//       --clamp x=0 --traction x=10:0,0,-1 --report solve.json   (one line)
#include <chrono>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/json_reports.h"
#include "cli/report.h"
#include "polydg/mesh/validate.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/post_process.h"
#include "polydg/physics/static_solver.h"

namespace polydg::cli {

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// "x=0.5": a plane selector.
struct PlaneArg {
  int axis = 0;
  double value = 0.0;
};
/// "x=10:0,0,-1": a plane and a traction vector.
struct TractionArg {
  PlaneArg plane;
  Vec3 traction = Vec3::Zero();
};

std::string parsePlane(const std::string& text, PlaneArg& out) {
  const auto eq = text.find('=');
  if (eq != 1 || text.size() < 3) return "expected AXIS=VALUE with AXIS one of x, y, z";
  const char a = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  if (a < 'x' || a > 'z') return "the axis must be x, y or z";
  out.axis = a - 'x';
  try {
    std::size_t used = 0;
    out.value = std::stod(text.substr(2), &used);
    if (used != text.size() - 2) return "the plane's value is not a number";
  } catch (const std::exception&) {
    return "the plane's value is not a number";
  }
  return {};
}

std::string parseVector(const std::string& text, Vec3& out) {
  std::stringstream ss(text);
  std::string item;
  int k = 0;
  while (std::getline(ss, item, ',')) {
    if (k == 3) return "expected three comma-separated numbers";
    try {
      std::size_t used = 0;
      out[k++] = std::stod(item, &used);
      if (used != item.size()) return "expected three comma-separated numbers";
    } catch (const std::exception&) {
      return "expected three comma-separated numbers";
    }
  }
  return k == 3 ? std::string() : "expected three comma-separated numbers";
}

std::string parseTraction(const std::string& text, TractionArg& out) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) return "expected AXIS=VALUE:TX,TY,TZ";
  if (auto e = parsePlane(text.substr(0, colon), out.plane); !e.empty()) return e;
  return parseVector(text.substr(colon + 1), out.traction);
}

struct SolveOptions {
  std::string input;
  std::string output;
  std::string report;
  Method method = Method::IP;
  int degree = 2;
  Material material;
  Vec3 gravity = Vec3::Zero();
  std::vector<PlaneArg> clamps;
  std::vector<TractionArg> tractions;
  SolverKind solver = SolverKind::Auto;
  PenaltyRule penalty = PenaltyRule::TraceBound;
  double eta = 0.0;  ///< > 0: fixed penalty
};

const std::map<std::string, Method> kMethods{{"ip", Method::IP}, {"bz", Method::BZ}};
const std::map<std::string, SolverKind> kSolvers{{"auto", SolverKind::Auto},
                                                 {"cholesky", SolverKind::Cholesky},
                                                 {"cg", SolverKind::ConjugateGradient}};
const std::map<std::string, PenaltyRule> kPenalties{{"bound", PenaltyRule::TraceBound},
                                                    {"doubling", PenaltyRule::Doubling}};

// The overload below would hide the shared ones (cli/json_reports.h) from this namespace.
using cli::toString;
std::string toString(PenaltyRule r) {
  switch (r) {
    case PenaltyRule::TraceBound: return "bound";
    case PenaltyRule::Doubling: return "doubling";
    case PenaltyRule::Fixed: break;
  }
  return "fixed";
}

nlohmann::json reportJson(const StaticReport& r) {
  const double dofs = static_cast<double>(r.dofs);
  return {{"elements", r.elements},
          {"dofs", r.dofs},
          {"nonzeros", r.nonzeros},
          {"sparsity", dofs > 0 ? static_cast<double>(r.nonzeros) / (dofs * dofs) : 0.0},
          {"eta", r.eta},
          {"eta_threshold", r.etaThreshold},
          {"penalty_attempts", r.penaltyAttempts},
          {"dirichlet_faces", r.dirichletFaces},
          {"traction_faces", r.tractionFaces},
          {"basis_fallbacks", r.basisFallbacks},
          {"timings_s",
           {{"integrate", r.integrateSeconds},
            {"assemble", r.assembleSeconds},
            {"solve", r.solveSeconds},
            {"factorize", r.solver.factorSeconds}}},
          {"solver",
           {{"kind", toString(r.solver.used)},
            {"preconditioner", r.solver.used != SolverKind::ConjugateGradient ? "none"
                               : r.solver.preconditioner == CgPreconditioner::PMultigrid
                                   ? "p-multigrid"
                                   : "block-jacobi"},
            {"success", r.solver.success},
            {"iterations", r.solver.iterations},
            {"residual", r.solver.residual}}},
          {"energy", r.energy}};
}

template <class Tag>
VtuArray<Tag> vectorArray(const std::string& name, const IndexedData<Tag, Vec3>& data) {
  VtuArray<Tag> a{name, 3, {}};
  a.values.reserve(3 * data.size());
  for (const Vec3& v : data) a.values.insert(a.values.end(), {v.x(), v.y(), v.z()});
  return a;
}

void runSolve(const SolveOptions& o, const CommonOptions& common) {
  if (!isVolumeMeshPath(o.input))
    throw UserError(o.input +
                    ": solve reads simulation meshes (.vtu); make one with 'polydg mesh'");
  requireDistinct(o.output, o.input);
  if (!o.report.empty()) requireDistinct(o.report, o.input);
  try {
    o.material.check();
  } catch (const std::invalid_argument& e) {
    throw UserError(std::string(e.what()) + "; check --E, --nu and --density");
  }
  const auto t0 = Clock::now();
  const PolyMesh mesh = readVtu(o.input);
  const double readSeconds = secondsSince(t0);
  const ValidationReport valid = validate(mesh);
  if (!valid.passed)
    throw UserError(
        o.input + ": the mesh is invalid (" +
        (valid.messages.empty() ? std::string("see 'polydg check'") : valid.messages.front()) +
        "); run 'polydg check' for details");
  if (o.clamps.empty())
    throw UserError("nothing holds the body: add at least one --clamp AXIS=VALUE");

  LoadCase loads;
  for (const PlaneArg& c : o.clamps)
    loads.dirichlet.push_back({FaceSelector::plane(c.axis, c.value), {}});
  for (const TractionArg& t : o.tractions)
    loads.tractions.push_back({FaceSelector::plane(t.plane.axis, t.plane.value), t.traction});
  loads.gravity = o.gravity;

  StaticOptions so;
  so.discretization.method = o.method;
  so.discretization.basis.degree = o.degree;
  so.discretization.penalty.rule = o.eta > 0.0 ? PenaltyRule::Fixed : o.penalty;
  if (o.eta > 0.0) so.discretization.penalty.eta = o.eta;
  so.solver.kind = o.solver;

  StaticSolver solver(mesh, o.material, so);
  solver.integrate();
  solver.assemble(loads);
  if (solver.report().dirichletFaces == 0)
    throw UserError(
        "no boundary face lies in a --clamp plane; check the planes against the "
        "mesh's bounding box ('polydg info')");
  const Eigen::VectorXd& u = solver.solve();
  const StaticReport& report = solver.report();

  const auto tw = Clock::now();
  const CornerValues corners = cornerDisplacements(mesh, solver.basis(), u);
  const ElementFields fields = elementFields(mesh, solver.basis(), solver.moments(), u, o.material);
  std::vector<CellArray> cells{vectorArray("mean_displacement", fields.meanDisplacement),
                               CellArray{"von_mises", 1, fields.vonMises.raw()},
                               CellArray{"largest_jump", 1, fields.largestJump.raw()}};
  writeVtu(mesh, o.output, {}, cells, {}, {displacementPointData(corners)});
  const double writeSeconds = secondsSince(tw);

  const double maxDisplacement = corners.largestNorm();
  double maxJump = 0.0, maxVonMises = 0.0;
  for (double j : fields.largestJump) maxJump = std::max(maxJump, j);
  for (double s : fields.vonMises) maxVonMises = std::max(maxVonMises, s);

  if (!o.report.empty()) {
    nlohmann::json j{{"command", "solve"},
                     {"input", o.input},
                     {"output", o.output},
                     {"method", toString(o.method)},
                     {"degree", o.degree},
                     {"material",
                      {{"E", o.material.youngsModulus},
                       {"nu", o.material.poissonRatio},
                       {"density", o.material.density}}},
                     {"penalty_rule", toString(so.discretization.penalty.rule)},
                     {"max_displacement", maxDisplacement},
                     {"max_von_mises", maxVonMises},
                     {"max_jump", maxJump}};
    j.update(reportJson(report));
    j["timings_s"]["read"] = readSeconds;
    j["timings_s"]["write"] = writeSeconds;
    writeReport(o.report, j);
  }
  if (!common.quiet) {
    std::cout << o.input << ": " << toString(o.method) << " p=" << o.degree << ", " << report.dofs
              << " DOFs, " << report.nonzeros << " nonzeros, eta " << report.eta << ", "
              << toString(report.solver.used) << " (residual " << report.solver.residual
              << (report.solver.iterations
                      ? ", " + std::to_string(report.solver.iterations) + " iterations"
                      : std::string())
              << ")\n  integrate " << report.integrateSeconds << " s, assemble "
              << report.assembleSeconds << " s, solve " << report.solveSeconds << " s; max |u| "
              << maxDisplacement << ", energy " << report.energy << '\n'
              << "  wrote " << o.output << '\n';
  }
}

}  // namespace

void addSolveCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<SolveOptions>();
  CLI::App* cmd = app.add_subcommand(
      "solve", "Static linear elasticity on a simulation mesh with DG (IP or BZ)");
  cmd->add_option("mesh", o->input, "simulation mesh (.vtu)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "output mesh with displacement and stress (.vtu)")
      ->required();
  cmd->add_option("--method", o->method, "DG method: ip (interior penalty) or bz")
      ->transform(CLI::CheckedTransformer(kMethods, CLI::ignore_case))
      ->capture_default_str();
  cmd->add_option("--degree", o->degree, "polynomial degree of the basis")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_option("--E", o->material.youngsModulus, "Young's modulus")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--nu", o->material.poissonRatio, "Poisson's ratio, in (-1, 0.5)")
      ->capture_default_str();
  cmd->add_option("--density", o->material.density, "mass density (with --gravity)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option_function<std::string>(
         "--gravity",
         [o](const std::string& s) {
           if (auto e = parseVector(s, o->gravity); !e.empty())
             throw CLI::ValidationError("--gravity", e);
         },
         "gravitational acceleration GX,GY,GZ")
      ->type_name("GX,GY,GZ");
  cmd->add_option_function<std::vector<std::string>>(
         "--clamp",
         [o](const std::vector<std::string>& v) {
           for (const std::string& s : v) {
             PlaneArg p;
             if (auto e = parsePlane(s, p); !e.empty()) throw CLI::ValidationError("--clamp", e);
             o->clamps.push_back(p);
           }
         },
         "clamp (u = 0, weakly) the boundary faces in the plane AXIS=VALUE; repeatable")
      ->type_name("AXIS=VALUE");
  cmd->add_option_function<std::vector<std::string>>(
         "--traction",
         [o](const std::vector<std::string>& v) {
           for (const std::string& s : v) {
             TractionArg t;
             if (auto e = parseTraction(s, t); !e.empty())
               throw CLI::ValidationError("--traction", e);
             o->tractions.push_back(t);
           }
         },
         "traction (force per area) on the boundary faces in a plane; repeatable")
      ->type_name("AXIS=VALUE:TX,TY,TZ");
  cmd->add_option("--solver", o->solver, "linear solver: auto, cholesky or cg")
      ->transform(CLI::CheckedTransformer(kSolvers, CLI::ignore_case));
  cmd->add_option("--penalty", o->penalty,
                  "penalty choice: bound (guaranteed SPD, default) or doubling (the paper's)")
      ->transform(CLI::CheckedTransformer(kPenalties, CLI::ignore_case));
  cmd->add_option("--eta", o->eta, "a fixed global penalty instead")->check(CLI::PositiveNumber);
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->callback([o, &common, &exitCode] {
    runSolve(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
