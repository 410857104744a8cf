// polydg run: a JSON pipeline of steps (mesh, cut, merge, check, solve, write) applied to one
// input or to many (model/pipeline.h), each input in its own output folder with its own report;
// one failing input never stops or spoils the others.
//
// Sample runs:
//   polydg run testdata/pipeline.json --out runs/
//   polydg run testdata/pipeline.json --inputs a.obj b.stl c.vtu --jobs 2 --out runs/
//       --report runs/summary.json   (one line)
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/progress.h"
#include "model/files.h"
#include "polydg/model/pipeline.h"
#include "util/format.h"

namespace polydg::cli {

namespace {

namespace fs = std::filesystem;

struct RunOptions {
  std::string pipeline;
  std::vector<std::string> inputs;
  int jobs = 1;
  std::string out;
  std::string report;
};

void printSummary(const std::vector<InputOutcome>& outcomes, std::ostream& out) {
  std::size_t width = 5;
  for (const InputOutcome& o : outcomes) width = std::max(width, o.input.size());
  out << std::left << std::setw(static_cast<int>(width)) << "input"
      << "  " << std::setw(6) << "status" << std::right << std::setw(10) << "elements"
      << std::setw(14) << "volume" << std::setw(10) << "time_s"
      << "  first error\n";
  for (const InputOutcome& o : outcomes) {
    out << std::left << std::setw(static_cast<int>(width)) << o.input << "  " << std::setw(6)
        << (o.passed ? "ok" : "FAILED") << std::right << std::setw(10)
        << (o.elements ? std::to_string(o.elements) : std::string("-")) << std::setw(14)
        << (o.volume && o.elements ? formatNumber(*o.volume, 8) : std::string("-")) << std::setw(10)
        << formatNumber(o.seconds, 3) << "  " << (o.passed ? "" : o.error) << '\n';
  }
}

void run(const RunOptions& o, const CommonOptions& common, int& exitCode) {
  Pipeline pipeline = readPipeline(o.pipeline);
  if (!o.inputs.empty()) pipeline.inputs = o.inputs;
  BatchOptions batch;
  batch.jobs = o.jobs;
  batch.out =
      o.out.empty() ? fs::path(fs::path(o.pipeline).stem().string() + "-out") : fs::path(o.out);
  if (!o.report.empty()) requireOutput(o.report, {o.pipeline});
  ProgressBar bar("run", common.quiet);
  std::size_t done = 0;
  batch.onDone = [&](std::size_t, const InputOutcome& outcome) {
    bar.finish();  // clear the bar's line before the input's lines; redrawn below
    if (!common.quiet) {
      std::cout << outcome.input << ": " << (outcome.passed ? "ok" : "FAILED") << " -> "
                << (batch.out / outcome.stem).string() << '\n'
                << outcome.log;
      if (!outcome.passed) std::cout << "  error: " << outcome.error << '\n';
      std::cout << std::flush;
    }
    bar.update(static_cast<double>(++done) / static_cast<double>(pipeline.inputs.size()));
  };
  const std::vector<InputOutcome> outcomes = runBatch(pipeline, batch);
  bar.finish();
  const nlohmann::json summary = batchReport(pipeline, batch.out, outcomes);
  if (!o.report.empty()) writeJsonFile(o.report, summary);
  if (!common.quiet) {
    std::cout << '\n';
    printSummary(outcomes, std::cout);
  } else {
    for (const InputOutcome& outcome : outcomes)
      if (!outcome.passed)
        std::cerr << "polydg: " << outcome.input << ": " << outcome.error << '\n';
  }
  exitCode = summary["passed"].get<bool>() ? 0 : 1;
}

}  // namespace

void addRunCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run a JSON pipeline of steps (mesh, cut, merge, check, solve, write) on inputs");
  cmd->add_option("pipeline", o->pipeline, "pipeline file (.json; format in README.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--inputs", o->inputs, "inputs instead of the pipeline's (surfaces or .vtu)");
  cmd->add_option("--jobs", o->jobs, "inputs run at the same time")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_option("--out", o->out,
                  "output folder: one subfolder per input (default: PIPELINE-out)");
  cmd->add_option("--report", o->report, "write every input's report and the summary as JSON");
  cmd->callback([o, &common, &exitCode] { run(*o, common, exitCode); });
}

}  // namespace polydg::cli
