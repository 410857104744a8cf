// polydg simulate: a body in time (model/scene.h): Model::simulate() on a simulation mesh, with
// the scene from a JSON file, a ParaView time series in the output folder and a JSON report.
//
// Sample run:
//   polydg simulate beam.vtu --scene fall.json -o beam_fall --report fall.json
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/progress.h"
#include "model/files.h"
#include "polydg/mesh/tet_mesh.h"
#include "polydg/model/names.h"
#include "polydg/model/report_json.h"
#include "polydg/model/scene.h"

namespace polydg::cli {

namespace {

struct SimulateCommandOptions {
  std::string input, scene, output, report;
};

void run(const SimulateCommandOptions& o, const CommonOptions& common) {
  if (!isVolumeMeshPath(o.input) && !isTetMeshFile(o.input))
    throw InputError(o.input +
                     ": simulate reads simulation meshes (.vtu), and tet meshes (TetGen .ele, "
                     "Gmsh .msh) for the tet methods; make a simulation mesh with 'polydg mesh'");
  if (!o.report.empty()) requireOutput(o.report, {o.input, o.scene});
  const Scene scene = readScene(o.scene);  // every key checked before anything runs
  // The frames are OUTDIR/scene_NNNNNN.vtu and OUTDIR/scene.pvd: no input may be one of them.
  namespace fs = std::filesystem;
  for (const std::string& in : {o.input, o.scene}) {
    const fs::path folder = fs::absolute(in).parent_path();
    const std::string name = fs::path(in).filename().string();
    std::error_code ec;
    if (fs::equivalent(folder, o.output, ec) &&
        (name.rfind("scene_", 0) == 0 || name == "scene.pvd"))
      throw InputError(in +
                       " lies in the output folder under a name the frames take; choose "
                       "another -o");
  }
  ReadReport read;
  Model model = Model::read(o.input, &read);
  ProgressBar bar("simulate", common.quiet);
  SimulateOptions options;
  options.outputDir = o.output;
  // Steps per second over the last second or so: the frame rate as the user feels it.
  std::chrono::steady_clock::time_point windowStart;
  int windowStep = -1;  // the first report opens the window (after the set-up)
  std::string rate;
  options.progress = [&](const SimulationProgress& p) {
    const auto now = std::chrono::steady_clock::now();
    if (windowStep < 0) {
      windowStart = now;
      windowStep = p.step;
    }
    const double seconds = std::chrono::duration<double>(now - windowStart).count();
    if (seconds >= 1.0 && p.step > windowStep) {
      std::ostringstream s;
      s.precision(3);
      s << (p.step - windowStep) / seconds << " steps/s";
      rate = s.str();
      windowStart = now;
      windowStep = p.step;
    }
    bar.update(static_cast<double>(p.step) / p.steps, rate);
  };
  const SimulationReport r = model.simulate(scene, options);
  bar.finish();
  if (!o.report.empty()) {
    nlohmann::json j{
        {"command", "simulate"}, {"input", o.input}, {"scene_file", o.scene}, {"output", o.output}};
    j.update(toJson(r));
    j["timings_s"]["read"] = read.seconds;
    writeJsonFile(o.report, j);
  }
  if (!common.quiet) {
    const BodyState& last = r.steps.back().state;
    int iterations = 0;
    double stepping = 0.0;
    for (const SimulationStep& s : r.steps) {
      iterations += s.step.iterations;
      stepping += s.seconds;
    }
    const double n = static_cast<double>(r.steps.size());
    std::cout << o.input << ": "
              << (scene.tetMethod
                      ? toString(*scene.tetMethod) + ", " + std::to_string(r.elements) + " tets, "
                      : std::to_string(r.elements) + " elements, ")
              << r.dofs << " DOFs, " << r.steps.size() << " steps of dt " << scene.dt << " ("
              << (scene.corotational ? "corotational" : "linear") << ", "
              << nameOf(integratorNames(), scene.integrator) << ")"
              << (iterations ? ", " + std::to_string(iterations) + " CG iterations" : "") << '\n'
              << "  per step: " << stepping / n << " s (" << n / stepping << " steps/s): rotation "
              << r.rotationSeconds / n << " s, assembly " << r.assemblySeconds / n << " s, solve "
              << r.solveSeconds / n << " s; " << r.cuts.size() << " cuts, " << r.frames.size()
              << " frames\n"
              << "  at t = " << r.steps.back().step.t << ": kinetic " << last.kinetic
              << ", elastic " << last.elastic << ", gravity " << last.gravity << '\n';
    const SimulationEmbedding& e = r.embedding;
    if (!e.surface.empty())
      std::cout << "  surface " << e.surface << ": " << e.points << " points, " << e.samples
                << " samples, W " << e.weightNonzeros << " nonzeros, set up in " << e.setupSeconds
                << " s\n";
    if (!e.contactPointKind.empty()) {
      double deepest = 0.0, collision = 0.0;
      for (const SimulationStep& s : r.steps) {
        deepest = std::max(deepest, s.contact.deepest);
        collision += s.collisionSeconds;
      }
      const ContactMeasure& c = r.steps.back().contact;
      std::cout << "  contact (" << e.contactPoints << " " << e.contactPointKind
                << " points): at the end " << c.contacts << " in contact, penetration " << c.deepest
                << " (deepest over the run " << deepest << "); collisions " << collision / n
                << " s per step\n";
    }
    std::cout << "  wrote " << (r.pvd.empty() ? std::string("nothing") : r.pvd) << '\n';
  }
}

}  // namespace

void addSimulateCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<SimulateCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Move a body in time (corotational DG dynamics, cuts while it moves)");
  cmd->add_option("mesh", o->input,
                  "simulation mesh (.vtu); for \"method\": \"fem\" or \"fs-fem\" a tet mesh "
                  "(.vtu of tets, TetGen .ele, Gmsh .msh)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "the scene (JSON; see README.md, Scenes)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", o->output,
                  "output folder: scene.pvd and one VTU per frame (created if missing)")
      ->required();
  cmd->add_option("--report", o->report, "write the figures as JSON to this file");
  cmd->callback([o, &common, &exitCode] {
    run(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
