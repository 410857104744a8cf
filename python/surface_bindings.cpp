// polydg.Surface (a triangle surface as numpy arrays) and polydg.read_surface.
#include <pybind11/stl.h>

#include <array>

#include "bindings.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/util/error.h"

namespace polydg::python {

namespace {

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

}  // namespace

void bindSurface(py::module_& m) {
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
          "F", [](const TriangleSurface& s) { return trianglesArray(s.triangles); },
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
}

}  // namespace polydg::python
