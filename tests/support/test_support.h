#pragma once
// Helpers for the test suites: temporary directories, running the real executables, file bytes.
#include <string>
#include <vector>

namespace voroudf::test {

/// A fresh directory under $TMPDIR, removed with its contents when the object goes.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }
  /// Every entry in the directory, hidden ones included (to prove no temporary file was left behind).
  std::vector<std::string> List() const;

 private:
  std::string path_;
};

struct RunResult {
  int exit_code = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

/// Runs bin/<program> from the build tree with `args` (no shell); captures stdout and stderr.
RunResult RunProgram(const std::string& program, const std::vector<std::string>& args);

std::string ReadBytes(const std::string& path);
void WriteBytes(const std::string& path, const std::string& bytes);
bool Exists(const std::string& path);

}  // namespace voroudf::test
