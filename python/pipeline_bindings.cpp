// The module's functions that make models (polydg.mesh, polydg.read) and run pipelines
// (run_input and the helpers of polydg.batch, python/polydg/batch.py).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <optional>

#include <tbb/global_control.h>

#include "bindings.h"
#include "polydg/model/report_json.h"
#include "polydg/util/error.h"

namespace polydg::python {

namespace {

py::tuple mesh(const TriangleSurface& surface, const py::dict& kwargs, const std::string& source,
               const py::object& progress) {
  MeshStep step = parseStep<MeshStep>("mesh", "polydg.mesh()", kwargs);
  // Guarded: an exception from the callback is re-raised as itself, whatever handlers the
  // slicing has on the way out (and Ctrl-C stops the slicing).
  GuardedCallback callback(progress);
  step.options.progress = [&callback](double fraction) { callback(fraction); };
  MeshReport report;
  std::optional<Model> model;
  try {
    py::gil_scoped_release release;
    model.emplace(Model::fromSurface(surface, step.options, report, source));
  } catch (const CallbackRaised&) {
    callback.reraise();
  }
  if (!report.passed()) throw CheckFailure("the new mesh failed: " + report.failures().front());
  return py::make_tuple(std::move(*model), toPython(toJson(report)));
}

py::tuple read(const std::string& path) {
  ReadReport report;
  std::optional<Model> model;
  {
    py::gil_scoped_release release;
    model.emplace(Model::read(path, &report));
  }
  return py::make_tuple(std::move(*model), toPython(toJson(report)));
}

py::object runInput(const std::string& pipelineText, const std::string& pipelineFile,
                    const std::string& base, const std::string& input, const std::string& stem,
                    const std::string& out, int threads) {
  const Pipeline pipeline = parsePipeline(nlohmann::json::parse(pipelineText), pipelineFile, base);
  InputOutcome outcome;
  {
    py::gil_scoped_release release;
    // A Dask worker process runs as many tasks at once as it has threads; the parallel parts of
    // one input then get no more threads than that, as under `polydg run`.
    std::optional<tbb::global_control> limit;
    if (threads > 0)
      limit.emplace(tbb::global_control::max_allowed_parallelism,
                    static_cast<std::size_t>(threads));
    outcome = runPipelineInput(pipeline, input, stem, out);
  }
  return toPython(outcome.report);
}

std::vector<std::string> checkPipeline(const std::string& pipelineText,
                                       const std::string& pipelineFile, const std::string& base) {
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(pipelineText);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(pipelineFile + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  return parsePipeline(document, pipelineFile, base).inputs;
}

}  // namespace

void bindModelIo(py::module_& m) {
  m.def("mesh", &mesh, py::arg("surface"), py::arg("kwargs"), py::arg("source") = "",
        py::arg("progress") = py::none());
  m.def("read", &read, py::arg("path"));
}

void bindPipelines(py::module_& m) {
  m.def("run_input", &runInput, py::arg("pipeline"), py::arg("pipeline_file"), py::arg("base"),
        py::arg("input"), py::arg("stem"), py::arg("out"), py::arg("threads") = 0);
  m.def("check_pipeline", &checkPipeline, py::arg("pipeline"), py::arg("pipeline_file"),
        py::arg("base"));
  m.def("unique_stems", &uniqueStems, py::arg("inputs"));
  m.def(
      "refuse_inputs_in_outputs",
      [](const std::vector<std::string>& inputs, const std::vector<std::string>& stems,
         const std::string& out) { refuseInputsInOutputs(inputs, stems, out); },
      py::arg("inputs"), py::arg("stems"), py::arg("out"));
}

}  // namespace polydg::python
