// Writing command reports and other output files safely: to a temporary file beside the target,
// then renamed over it, so a failure never leaves a partial or clobbered file.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace polydg::cli {

/// An error meant for the user: one line saying what is wrong and what to do about it.
struct UserError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Writes `path` through `write(stream)` into "path.tmp-<pid>" and renames it into place.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

/// Writes `report` as indented JSON to `path` atomically.
void writeReport(const std::filesystem::path& path, const nlohmann::json& report);

/// Refuses to write an output over one of the inputs.
void requireDistinct(const std::filesystem::path& output, const std::filesystem::path& input);

}  // namespace polydg::cli
