// polydg: surface meshes to polyhedral DG simulation meshes, with exact integration and checks.
//
// Sample runs:
//   polydg mesh testdata/torus.obj --cells 16 -o torus.vtu --report mesh.json
//   polydg info testdata/cube.obj --report info.json
//   polydg check mesh.vtu --report check.json
//   polydg solve beam.vtu -o out.vtu --degree 2 --clamp x=0 --traction x=10:0,0,-1
//   polydg bench --suite accuracy --out bench/
//   polydg run testdata/pipeline.json --jobs 2 --out runs/
//   polydg cut mesh.vtu -o half.vtu --plane "0,0,1,0.5" --remove-side + --report cut.json
#include <cstdio>
#include <exception>
#include <iostream>

#include "cli/commands.h"
#include "cli/report.h"

int main(int argc, char** argv) {
  CLI::App app{"polydg: turn surface meshes into polyhedral DG simulation meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "polydg 0.1.0");
  polydg::cli::CommonOptions common;
  int exitCode = 0;
  app.add_flag("-q,--quiet", common.quiet, "print nothing but errors");
  app.fallthrough();  // --quiet may follow the subcommand
  polydg::cli::addInfoCommand(app, common, exitCode);
  polydg::cli::addMeshCommand(app, common, exitCode);
  polydg::cli::addCheckCommand(app, common, exitCode);
  polydg::cli::addSolveCommand(app, common, exitCode);
  polydg::cli::addBenchCommand(app, common, exitCode);
  polydg::cli::addRunCommand(app, common, exitCode);
  polydg::cli::addCutCommand(app, common, exitCode);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error; CLI11's own would add a second.
    std::cerr << "polydg: error: " << e.what() << " (see polydg --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "polydg: error: " << e.what() << '\n';
    return 2;
  }
  return exitCode;
}
