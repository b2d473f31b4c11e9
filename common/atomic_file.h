#pragma once
// Output files appear whole or not at all: written to a hidden temporary file beside the target, then
// renamed over it. A failed stage leaves no partial file; SIGINT/SIGTERM remove the temporary file too.
#include <string>

namespace voroudf {

/// Writes `contents` to `path` atomically. Throws OutputError (exit code 1) if it cannot.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Throws OutputError if `path` could not be created: its directory is missing or not writable, or it
/// names a directory. Called before long work so a typo in -o fails at once.
void CheckWritable(const std::string& path);

/// Installs SIGINT/SIGTERM/SIGHUP handlers that delete the temporary file being written, if any,
/// then end the process with the signal's default action.
void InstallTemporaryFileCleanup();

}  // namespace voroudf
