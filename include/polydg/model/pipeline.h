// Pipelines: a JSON list of steps (mesh, cut, merge, check, solve, write) applied to inputs, each
// input on its own model, in its own output folder, with its own report; a failing input never
// stops or spoils the others. The format is documented in README.md ("Pipelines") and checked
// completely by readPipeline() before any input is touched. `polydg run` and polydg.batch()
// (Python, on threads or a Dask cluster) run inputs through runPipelineInput().
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/model/model.h"

namespace polydg {

struct MeshStep {
  MeshOptions options;  ///< its momentDegree is set when the input runs (the pipeline's need)
};
struct CutStep {
  CutRequest request;
};
struct MergeStep {
  MergeRequest request;
};
struct CheckStep {
  MeshCheckOptions options;
};
struct SolveStep {
  SolveOptions options;
  std::string output;  ///< VTU with the solution, relative to the input's folder; "" for none
};
struct WriteStep {
  std::string path;  ///< relative to the input's folder; "{stem}" is the input's stem
};
struct ExportStep {
  std::string path;  ///< the case folder, relative to the input's folder; "{stem}" as above
  ExportOptions options;
};
using PipelineStep =
    std::variant<MeshStep, CutStep, MergeStep, CheckStep, SolveStep, WriteStep, ExportStep>;

/// "mesh", "cut", "merge", "check", "solve", "write" or "export".
const char* stepName(const PipelineStep& step);

struct Pipeline {
  std::string file;  ///< where it was read from (for messages)
  std::string description;
  std::vector<std::string> inputs;  ///< resolved against the pipeline file's folder
  std::vector<PipelineStep> steps;

  /// The moment degree the steps need at most (0 if none reads moments): meshing and reading
  /// integrate every face once to it, so no later step integrates again.
  int momentDegree() const;
};

/// Reads and checks a pipeline file. Throws InputError with one line naming the file and the
/// place ("FILE: steps[1].plnae: unknown key; see the pipeline format in README.md").
Pipeline readPipeline(const std::string& file);
/// The same from a parsed document; `file` names it in messages, `base` is the folder relative
/// inputs are resolved against.
Pipeline parsePipeline(const nlohmann::json& document, const std::string& file,
                       const std::filesystem::path& base);

/// Parses one step object of the pipeline format (a `steps` entry) on its own, checked as in a
/// pipeline; messages start with `caller` ("Model.cut(): plane: ...; see `hint`"). The Python
/// module passes its keyword arguments through it.
PipelineStep parsePipelineStep(const nlohmann::json& step, const std::string& caller,
                               const std::string& hint);

/// The outcome of one input.
struct InputOutcome {
  std::string input, stem;
  bool passed = false;
  std::size_t elements = 0;
  std::optional<double> volume;
  std::size_t facesIntegrated = 0;
  double seconds = 0.0;
  std::string error;      ///< the failed step and why, one line
  nlohmann::json report;  ///< what DIR/<stem>/report.json holds
  std::string log;        ///< a line per step, for the terminal
};

/// Runs `input` (a surface, or a .vtu mesh that skips the mesh step) through the steps in a
/// staging folder `out/.<stem>.partial-<pid>` that is renamed to `out/<stem>` at the end,
/// replacing an older one: a success leaves every output and report.json, a failure only
/// report.json with the error of the step that failed. Every failure of the input is caught
/// into the outcome; throws (InputError) only if the folder cannot be written.
InputOutcome runPipelineInput(const Pipeline& pipeline, const std::string& input,
                              const std::string& stem, const std::filesystem::path& out);

/// Output folder names: the inputs' stems, made unique with _2, _3, ... in input order.
std::vector<std::string> uniqueStems(const std::vector<std::string>& inputs);

/// Throws InputError if an input lies in a folder the run would replace (out/<stem>).
void refuseInputsInOutputs(const std::vector<std::string>& inputs,
                           const std::vector<std::string>& stems, const std::filesystem::path& out);

struct BatchOptions {
  int jobs = 1;  ///< inputs at a time (threads)
  std::filesystem::path out;
  /// Called (under a lock, from the thread that ran it) as each input ends.
  std::function<void(std::size_t index, const InputOutcome&)> onDone;
};

/// Runs every input of `pipeline` (which must have some) into `options.out`; returns the
/// outcomes in input order. Throws InputError for an unusable output folder or an input inside
/// one (nothing run).
std::vector<InputOutcome> runBatch(const Pipeline& pipeline, const BatchOptions& options);

/// The summary report of a batch: command "run", pipeline, out, inputs (each input's report),
/// failed, passed.
nlohmann::json batchReport(const Pipeline& pipeline, const std::filesystem::path& out,
                           const std::vector<InputOutcome>& outcomes);

}  // namespace polydg
