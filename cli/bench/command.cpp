// polydg bench: the benchmark suites of shared/BENCHMARKS.md (cli/bench/suites.h), each written
// as DIR/NAME.json, DIR/NAME.csv and one or more plots DIR/NAME*.svg.
//
// Sample runs:
//   polydg bench --suite all --out bench/          (every suite; dynamics takes the longest)
//   polydg bench --suite stability --out bench/    (B4: conditioning, locking, scale)
//   polydg bench --suite stability --out b/ --quick   (reduced sizes, as the tests run it)
//   polydg bench --suite dynamics --out bench/     (B6, B7, time per step up to 1M DOFs)
//   polydg bench --suite contact --out bench/      (B9, embedding and collision speed)
//   polydg bench --suite adaptivity --out bench/   (B11 and B12: refinement by stress and by
//                                                   the error estimate)
//   polydg bench --suite multigrid --out bench/    (CG iterations on the bunny and the torus,
//                                                   sliced and cut, beside the unit cube)
//   polydg bench --suite openfoam --out bench/     (polydg against OpenFOAM's snappyHexMesh on
//                                                   the torus and the bunny, checkMesh on both)
//   polydg bench --suite meshing --out b/ --data DIR  (torus.obj from DIR instead of the
//                                                      share/polydg folder beside the binary)
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <system_error>

#include "cli/bench/data_files.h"
#include "cli/bench/suites.h"
#include "cli/commands.h"
#include "model/files.h"
#include "polydg/util/error.h"
#include "util/stopwatch.h"

namespace polydg::cli {

namespace {

using bench::BenchOptions;

void runBench(BenchOptions o, const CommonOptions& common) {
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) throw InputError("cannot create " + o.out + ": " + ec.message());
  if (o.dataDir.empty()) o.dataDir = bench::dataDirectory().string();
  const bool all = o.suite == "all";
  const Stopwatch total;
  auto timed = [&](const std::string& name, auto&& run) {
    const Stopwatch suite;
    bench::writeSuite(o.out, run(), common.quiet);
    if (!common.quiet)
      std::cout << "suite " << name << ": " << suite.seconds() << " s" << std::endl;
  };
  if (all || o.suite == "accuracy")
    timed("accuracy", [&] { return bench::accuracySuite(o, common.quiet); });
  if (all || o.suite == "table41")
    timed("table41", [&] { return bench::table41Suite(common.quiet); });
  if (all || o.suite == "stability")
    timed("stability", [&] { return bench::stabilitySuite(o, common.quiet); });
  if (all || o.suite == "meshing")
    timed("meshing", [&] { return bench::meshingSuite(o, common.quiet); });
  if (all || o.suite == "cutting")
    timed("cutting", [&] { return bench::cuttingSuite(o, common.quiet); });
  if (all || o.suite == "dynamics")
    timed("dynamics", [&] { return bench::dynamicsSuite(o, common.quiet); });
  if (all || o.suite == "contact")
    timed("contact", [&] { return bench::contactSuite(o, common.quiet); });
  if (all || o.suite == "adaptivity")
    timed("adaptivity", [&] { return bench::adaptivitySuite(o, common.quiet); });
  if (all || o.suite == "multigrid")
    timed("multigrid", [&] { return bench::multigridSuite(o, common.quiet); });
  if (all || o.suite == "sfem") timed("sfem", [&] { return bench::sfemSuite(o, common.quiet); });
  if (all || o.suite == "openfoam")
    timed("openfoam", [&] { return bench::openfoamSuite(o, common.quiet); });
  if (!common.quiet && all) std::cout << "all suites: " << total.seconds() << " s" << std::endl;
}

}  // namespace

void addBenchCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Benchmark suites as JSON, CSV and SVG plots: accuracy (B1), table41 (B2), "
      "stability (B4), meshing, cutting, dynamics (B6, B7, time per step), contact (B9, "
      "embedding and collision speed), adaptivity (B11, B12), multigrid (CG iterations on real "
      "models), sfem (the tet methods beside DG), openfoam (polydg beside OpenFOAM's "
      "snappyHexMesh), or all");
  cmd->add_option("--suite", o->suite,
                  "accuracy, table41, stability, meshing, cutting, dynamics, contact, adaptivity, "
                  "multigrid, sfem, openfoam or all")
      ->required()
      ->check(CLI::IsMember({"accuracy", "table41", "stability", "meshing", "cutting", "dynamics",
                             "contact", "adaptivity", "multigrid", "sfem", "openfoam", "all"}));
  cmd->add_option("--out", o->out, "folder for NAME.json, NAME.csv and NAME*.svg")->required();
  cmd->add_flag("--skip-sliced", o->skipSliced, "accuracy: hex grids only");
  cmd->add_flag("--quick", o->quick,
                "reduced sizes (a smoke test of every output; the figures are not the "
                "benchmark's)");
  cmd->add_option("--data", o->dataDir,
                  "folder of the bundled models (torus.obj, models/bunny.off); default: "
                  "share/polydg beside the folder of the polydg binary")
      ->check(CLI::ExistingDirectory);
  cmd->callback([o, &common, &exitCode] {
    runBench(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
