// The compiled part of the Python module `polydg` (polydg._polydg): surfaces, the Model and its
// operations, each a thin layer over the library (polydg/model/model.h) built against its
// public headers only. Keyword arguments of the operations are checked by the pipeline format's
// step parser (parsePipelineStep), so a Python call, a pipeline step and a `polydg` command
// accept and refuse the same values; reports are the JSON of model/report_json.h as Python
// dicts. Long operations release the GIL. One file per class (python/*_bindings.cpp).
#include "bindings.h"
#include "polydg/util/process.h"
#include "polydg/version.h"

PYBIND11_MODULE(_polydg, m) {
  using namespace polydg;
  using namespace polydg::python;
  m.doc() = "polydg's compiled core; use the package `polydg`";
  m.attr("__version__") = kVersion;
  // As the `polydg` binary does: freed memory stays in the process for the next operation
  // (and the process runs the BLAS kernels of its CPU).
  keepFreedMemory();
  bindErrors(m);
  bindSurface(m);
  bindModel(m);
  bindModelIo(m);
  bindPipelines(m);
}
