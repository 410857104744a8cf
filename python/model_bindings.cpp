// polydg.Model: a simulation mesh with its cached integrals, its arrays, and its operations
// (edits, checks, solves, the embedded surface, simulation, writing).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <limits>

#include "bindings.h"
#include "polydg/model/names.h"
#include "polydg/model/report_json.h"
#include "polydg/model/scene.h"
#include "polydg/util/error.h"

namespace polydg::python {

namespace {

using ModelClass = py::class_<Model>;

/// Face f's loops and elements as flat int64 arrays (see Model.faces).
py::dict faceArrays(const PolyMesh& mesh) {
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
}

/// A float64 copy of `values`.
template <class Range>
py::array_t<double> valuesArray(const Range& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

void bindArrays(ModelClass& c) {
  c.def_property_readonly(
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
            std::vector<double> v(model.mesh().numElements());
            for (std::size_t e = 0; e < v.size(); ++e) v[e] = moments.volume(ElementId(e));
            return valuesArray(v);
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
          "faces", [](const Model& model) { return faceArrays(model.mesh()); },
          "The faces as flat arrays (int64): loop j's point indices are "
          "vertices[loop_offsets[j]:loop_offsets[j + 1]], counter-clockwise about the normal "
          "pointing out of elements[f, 0]; face f's loops are face_loops[f]:face_loops[f + 1] "
          "(the outer loop first, then holes); elements[f] = (front, back), back -1 on the "
          "boundary.")
      .def_property_readonly(
          "faces_integrated", &Model::facesIntegrated,
          "Faces integrated over the model's life (each integration of each face counts).")
      .def_property_readonly(
          "provenance", [](const Model& model) { return toPython(toJson(model.provenance())); },
          "Where the mesh came from and the scale of its sliver rule, as `polydg info` prints it: "
          "source, cell_size, reference_volume, reference, sliver_fraction, sliver_threshold.");
}

void bindSolutionArrays(ModelClass& c) {
  c.def_property_readonly(
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
            return valuesArray(s->fields.vonMises.raw());
          },
          "The last solve's von Mises stress per element (of the element's mean stress; units "
          "of E), or None before a solve and after an edit.")
      .def_property_readonly(
          "coefficients",
          [](const Model& model) -> py::object {
            const Solution* s = model.solution();
            if (!s) return py::none();
            return valuesArray(s->coefficients);
          },
          "The last solution's DG coefficients U (float64), in the layout U[(e * 3 + d) * n + i] "
          "(element e, component d, basis function i of n), or None before a solve and after an "
          "edit.");
}

CheckLevel checkLevelOf(const std::string& validate) {
  const auto level = parseName(checkLevelNames(), validate);
  if (!level)
    throw InputError("validate must be one of " + listNames(checkLevelNames()) + ", not '" +
                     validate + "'");
  return *level;
}

ElementId elementOf(std::int64_t e) {
  if (e < 0 || e > std::numeric_limits<std::uint32_t>::max() - 1)
    throw InputError("element " + std::to_string(e) + " is not in the mesh");
  return ElementId(static_cast<std::uint32_t>(e));
}

py::object refine(Model& model, const std::vector<std::int64_t>& elements, const std::string& split,
                  const std::optional<std::vector<std::array<double, 3>>>& directions,
                  std::optional<double> mergeSlivers, const std::string& validate) {
  RefineRequest request;
  const auto kind = parseName(refineSplitNames(), split);
  if (!kind)
    throw InputError("split must be one of " + listNames(refineSplitNames()) + ", not '" + split +
                     "'");
  request.split = *kind;
  request.checks = checkLevelOf(validate);
  for (std::int64_t e : elements) request.elements.push_back(elementOf(e));
  if (directions)
    for (const auto& d : *directions) request.directions.push_back(Vec3(d[0], d[1], d[2]));
  request.sliverFraction = mergeSlivers;
  RefineReport r;
  {
    py::gil_scoped_release release;
    r = model.refine(request);
  }
  if (!r.operation.check.passed) throw CheckFailure("refine failed: " + r.operation.check.failure);
  return toPython(toJson(r));
}

py::object coarsen(Model& model, const std::vector<std::vector<std::int64_t>>& groups,
                   const std::string& validate) {
  CoarsenRequest request;
  request.checks = checkLevelOf(validate);
  for (const auto& group : groups) {
    request.groups.emplace_back();
    for (std::int64_t e : group) request.groups.back().push_back(elementOf(e));
  }
  CoarsenReport r;
  {
    py::gil_scoped_release release;
    r = model.coarsen(request);
  }
  if (!r.operation.check.passed) throw CheckFailure("coarsen failed: " + r.operation.check.failure);
  nlohmann::json j = toJson(r.operation);
  j["solution_projected"] = r.solutionProjected;
  return toPython(j);
}

void bindOperations(ModelClass& c) {
  c.def("_cut",
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
      .def("_refine", &refine, py::arg("elements"), py::arg("split") = "octants",
           py::arg("directions") = py::none(), py::arg("merge_slivers") = py::none(),
           py::arg("validate") = "local")
      .def("_coarsen", &coarsen, py::arg("groups"), py::arg("validate") = "local")
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
      .def("_export",
           [](Model& model, const std::string& folder, const py::kwargs& kwargs) {
             // The step's own path must be relative (a pipeline's); Python's folder is any path.
             py::dict step(kwargs);
             step["path"] = "case";
             return operate<ExportStep>(
                 model, "export", "Model.export()", step, [&folder](Model& m, const ExportStep& s) {
                   nlohmann::json r = toJson(m.exportOpenFoam(folder, s.options));
                   return r;
                 });
           })
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
}

/// The scalar weights W (eq. 19) spread to the three components as a sparse triple: row 3 v + d,
/// column (e * 3 + d) * n + i, so that u = W @ U.
void addWeights(py::dict& out, const Eigen::SparseMatrix<double, Eigen::RowMajor, int>& w,
                std::size_t n) {
  const py::ssize_t nnz = static_cast<py::ssize_t>(3 * w.nonZeros());
  py::array_t<std::int64_t> rows(nnz), cols(nnz);
  py::array_t<double> values(nnz);
  auto r = rows.mutable_unchecked<1>();
  auto c = cols.mutable_unchecked<1>();
  auto v = values.mutable_unchecked<1>();
  py::ssize_t k = 0;
  for (int row = 0; row < w.outerSize(); ++row)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor, int>::InnerIterator it(w, row); it; ++it)
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
}

/// The embedded surface (python/polydg: Model.embedding_weights, Model.deformed_surface).
py::dict embed(Model& model, const std::string& surface, int degree, double support,
               bool deformed) {
  EmbeddingOptions options;
  options.support = support;
  if (deformed && !model.solution())
    throw InputError("the model has no solution to deform the surface with; solve first");
  const int p = degree > 0 ? degree : model.solution() ? model.solution()->basis->degree() : 1;
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
  out["triangles"] = trianglesArray(e.surface.triangles);
  out["surface"] = e.file;
  out["degree"] = p;
  out["setup_seconds"] = e.embedding->setupSeconds();
  if (deformed) {
    py::array_t<double> disp({static_cast<py::ssize_t>(u.rows()), py::ssize_t(3)});
    auto d = disp.mutable_unchecked<2>();
    for (Eigen::Index i = 0; i < u.rows(); ++i)
      for (int j = 0; j < 3; ++j) d(i, j) = u(i, j);
    out["displacement"] = disp;
  } else {
    addWeights(out, w, static_cast<std::size_t>(e.embedding->basisSize()));
  }
  return out;
}

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
        "format in docs/guide.md");
  }
  return parseScene(document, "scene");
}

py::object simulate(Model& model, const py::object& scene, const std::string& output,
                    const py::object& progress) {
  const Scene parsed = sceneOf(scene);
  SimulateOptions options;
  options.outputDir = output;
  GuardedCallback callback(progress);  // also without progress: Ctrl-C
  options.progress = [&callback](const SimulationProgress& p) { callback(p.step, p.steps, p.t); };
  std::optional<SimulationReport> report;
  try {
    py::gil_scoped_release release;
    report.emplace(model.simulate(parsed, options));
  } catch (const CallbackRaised&) {
    callback.reraise();
  }
  return toPython(toJson(*report));
}

}  // namespace

void bindModel(py::module_& m) {
  ModelClass c(m, "Model", py::dynamic_attr(),
               "A simulation mesh with its cached integrals and provenance (polydg::Model).");
  bindArrays(c);
  bindSolutionArrays(c);
  bindOperations(c);
  c.def("_embed", &embed, py::arg("surface"), py::arg("degree"), py::arg("support"),
        py::arg("deformed"));
  c.def("_simulate", &simulate, py::arg("scene"), py::arg("output") = "",
        py::arg("progress") = py::none());
}

}  // namespace polydg::python
