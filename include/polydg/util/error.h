// The errors polydg reports to its users: each carries one line saying what is wrong and what
// to do about it. Front ends map them to exit codes (the CLI) or to polydg.Error (Python).
#pragma once

#include <stdexcept>
#include <string>

namespace polydg {

/// An error meant for the user: one line naming the problem and what to do about it.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Input polydg refuses: a file, an option value or a request that cannot be carried out as
/// given (the CLI exits with 2). Nothing was changed or written.
struct InputError : Error {
  using Error::Error;
};

/// An output polydg cannot write: its folder is missing or not writable, or the write failed.
/// An InputError (the CLI exits with 2), whose message names the output, never an input.
struct OutputError : InputError {
  using InputError::InputError;
};

/// A value an option may not take, named by its key in the formats users write (the keys of
/// scenes, pipelines and Python: "E", "degree", "dt", "damping.mass"). The option's own check
/// throws it; each front end says where the value came from (a file and its place, a
/// command-line option).
struct InvalidOption : std::invalid_argument {
  InvalidOption(std::string key_, std::string problem_)
      : std::invalid_argument(key_ + ": " + problem_),
        key(std::move(key_)),
        problem(std::move(problem_)) {}
  std::string key;      ///< "E", "damping.mass", ...
  std::string problem;  ///< "Young's modulus must be a positive number"
};

/// An operation that ran but whose result failed a check, or left nothing (the CLI exits
/// with 1). Its outputs were not written.
struct CheckFailure : Error {
  using Error::Error;
};

}  // namespace polydg
