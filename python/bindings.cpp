#include "bindings.h"

#include "polydg/model/report_json.h"
#include "polydg/util/error.h"

namespace polydg::python {

py::object toPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json jsonOf(const py::handle& value) {
  const std::string text = py::str(py::module_::import("json").attr("dumps")(value));
  return nlohmann::json::parse(text);
}

nlohmann::json stepObject(const char* step, const py::dict& kwargs) {
  nlohmann::json object = nlohmann::json::object();
  object["step"] = step;
  for (const auto& [key, value] : kwargs)
    if (!value.is_none()) object[py::str(key).cast<std::string>()] = jsonOf(value);
  return object;
}

nlohmann::json editReport(const OperationReport& r) {
  if (!r.check.passed) throw CheckFailure(r.op + " failed: " + r.check.failure);
  return toJson(r);
}

py::array_t<double> pointsArray(const std::vector<Vec3>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t(3)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) a(i, k) = points[i][k];
  return out;
}

py::array_t<std::int64_t> trianglesArray(const std::vector<std::array<std::uint32_t, 3>>& t) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(t.size()), py::ssize_t(3)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t k = 0; k < t.size(); ++k)
    for (int j = 0; j < 3; ++j) a(k, j) = t[k][j];
  return out;
}

void bindErrors(py::module_& m) {
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
}

}  // namespace polydg::python
