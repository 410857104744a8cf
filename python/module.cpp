// The compiled part of the Python module `polydg` (polydg._polydg): surfaces, the Model and its
// operations, each a thin layer over the library (polydg/model/model.h). Keyword arguments of
// the operations are checked by the pipeline format's step parser (parsePipelineStep), so a
// Python call, a pipeline step and a `polydg` command accept and refuse the same values; reports
// are the JSON of model/report_json.h as Python dicts. Long operations release the GIL.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include <tbb/global_control.h>

#include "polydg/mesh/surface_io.h"
#include "polydg/model/model.h"
#include "polydg/model/names.h"
#include "polydg/model/pipeline.h"
#include "polydg/model/report_json.h"
#include "polydg/model/scene.h"
#include "polydg/util/error.h"
#include "polydg/util/process.h"
#include "polydg/version.h"

namespace py = pybind11;

namespace polydg::python {

namespace {

/// A JSON value as the Python object json.loads makes of it (dicts, lists, floats, ...).
py::object toPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

/// A Python value of JSON types as JSON (for the step parser).
nlohmann::json jsonOf(const py::handle& value) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(value));
  return nlohmann::json::parse(text);
}

/// The keyword arguments a caller gave (None means "not given"), as a pipeline step object.
nlohmann::json stepObject(const char* step, const py::dict& kwargs) {
  nlohmann::json object = nlohmann::json::object();
  object["step"] = step;
  for (const auto& [key, value] : kwargs)
    if (!value.is_none()) object[py::str(key).cast<std::string>()] = jsonOf(value);
  return object;
}

template <class Step>
Step parseStep(const char* step, const char* caller, const py::dict& kwargs) {
  const PipelineStep parsed = parsePipelineStep(
      stepObject(step, kwargs), caller,
      "see help(polydg." + std::string(caller).substr(0, std::strlen(caller) - 2) +
          ") or README.md");
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

/// The report of a cut or merge; one that failed its validation (or left nothing) raises
/// CheckFailure naming it, as `polydg cut` exits 1.
nlohmann::json editReport(const OperationReport& r) {
  if (!r.check.passed) throw CheckFailure(r.op + " failed: " + r.check.failure);
  return toJson(r);
}

/// A read-only float64 array of shape (n, 3) copied from Vec3s.
py::array_t<double> pointsArray(const std::vector<Vec3>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t(3)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) a(i, k) = points[i][k];
  return out;
}

TriangleSurface surfaceFromArrays(const py::array_t<double, py::array::c_style>& v,
                                  const py::array_t<std::int64_t, py::array::c_style>& f) {
  if (v.ndim() != 2 || v.shape(1) != 3)
    throw InputError("Surface(V, F): V must be an n x 3 array of coordinates");
  if (f.ndim() != 2 || f.shape(1) != 3)
    throw InputError("Surface(V, F): F must be an m x 3 array of vertex indices");
  TriangleSurface s;
  auto va = v.unchecked<2>();
  s.vertices.reserve(v.shape(0));
  for (py::ssize_t i = 0; i < v.shape(0); ++i) {
    const Vec3 p(va(i, 0), va(i, 1), va(i, 2));
    if (!p.allFinite())
      throw InputError("Surface(V, F): V[" + std::to_string(i) +
                       "] is not finite; fix the coordinates");
    s.vertices.push_back(p);
  }
  auto fa = f.unchecked<2>();
  s.triangles.reserve(f.shape(0));
  for (py::ssize_t t = 0; t < f.shape(0); ++t) {
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const std::int64_t index = fa(t, k);
      if (index < 0 || index >= v.shape(0))
        throw InputError("Surface(V, F): F[" + std::to_string(t) + "] refers to vertex " +
                         std::to_string(index) + ", but V has " + std::to_string(v.shape(0)) +
                         " rows");
      tri[k] = static_cast<std::uint32_t>(index);
    }
    s.triangles.push_back(tri);
  }
  return s;
}

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

/// A scene given to Model.simulate(): a path (str) to a scene file, or a dict of the same
/// format, named "scene" in messages.
Scene sceneOf(const py::handle& scene) {
  if (py::isinstance<py::str>(scene)) return readScene(scene.cast<std::string>());
  nlohmann::json document;
  try {
    document = jsonOf(scene);
  } catch (const nlohmann::json::parse_error&) {  // json.dumps wrote NaN or Infinity
    throw InputError(
        "scene: holds a number that is not finite (NaN or infinity); see the scene "
        "format in README.md");
  }
  return parseScene(document, "scene");
}

}  // namespace
}  // namespace polydg::python

PYBIND11_MODULE(_polydg, m) {
  using namespace polydg;
  using namespace polydg::python;
  m.doc() = "polydg's compiled core; use the package `polydg`";
  m.attr("__version__") = kVersion;
  // As the `polydg` binary does: freed memory stays in the process for the next operation
  // (a batch on Dask workers ran 2.2x slower without it and the BLAS kernels below).
  keepFreedMemory();

  // Errors: polydg.Error (bad input, nothing changed), polydg.CheckFailure (a result failed a
  // check; a Model it happened to must not be used further).
  static py::exception<Error> error(m, "Error");
  static py::exception<CheckFailure> checkFailure(m, "CheckFailure", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const CheckFailure& e) {
      PyErr_SetString(checkFailure.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  py::class_<TriangleSurface>(m, "Surface", py::dynamic_attr(),
                              "A triangle surface: vertices V (n x 3 float64) and triangles F "
                              "(m x 3 vertex indices).")
      .def(py::init(&surfaceFromArrays), py::arg("V"), py::arg("F"),
           "Surface(V, F): V an n x 3 array of coordinates (float64, model units), F an m x 3 "
           "array of 0-based vertex indices, counter-clockwise seen from outside. Copied.")
      .def_property_readonly(
          "V", [](const TriangleSurface& s) { return pointsArray(s.vertices); },
          "The vertices, an n x 3 float64 array (a copy).")
      .def_property_readonly(
          "F",
          [](const TriangleSurface& s) {
            py::array_t<std::int64_t> out(
                {static_cast<py::ssize_t>(s.triangles.size()), py::ssize_t(3)});
            auto a = out.mutable_unchecked<2>();
            for (std::size_t t = 0; t < s.triangles.size(); ++t)
              for (int k = 0; k < 3; ++k) a(t, k) = s.triangles[t][k];
            return out;
          },
          "The triangles, an m x 3 int64 array of vertex indices (a copy).")
      .def("__repr__", [](const TriangleSurface& s) {
        return "<polydg.Surface: " + std::to_string(s.vertices.size()) + " vertices, " +
               std::to_string(s.triangles.size()) + " triangles>";
      });

  m.def(
      "read_surface",
      [](const std::string& path) {
        SurfaceReadInfo info;
        TriangleSurface s;
        {
          py::gil_scoped_release release;
          try {
            s = readSurface(path, &info);
          } catch (const std::runtime_error& e) {
            throw InputError(e.what());
          }
        }
        return py::make_tuple(s, info.warnings);
      },
      py::arg("path"));

  py::class_<Model>(m, "Model", py::dynamic_attr(),
                    "A simulation mesh with its cached integrals and provenance (polydg::Model).")
      .def_property_readonly(
          "points", [](const Model& model) { return pointsArray(model.mesh().positions().raw()); },
          "The mesh's points, an n x 3 float64 array (a copy).")
      .def_property_readonly(
          "num_elements", [](const Model& model) { return model.mesh().numElements(); },
          "The number of elements (polyhedra).")
      .def_property_readonly(
          "num_faces", [](const Model& model) { return model.mesh().numFaces(); },
          "The number of faces (each interior face once).")
      .def_property_readonly("volume", &Model::volume, "The sum of the element volumes.")
      .def_property_readonly(
          "element_volumes",
          [](Model& model) {
            const MomentCache& moments = model.moments();
            py::array_t<double> out(static_cast<py::ssize_t>(model.mesh().numElements()));
            auto a = out.mutable_unchecked<1>();
            for (std::size_t e = 0; e < model.mesh().numElements(); ++e)
              a(e) = moments.volume(ElementId(e));
            return out;
          },
          "The element volumes, a float64 array (exact moments; model units cubed).")
      .def_property_readonly(
          "element_centroids",
          [](Model& model) {
            const MomentCache& moments = model.moments();
            std::vector<Vec3> c(model.mesh().numElements());
            for (std::size_t e = 0; e < c.size(); ++e) c[e] = moments.centroid(ElementId(e));
            return pointsArray(c);
          },
          "The element centroids, an n x 3 float64 array.")
      .def_property_readonly(
          "faces",
          [](const Model& model) {
            const PolyMesh& mesh = model.mesh();
            const std::size_t n = mesh.numFaces();
            std::size_t corners = 0, loops = 0;
            for (const Face& face : mesh.faces()) {
              corners += face.vertices.size();
              loops += face.numLoops();
            }
            py::array_t<std::int64_t> vertices(static_cast<py::ssize_t>(corners));
            py::array_t<std::int64_t> loopOffsets(static_cast<py::ssize_t>(loops + 1));
            py::array_t<std::int64_t> faceLoops(static_cast<py::ssize_t>(n + 1));
            py::array_t<std::int64_t> elements({static_cast<py::ssize_t>(n), py::ssize_t(2)});
            auto v = vertices.mutable_unchecked<1>();
            auto lo = loopOffsets.mutable_unchecked<1>();
            auto fl = faceLoops.mutable_unchecked<1>();
            auto el = elements.mutable_unchecked<2>();
            std::size_t c = 0, l = 0;
            lo(0) = 0;
            for (std::size_t f = 0; f < n; ++f) {
              const Face& face = mesh.face(FaceId(f));
              fl(f) = static_cast<std::int64_t>(l);
              for (std::size_t k = 0; k < face.numLoops(); ++k) {
                for (VertexId x : face.loop(k)) v(c++) = x.value;
                lo(++l) = static_cast<std::int64_t>(c);
              }
              el(f, 0) = face.front.valid() ? std::int64_t(face.front.value) : -1;
              el(f, 1) = face.back.valid() ? std::int64_t(face.back.value) : -1;
            }
            fl(n) = static_cast<std::int64_t>(l);
            py::dict out;
            out["vertices"] = vertices;
            out["loop_offsets"] = loopOffsets;
            out["face_loops"] = faceLoops;
            out["elements"] = elements;
            return out;
          },
          "The faces as flat arrays (int64): loop j's point indices are "
          "vertices[loop_offsets[j]:loop_offsets[j + 1]], counter-clockwise about the normal "
          "pointing out of elements[f, 0]; face f's loops are face_loops[f]:face_loops[f + 1] "
          "(the outer loop first, then holes); elements[f] = (front, back), back -1 on the "
          "boundary.")
      .def_property_readonly(
          "element_displacements",
          [](const Model& model) -> py::object {
            const Solution* s = model.solution();
            if (!s) return py::none();
            return pointsArray(s->fields.meanDisplacement.raw());
          },
          "The last solve's mean displacement per element, an n x 3 float64 array (model "
          "units), or None before a solve and after an edit.")
      .def_property_readonly(
          "element_von_mises",
          [](const Model& model) -> py::object {
            const Solution* s = model.solution();
            if (!s) return py::none();
            const auto& vm = s->fields.vonMises.raw();
            py::array_t<double> out(static_cast<py::ssize_t>(vm.size()));
            std::copy(vm.begin(), vm.end(), out.mutable_data());
            return out;
          },
          "The last solve's von Mises stress per element (of the element's mean stress; units "
          "of E), or None before a solve and after an edit.")
      .def_property_readonly(
          "faces_integrated", &Model::facesIntegrated,
          "Faces integrated over the model's life (each integration of each face counts).")
      .def_property_readonly(
          "provenance", [](const Model& model) { return toPython(toJson(model.provenance())); },
          "Where the mesh came from and the scale of its sliver rule, as `polydg info` prints it: "
          "source, cell_size, reference_volume, reference, sliver_fraction, sliver_threshold.")
      .def("_cut",
           [](Model& model, const py::kwargs& kwargs) {
             return operate<CutStep>(
                 model, "cut", "Model.cut()", kwargs,
                 [](Model& m, const CutStep& s) { return editReport(m.cut(s.request)); });
           })
      .def("_merge_slivers",
           [](Model& model, const py::kwargs& kwargs) {
             return operate<MergeStep>(model, "merge", "Model.merge_slivers()", kwargs,
                                       [](Model& m, const MergeStep& s) {
                                         return editReport(m.mergeSlivers(s.request));
                                       });
           })
      .def(
          "_refine",
          [](Model& model, const std::vector<std::int64_t>& elements, const std::string& split,
             const std::optional<std::vector<std::array<double, 3>>>& directions,
             std::optional<double> mergeSlivers, const std::string& validate) {
            RefineRequest request;
            const auto kind = parseName(refineSplitNames(), split);
            if (!kind)
              throw InputError("split must be one of " + listNames(refineSplitNames()) + ", not '" +
                               split + "'");
            request.split = *kind;
            const auto level = parseName(checkLevelNames(), validate);
            if (!level)
              throw InputError("validate must be one of " + listNames(checkLevelNames()) +
                               ", not '" + validate + "'");
            request.checks = *level;
            for (std::int64_t e : elements) {
              if (e < 0 || e > std::numeric_limits<std::uint32_t>::max() - 1)
                throw InputError("element " + std::to_string(e) + " is not in the mesh");
              request.elements.push_back(ElementId(static_cast<std::uint32_t>(e)));
            }
            if (directions)
              for (const auto& d : *directions)
                request.directions.push_back(Vec3(d[0], d[1], d[2]));
            request.sliverFraction = mergeSlivers;
            RefineReport r;
            {
              py::gil_scoped_release release;
              r = model.refine(request);
            }
            if (!r.operation.check.passed)
              throw CheckFailure("refine failed: " + r.operation.check.failure);
            return toPython(toJson(r));
          },
          py::arg("elements"), py::arg("split") = "octants", py::arg("directions") = py::none(),
          py::arg("merge_slivers") = py::none(), py::arg("validate") = "local")
      .def(
          "_coarsen",
          [](Model& model, const std::vector<std::vector<std::int64_t>>& groups,
             const std::string& validate) {
            CoarsenRequest request;
            const auto level = parseName(checkLevelNames(), validate);
            if (!level)
              throw InputError("validate must be one of " + listNames(checkLevelNames()) +
                               ", not '" + validate + "'");
            request.checks = *level;
            for (const auto& group : groups) {
              request.groups.emplace_back();
              for (std::int64_t e : group) {
                if (e < 0 || e > std::numeric_limits<std::uint32_t>::max() - 1)
                  throw InputError("element " + std::to_string(e) + " is not in the mesh");
                request.groups.back().push_back(ElementId(static_cast<std::uint32_t>(e)));
              }
            }
            CoarsenReport r;
            {
              py::gil_scoped_release release;
              r = model.coarsen(request);
            }
            if (!r.operation.check.passed)
              throw CheckFailure("coarsen failed: " + r.operation.check.failure);
            nlohmann::json j = toJson(r.operation);
            j["solution_projected"] = r.solutionProjected;
            return toPython(j);
          },
          py::arg("groups"), py::arg("validate") = "local")
      .def("_check",
           [](Model& model, const py::kwargs& kwargs) {
             return operate<CheckStep>(
                 model, "check", "Model.check()", kwargs,
                 [](Model& m, const CheckStep& s) { return toJson(m.check(s.options)); });
           })
      .def("_solve",
           [](Model& model, const py::kwargs& kwargs) {
             return operate<SolveStep>(
                 model, "solve", "Model.solve()", kwargs,
                 [](Model& m, const SolveStep& s) { return toJson(m.solve(s.options)); });
           })
      .def_property_readonly(
          "coefficients",
          [](const Model& model) -> py::object {
            const Solution* s = model.solution();
            if (!s) return py::none();
            py::array_t<double> out(static_cast<py::ssize_t>(s->coefficients.size()));
            std::copy(s->coefficients.data(), s->coefficients.data() + s->coefficients.size(),
                      out.mutable_data());
            return out;
          },
          "The last solution's DG coefficients U (float64), in the layout U[(e * 3 + d) * n + i] "
          "(element e, component d, basis function i of n), or None before a solve and after an "
          "edit.")
      .def(
          "_embed",
          [](Model& model, const std::string& surface, int degree, double support, bool deformed) {
            EmbeddingOptions options;
            options.support = support;
            if (deformed && !model.solution())
              throw InputError("the model has no solution to deform the surface with; solve first");
            const int p = degree > 0         ? degree
                          : model.solution() ? model.solution()->basis->degree()
                                             : 1;
            EmbeddedSurface e;
            Eigen::Matrix<double, Eigen::Dynamic, 3> u;
            Eigen::SparseMatrix<double, Eigen::RowMajor, int> w;
            {
              py::gil_scoped_release release;
              e = model.embedSurface(surface, p, options);
              if (deformed)
                u = e.embedding->displacements(model.solution()->coefficients);
              else
                w = e.embedding->weights();
            }
            py::dict out;
            out["points"] = pointsArray(e.surface.vertices);
            py::array_t<std::int64_t> tris(
                {static_cast<py::ssize_t>(e.surface.triangles.size()), py::ssize_t(3)});
            auto t = tris.mutable_unchecked<2>();
            for (std::size_t k = 0; k < e.surface.triangles.size(); ++k)
              for (int j = 0; j < 3; ++j) t(k, j) = e.surface.triangles[k][j];
            out["triangles"] = tris;
            out["surface"] = e.file;
            out["degree"] = p;
            out["setup_seconds"] = e.embedding->setupSeconds();
            if (deformed) {
              py::array_t<double> disp({static_cast<py::ssize_t>(u.rows()), py::ssize_t(3)});
              auto d = disp.mutable_unchecked<2>();
              for (Eigen::Index i = 0; i < u.rows(); ++i)
                for (int j = 0; j < 3; ++j) d(i, j) = u(i, j);
              out["displacement"] = disp;
              return out;
            }
            // The scalar weights W (eq. 19) spread to the three components: row 3 v + d, column
            // (e * 3 + d) * n + i, so that u = W @ U.
            const std::size_t n = static_cast<std::size_t>(e.embedding->basisSize());
            const py::ssize_t nnz = static_cast<py::ssize_t>(3 * w.nonZeros());
            py::array_t<std::int64_t> rows(nnz), cols(nnz);
            py::array_t<double> values(nnz);
            auto r = rows.mutable_unchecked<1>();
            auto c = cols.mutable_unchecked<1>();
            auto v = values.mutable_unchecked<1>();
            py::ssize_t k = 0;
            for (int row = 0; row < w.outerSize(); ++row)
              for (Eigen::SparseMatrix<double, Eigen::RowMajor, int>::InnerIterator it(w, row); it;
                   ++it)
                for (std::size_t d = 0; d < 3; ++d, ++k) {
                  const std::size_t col = static_cast<std::size_t>(it.col());
                  r(k) = 3 * static_cast<std::int64_t>(row) + static_cast<std::int64_t>(d);
                  c(k) = static_cast<std::int64_t>(((col / n) * 3 + d) * n + col % n);
                  v(k) = it.value();
                }
            out["rows"] = rows;
            out["cols"] = cols;
            out["values"] = values;
            out["shape"] = py::make_tuple(3 * w.rows(), 3 * static_cast<py::ssize_t>(w.cols()));
            return out;
          },
          py::arg("surface"), py::arg("degree"), py::arg("support"), py::arg("deformed"))
      .def(
          "_simulate",
          [](Model& model, const py::object& scene, const std::string& output,
             const py::object& progress) {
            const Scene parsed = sceneOf(scene);
            SimulateOptions options;
            options.outputDir = output;
            GuardedCallback callback(progress);  // also without progress: Ctrl-C
            options.progress = [&callback](const SimulationProgress& p) {
              callback(p.step, p.steps, p.t);
            };
            std::optional<SimulationReport> report;
            try {
              py::gil_scoped_release release;
              report.emplace(model.simulate(parsed, options));
            } catch (const CallbackRaised&) {
              callback.reraise();
            }
            return toPython(toJson(*report));
          },
          py::arg("scene"), py::arg("output") = "", py::arg("progress") = py::none())
      .def(
          "_write",
          [](const Model& model, const std::string& path, bool solution) {
            WriteOptions options;
            options.solution = solution;
            WriteReport r;
            {
              py::gil_scoped_release release;
              r = model.write(path, options);
            }
            return toPython(toJson(r));
          },
          py::arg("path"), py::arg("solution") = true);

  m.def(
      "mesh",
      [](const TriangleSurface& surface, const py::dict& kwargs, const std::string& source,
         const py::object& progress) {
        MeshStep step = parseStep<MeshStep>("mesh", "polydg.mesh()", kwargs);
        // Guarded: an exception from the callback is re-raised as itself, whatever handlers
        // the slicing has on the way out (and Ctrl-C stops the slicing).
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
        if (!report.passed())
          throw CheckFailure("the new mesh failed: " + report.failures().front());
        return py::make_tuple(std::move(*model), toPython(toJson(report)));
      },
      py::arg("surface"), py::arg("kwargs"), py::arg("source") = "",
      py::arg("progress") = py::none());

  m.def(
      "read",
      [](const std::string& path) {
        ReadReport report;
        std::optional<Model> model;
        {
          py::gil_scoped_release release;
          model.emplace(Model::read(path, &report));
        }
        return py::make_tuple(std::move(*model), toPython(toJson(report)));
      },
      py::arg("path"));

  m.def(
      "run_input",
      [](const std::string& pipelineText, const std::string& pipelineFile, const std::string& base,
         const std::string& input, const std::string& stem, const std::string& out, int threads) {
        const Pipeline pipeline =
            parsePipeline(nlohmann::json::parse(pipelineText), pipelineFile, base);
        InputOutcome outcome;
        {
          py::gil_scoped_release release;
          // A Dask worker process runs as many tasks at once as it has threads; the parallel
          // parts of one input then get no more threads than that, as under `polydg run`.
          std::optional<tbb::global_control> limit;
          if (threads > 0)
            limit.emplace(tbb::global_control::max_allowed_parallelism,
                          static_cast<std::size_t>(threads));
          outcome = runPipelineInput(pipeline, input, stem, out);
        }
        return toPython(outcome.report);
      },
      py::arg("pipeline"), py::arg("pipeline_file"), py::arg("base"), py::arg("input"),
      py::arg("stem"), py::arg("out"), py::arg("threads") = 0);

  m.def(
      "check_pipeline",
      [](const std::string& pipelineText, const std::string& pipelineFile,
         const std::string& base) {
        nlohmann::json document;
        try {
          document = nlohmann::json::parse(pipelineText);
        } catch (const nlohmann::json::parse_error& e) {
          throw InputError(pipelineFile + ": not valid JSON (" + std::string(e.what()) + ")");
        }
        return parsePipeline(document, pipelineFile, base).inputs;
      },
      py::arg("pipeline"), py::arg("pipeline_file"), py::arg("base"));

  m.def("unique_stems", &uniqueStems, py::arg("inputs"));
  m.def(
      "refuse_inputs_in_outputs",
      [](const std::vector<std::string>& inputs, const std::vector<std::string>& stems,
         const std::string& out) { refuseInputsInOutputs(inputs, stems, out); },
      py::arg("inputs"), py::arg("stems"), py::arg("out"));
}
