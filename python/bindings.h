// What the binding files of the Python module share (python/*_bindings.cpp): JSON to and from
// Python, keyword arguments read as pipeline steps, array copies and Python callbacks called
// from library code that runs without the GIL. Private to python/.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "polydg/model/model.h"
#include "polydg/model/pipeline.h"

namespace polydg::python {

namespace py = pybind11;

/// A JSON value as the Python object json.loads makes of it (dicts, lists, floats, ...).
py::object toPython(const nlohmann::json& j);
/// A Python value of JSON types as JSON (for the step parser).
nlohmann::json jsonOf(const py::handle& value);
/// The keyword arguments a caller gave (None means "not given"), as a pipeline step object.
nlohmann::json stepObject(const char* step, const py::dict& kwargs);

/// `kwargs` parsed as a `step` of the pipeline format, so that Python, pipelines and the
/// commands accept and refuse the same values; `caller` ("Model.cut()") names it in messages.
template <class Step>
Step parseStep(const char* step, const char* caller, const py::dict& kwargs) {
  const PipelineStep parsed = parsePipelineStep(
      stepObject(step, kwargs), caller,
      "see help(polydg." + std::string(caller).substr(0, std::strlen(caller) - 2) +
          ") or docs/guide.md");
  return std::get<Step>(parsed);
}

/// Parses `kwargs` as a `step` of the pipeline format, runs `run(model, step)` with the GIL
/// released and returns its JSON report as a dict.
template <class Step, class Run>
py::object operate(Model& model, const char* step, const char* caller, const py::dict& kwargs,
                   Run run) {
  const Step parsed = parseStep<Step>(step, caller, kwargs);
  nlohmann::json report;
  {
    py::gil_scoped_release release;
    report = run(model, parsed);
  }
  return toPython(report);
}

/// The report of a cut or merge; one that failed its checks (or left nothing) raises
/// CheckFailure naming it, as `polydg cut` exits 1.
nlohmann::json editReport(const OperationReport& r);

/// A float64 array of shape (n, 3) copied from Vec3s.
py::array_t<double> pointsArray(const std::vector<Vec3>& points);
/// An int64 array of shape (m, 3) copied from triangles.
py::array_t<std::int64_t> trianglesArray(const std::vector<std::array<std::uint32_t, 3>>& t);

/// Thrown through the library when a Python callback raised. Not a std::exception, so no
/// handler in the library converts or swallows it on the way out.
struct CallbackRaised {};

/// A Python callable called from code that runs without the GIL: each call takes the GIL; if the
/// callable raises, its exception is kept and the library unwound with CallbackRaised, and
/// reraise() (with the GIL held again, after the library returned) raises the callable's own
/// exception, traceback and all.
class GuardedCallback {
 public:
  explicit GuardedCallback(py::object callable) : callable_(std::move(callable)) {}

  /// Calls the callable (if not None), then lets Python handle pending signals: Ctrl-C stops a
  /// long run with KeyboardInterrupt like any Python code.
  template <class... Args>
  void operator()(Args&&... args) {
    py::gil_scoped_acquire gil;
    if (raised_) throw CallbackRaised{};  // once stopped, never called again (other threads)
    try {
      if (!callable_.is_none()) callable_(std::forward<Args>(args)...);
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    } catch (py::error_already_set& e) {
      raised_.emplace(std::move(e));
      throw CallbackRaised{};
    }
  }

  [[noreturn]] void reraise() { throw *raised_; }

 private:
  py::object callable_;
  std::optional<py::error_already_set> raised_;
};

// The module's parts, one per class or group of functions.
void bindErrors(py::module_& m);     ///< polydg.Error and polydg.CheckFailure
void bindSurface(py::module_& m);    ///< Surface, read_surface
void bindModel(py::module_& m);      ///< Model: arrays, edits, checks and solves
void bindModelIo(py::module_& m);    ///< mesh, read (making models)
void bindPipelines(py::module_& m);  ///< run_input, check_pipeline and batch helpers

}  // namespace polydg::python
