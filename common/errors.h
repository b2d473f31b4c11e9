#pragma once
// Typed errors. Every failure of a stage ends in one of these; the top-level handler in cli.h turns it
// into one line on stderr and the documented exit code.
#include <stdexcept>
#include <string>

namespace voroudf {

/// Exit codes shared by every program (docs/conventions.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,   ///< anything else (I/O failure writing output, out of memory, internal error)
  kExitUsage = 2,     ///< bad option or option value
  kExitBadInput = 3,  ///< unreadable, malformed or wrong kind of input (files, UDF sources)
  kExitNumerical = 4, ///< numerical failure (e.g. no seed reached the surface)
};

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  virtual int exit_code() const { return kExitFailure; }
};

/// A bad option value, found before any work is done.
class UsageError : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitUsage; }
};

/// Input that cannot be used: the message names the file (or UDF source) and what is wrong.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(message) {}
  InputError(const std::string& source, const std::string& problem) : Error(source + ": " + problem) {}
  int exit_code() const override { return kExitBadInput; }
};

/// The numbers did not work out: nothing converged, nothing reached the surface.
class NumericalError : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitNumerical; }
};

/// Output could not be written (exit code 1).
class OutputError : public Error {
 public:
  OutputError(const std::string& path, const std::string& problem) : Error(path + ": " + problem) {}
};

}  // namespace voroudf
