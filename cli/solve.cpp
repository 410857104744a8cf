// polydg solve: static linear elasticity on a simulation mesh (VTU) with the DG methods:
// Model::solve(), then the mesh with the solution written.
//
// Sample runs:
//   polydg solve beam.vtu -o beam_out.vtu --method ip --degree 2 --E 1000 --nu 0.3
//       --clamp x=0 --traction x=10:0,0,-1 --report solve.json   (one line)
//   polydg solve scan.vtu -o out.vtu --clamp-below 0,0,1,0.1 --gravity 0,0,-9.81
//   polydg solve beam.vtu -o out.vtu --clamp x=0 --gravity 0,0,-1 --surface deformed.vtp
//       (the surface the mesh was sliced from, carried by the MLS embedding; --embed FILE for
//       another)
//   polydg solve bar.vtu -o bar_adapted.vtu --clamp x=0 --traction x=9:0,0,-1 --adapt
//       --target-error 0.05 --max-dofs 200000   (solve, estimate, mark, refine; one line)
//   polydg solve beam.msh -o beam_out.vtu --method fs-fem --clamp x=0 --gravity 0,0,-9.81
//       (a tet mesh from Gmsh, TetGen's .ele or a VTU of tets, by the face-based smoothed FEM)
#include <filesystem>
#include <iostream>
#include <optional>

#include "cli/commands.h"
#include "cli/options.h"
#include "mesh/vtp_io.h"
#include "model/files.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/mesh/vtu_io.h"
#include "polydg/model/names.h"
#include "polydg/model/report_json.h"
#include "util/stopwatch.h"

namespace polydg::cli {

namespace {

struct SolveCommandOptions {
  std::string input, output, report;
  std::string method = "ip";             ///< --method: a DG method (methodNames) or a tet method
  std::vector<std::string> dgOnlyGiven;  ///< DG options given with a tet method
  std::string surfaceOutput, embed;      ///< --surface, --embed
  bool adapt = false;                    ///< --adapt
  AdaptOptions adaptOptions;
  SolveOptions solve = [] {
    SolveOptions s;
    s.discretization.basis.degree = 2;  // the command's own default; pipelines, scenes, Python
    return s;                           // and the library take the basis's (1)
  }();
};

/// What every solve needs before it reads: a .vtu output that is not the input (nor is the
/// report), and something that holds the body.
void checkOutputsAndClamps(const SolveCommandOptions& o) {
  if (!isVolumeMeshPath(o.output)) throw InputError(o.output + ": the output must be a .vtu file");
  requireOutput(o.output, {o.input});
  if (!o.report.empty()) requireOutput(o.report, {o.input});
  if (o.solve.clamps.empty())
    throw InputError(
        "nothing holds the body: add at least one --clamp, --clamp-plane, "
        "--clamp-below or --clamp-box");
}

/// --method fem|fs-fem: the DG-only options refused, the input a tet mesh.
void refuseForTets(const SolveCommandOptions& o) {
  if (!o.dgOnlyGiven.empty())
    throw InputError(o.dgOnlyGiven.front() +
                     " is an option of the DG methods (ip, bz), not of "
                     "--method " +
                     o.method + "; leave it out");
  if (!isVolumeMeshPath(o.input) && !isTetMeshFile(o.input))
    throw InputError(o.input + ": --method " + o.method +
                     " reads tet meshes (.vtu of tets, TetGen .ele, Gmsh .msh)");
}

void run(const SolveCommandOptions& o, const CommonOptions& common) {
  const std::optional<TetMethod> tets = parseName(tetMethodNames(), o.method);
  if (tets) {
    refuseForTets(o);
  } else if (!isVolumeMeshPath(o.input)) {
    throw InputError(o.input +
                     ": solve reads simulation meshes (.vtu); make one with 'polydg mesh'");
  }
  checkOutputsAndClamps(o);
  if (!o.embed.empty() && o.surfaceOutput.empty())
    throw InputError("--embed names the surface --surface writes: add --surface OUT.vtp");
  if (!o.surfaceOutput.empty()) {
    if (std::filesystem::path(o.surfaceOutput).extension() != ".vtp")
      throw InputError(o.surfaceOutput + ": the deformed surface is written as a .vtp file");
    requireOutput(o.surfaceOutput, {o.input, o.embed});
  }
  ReadReport read;
  Model model = Model::read(o.input, &read);
  SolveOptions options = o.solve;
  if (o.adapt) options.adapt = o.adaptOptions;
  if (tets) {
    options.tetMethod = tets;
    options.discretization = DiscretizationOptions{};  // the command's degree 2 is DG's
  }
  const SolveReport r = model.solve(options);
  for (const std::string& w : r.warnings) std::cerr << "polydg: warning: " << w << '\n';
  const WriteReport written = model.write(o.output);
  // The deformed embedded surface (physics/contact/embedding.h), written atomically.
  nlohmann::json surfaceJson;
  if (!o.surfaceOutput.empty()) {
    const Stopwatch watch;
    const EmbeddedSurface e = model.embedSurface(o.embed, o.solve.discretization.basis.degree);
    const Eigen::Matrix<double, Eigen::Dynamic, 3> u =
        e.embedding->displacements(model.solution()->coefficients);
    std::vector<Vec3> deformed(e.surface.vertices.size());
    std::vector<double> values(3 * deformed.size());
    for (std::size_t p = 0; p < deformed.size(); ++p) {
      deformed[p] = e.surface.vertices[p] + u.row(static_cast<Eigen::Index>(p)).transpose();
      for (int k = 0; k < 3; ++k)
        values[3 * p + static_cast<std::size_t>(k)] = u(static_cast<Eigen::Index>(p), k);
    }
    try {
      writeVtp(o.surfaceOutput, deformed, e.surface.triangles,
               {SurfacePointArray{"displacement", 3, values}});
    } catch (const std::runtime_error& err) {
      throw InputError(err.what());
    }
    surfaceJson = {{"surface", e.file},
                   {"output", o.surfaceOutput},
                   {"points", e.surface.vertices.size()},
                   {"triangles", e.surface.triangles.size()},
                   {"outside", e.embedding->outside()},
                   {"weight_nonzeros", e.embedding->weightNonzeros()},
                   {"max_displacement", u.rows() ? u.rowwise().norm().maxCoeff() : 0.0},
                   {"setup_seconds", e.embedding->setupSeconds()},
                   {"seconds", watch.seconds()}};
  }
  if (!o.report.empty()) {
    nlohmann::json j{{"command", "solve"}, {"input", o.input}, {"output", o.output}};
    j.update(toJson(r));
    j["embedded_surface"] = surfaceJson;
    j["timings_s"]["read"] = read.seconds;
    j["timings_s"]["write"] = written.seconds;
    writeJsonFile(o.report, j);
  }
  if (!common.quiet) {
    const StaticReport& s = r.solve;
    if (r.tets)
      std::cout << o.input << ": " << o.method << ", " << r.tets->tets << " tets, " << s.dofs
                << " DOFs (" << r.tets->heldNodes << " nodes held), ";
    else
      std::cout << o.input << ": " << toString(o.solve.discretization.method)
                << " p=" << o.solve.discretization.basis.degree << ", " << s.dofs << " DOFs, "
                << s.nonzeros << " nonzeros, eta " << s.eta << ", ";
    std::cout << toString(s.solver.used) << " (residual " << s.solver.residual
              << (s.solver.iterations ? ", " + std::to_string(s.solver.iterations) + " iterations"
                                      : std::string())
              << ")\n  integrate " << s.integrateSeconds << " s, assemble " << s.assembleSeconds
              << " s, solve " << s.solveSeconds << " s; max |u| " << r.maxDisplacement
              << ", energy " << s.energy << '\n'
              << "  wrote " << o.output << '\n';
    for (std::size_t i = 0; i < r.rounds.size(); ++i) {
      const AdaptRound& a = r.rounds[i];
      std::cout << "  round " << i << ": " << a.elements << " elements, " << a.dofs << " DOFs";
      if (o.adaptOptions.criterion == AdaptCriterion::Error)
        std::cout << ", estimate " << a.estimate << " (" << a.estimate / a.energyNorm
                  << " of the energy norm)";
      else
        std::cout << ", largest principal stress " << a.largestStress;
      if (a.marked) std::cout << "; refined " << a.marked;
      if (!a.stop.empty()) std::cout << "; stopped: " << a.stop;
      std::cout << '\n';
    }
    if (!surfaceJson.is_null())
      std::cout << "  wrote " << o.surfaceOutput << " (the deformed "
                << surfaceJson["surface"].get<std::string>() << ", "
                << surfaceJson["points"].get<std::size_t>() << " points, embedding "
                << surfaceJson["setup_seconds"].get<double>() << " s)\n";
  }
}

}  // namespace

void addSolveCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<SolveCommandOptions>();
  SolveOptions& s = o->solve;
  CLI::App* cmd = app.add_subcommand(
      "solve",
      "Static linear elasticity on a simulation mesh with DG (IP or BZ), or on a tet mesh with "
      "linear FEM or FS-FEM");
  cmd->add_option("mesh", o->input,
                  "simulation mesh (.vtu); for --method fem or fs-fem a tet mesh (.vtu, .ele, "
                  ".msh)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output, "output mesh with displacement and stress (.vtu)")
      ->required();
  DiscretizationOptions& d = s.discretization;
  std::vector<std::string> methods;
  for (const auto& [name, method] : methodNames()) methods.push_back(name);
  for (const auto& [name, method] : tetMethodNames()) methods.push_back(name);
  cmd->add_option("--method", o->method,
                  "the method: DG on any simulation mesh (ip: interior penalty, bz), or on a tet "
                  "mesh (.vtu of tets, TetGen .ele, Gmsh .msh) linear FEM (fem) or the "
                  "face-based smoothed FEM (fs-fem)")
      ->check(CLI::IsMember(methods))
      ->capture_default_str();
  addChoice(*cmd, "--bz-penalty", d.bzPenalty, bzPenaltyNames(),
            "--method bz: the superpenalty ~h^-(2p+1) (super: converges at rate >= p, stiffer "
            "system) or a penalty ~1/h (fixed: cheap, but its error does not fall with h)",
            DiscretizationOptions::kDefaultBzPenalty);
  cmd->add_option("--degree", d.basis.degree, "polynomial degree of the basis")
      ->check(kDegree)
      ->capture_default_str();
  cmd->add_option("--E", s.material.youngsModulus, "Young's modulus")
      ->check(kYoungsModulus)
      ->capture_default_str();
  cmd->add_option("--nu", s.material.poissonRatio, "Poisson's ratio, in (-1, 0.5)")
      ->check(kPoissonRatio)
      ->capture_default_str();
  cmd->add_option("--density", s.material.density, "mass density (with --gravity)")
      ->check(kDensity)
      ->capture_default_str();
  cmd->add_option_function<std::string>(
         "--gravity", [&s](const std::string& v) { s.gravity = parseVector(v, "--gravity"); },
         "gravitational acceleration")
      ->type_name("GX,GY,GZ");
  addRegionOptions(*cmd, "clamp", s.clamps, "clamp (u = 0, weakly)");
  addTractionOptions(*cmd, s.tractions);
  addChoice(*cmd, "--solver", s.solver, solverNames(), "linear solver");
  addChoice(*cmd, "--penalty", d.penalty.rule, penaltyNames(),
            "penalty choice: bound (guaranteed SPD), doubling (the paper's), fixed (--eta)");
  cmd->add_option_function<double>(
         "--eta",
         [&d](double eta) {
           d.penalty.eta = eta;
           if (d.penalty.rule == PenaltyRule::TraceBound) d.penalty.rule = PenaltyRule::Fixed;
         },
         "the penalty: fixed, or the first value of doubling")
      ->check(kPenalty);
  AdaptOptions& a = o->adaptOptions;
  cmd->add_flag("--adapt", o->adapt,
                "solve adaptively: solve, estimate, mark, refine until --target-error, "
                "--max-dofs or --max-rounds; writes the adapted mesh");
  addChoice(*cmd, "--adapt-by", a.criterion, adaptCriterionNames(),
            "what --adapt refines by: the error estimate, or the principal stress (the paper's)");
  addChoice(*cmd, "--split", a.split, refineSplitNames(),
            "how --adapt splits an element: 1-to-8 octants, or 1-to-2 halves across the "
            "principal stress");
  cmd->add_option_function<double>(
         "--target-error", [&a](double e) { a.targetError = e; },
         "--adapt: stop once the estimate is below this fraction of the energy norm")
      ->check(kPositive);
  cmd->add_option_function<std::size_t>(
         "--max-dofs", [&a](std::size_t n) { a.maxDofs = n; },
         "--adapt: stop before a refinement would exceed this many DOFs")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-rounds", a.maxRounds, "--adapt: refinement rounds at most")
      ->check(CLI::Range(0, 20))
      ->capture_default_str();
  cmd->add_option("--bulk", a.bulk,
                  "--adapt-by error: refine the fewest elements holding this share of the "
                  "squared estimate")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_option("--stress-fraction", a.stressFraction,
                  "--adapt-by stress: refine where the principal stress exceeds this fraction "
                  "of the first solve's largest")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_option("--max-level", a.maxLevel,
                  "--adapt-by stress: how often an element may be split (1: once, as the "
                  "thesis's Fig. 4.9; children are not marked again)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->add_option("--surface", o->surfaceOutput,
                  "write the deformed embedded surface (MLS embedding) to this .vtp file");
  cmd->add_option("--embed", o->embed,
                  "the surface --surface carries (default: the one the mesh was sliced from)")
      ->check(CLI::ExistingFile);
  cmd->callback([o, cmd, &common, &exitCode] {
    if (parseName(tetMethodNames(), o->method)) {
      for (const char* name :
           {"--degree", "--bz-penalty", "--penalty", "--eta", "--adapt", "--surface", "--embed"})
        if (cmd->count(name) > 0) o->dgOnlyGiven.push_back(name);
    } else {
      for (const auto& [name, method] : methodNames())
        if (name == o->method) o->solve.discretization.method = method;
    }
    run(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
