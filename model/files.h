// Writing output files safely: to a temporary file beside the target, then renamed over it, so
// a failure never leaves a partial or clobbered file; and the guard that keeps an output from
// replacing an input.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

#include <nlohmann/json.hpp>

namespace polydg {

/// Writes `path` through `write(stream)` into "path.tmp-<pid>" and renames it into place.
/// Throws InputError ("cannot write PATH: reason; ...") if the file cannot be written.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

/// Writes `document` as indented JSON to `path`, atomically.
void writeJsonFile(const std::filesystem::path& path, const nlohmann::json& document);

/// Throws InputError if the file `output` could not be written where it is to go: its folder
/// does not exist or is not writable, or `output` is a folder. Called before the work whose
/// result the file holds, so that a mistyped path costs nothing and leaves nothing half done.
void requireWritable(const std::filesystem::path& output);

/// Throws InputError if `output` is the file `input` (the same file by any path, including
/// links), so that no command ever overwrites its input.
void requireDistinct(const std::filesystem::path& output, const std::filesystem::path& input);

}  // namespace polydg
