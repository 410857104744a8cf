// Writing output files safely: to a temporary file beside the target, then renamed over it, so
// a failure never leaves a partial or clobbered file; and the guard that keeps an output from
// replacing an input.
#pragma once

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <ostream>

#include <nlohmann/json.hpp>

namespace polydg {

/// Writes `path` through `write(stream)` into "path.tmp-<pid>" and renames it into place.
/// Throws OutputError ("cannot write PATH: reason; ...") if the file cannot be written.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

/// Writes `document` as indented JSON to `path`, atomically.
void writeJsonFile(const std::filesystem::path& path, const nlohmann::json& document);

/// Throws OutputError if the file `output` could not be written where it is to go: its folder
/// does not exist or is not writable, or `output` is a folder. Called before the work whose
/// result the file holds, so that a mistyped path costs nothing and leaves nothing half done.
void requireWritable(const std::filesystem::path& output);

/// The checks of an output file, made before the work: throws InputError if `output` is one of
/// `inputs` (the same file by any path, including links; an empty or missing input is none), so
/// that no command ever overwrites its input, and then as requireWritable() does.
void requireOutput(const std::filesystem::path& output,
                   std::initializer_list<std::filesystem::path> inputs);

}  // namespace polydg
