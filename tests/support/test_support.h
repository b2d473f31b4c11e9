#pragma once
// Helpers for the test suites: temporary directories, running the real executables, file bytes.
#include <string>
#include <vector>

#include "common/types.h"

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

/// Coefficient of variation of the points' nearest-neighbour distances (the spacing's evenness; about 0.52
/// for uniform random points on a surface); `*mean_out`, if given, receives their mean. O(n²).
double NearestNeighbourCv(const std::vector<Vec3>& p, double* mean_out = nullptr);

}  // namespace voroudf::test
