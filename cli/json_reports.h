// JSON forms of the library's reports, shared by the subcommands' --report files.
#pragma once

#include <nlohmann/json.hpp>

#include "mesh/meshing.h"
#include "mesh/validate.h"

namespace polydg::cli {

nlohmann::json toJson(const ValidationReport& r);
nlohmann::json toJson(const Box3& box);
/// The `polydg mesh` report: input, output, volume_rel_error, validation, timings_s.
nlohmann::json toJson(const MeshingReport& r);

}  // namespace polydg::cli
