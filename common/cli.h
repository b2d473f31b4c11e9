#pragma once
// Program conventions shared by every stage (docs/conventions.md): CLI11 options with generated --help,
// long kebab-case flags, -i/-o/--udf/--seed/--threads/-v/-q, the echo of the effective options, logs and
// progress on stderr, and one top-level handler that turns typed errors into one line and an exit code.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "common/counting_udf.h"
#include "common/monitor.h"
#include "common/provenance.h"
#include "common/udf_spec.h"

namespace voroudf {

class StageCli {
 public:
  StageCli(std::string program, std::string description);

  CLI::App& app() { return app_; }

  /// -i/--input (required). `-` reads stdin.
  CLI::Option* AddInput(std::string* path, const std::string& description);
  /// A further input file (e.g. --reference); `-` reads stdin, which at most one input may do.
  CLI::Option* AddExtraInput(const std::string& flag, std::string* path, const std::string& description);
  /// -o/--output (required). Its temporary file is created before any work starts; `-` writes stdout.
  CLI::Option* AddOutput(std::string* path, const std::string& description);
  /// An extra optional output file (e.g. --labels), handled like -o when given. All outputs of a stage are
  /// published together or not at all (common/atomic_file.h).
  CLI::Option* AddExtraOutput(const std::string& flag, std::string* path, const std::string& description);
  /// Leaves an already added option (by its long name, e.g. "--trace") out of the provenance's option list:
  /// for options that do not change the results, such as debugging output.
  void MarkNonSemantic(const std::string& flag);
  /// --udf SPEC (required) plus the source options --udf-box, --udf-timeout, --udf-normalize and the output
  /// --udf-stats FILE (the queries made, common/counting_udf.h; also logged at the end).
  CLI::Option* AddUdf(std::string* spec);
  /// --seed for the random number generator.
  CLI::Option* AddSeed(uint64_t* seed);
  /// --ascii: write PLY as ASCII instead of binary little-endian.
  CLI::Option* AddAscii(bool* ascii);

  const UdfSourceOptions& udf_options() const { return udf_options_; }

  /// Opens the --udf source with the source options and logs what it is (every stage's first step). The
  /// source is wrapped in a CountingUdf: Run logs its usage after the body (and writes --udf-stats).
  /// \pre AddUdf was called and the command line parsed
  std::unique_ptr<Udf> OpenUdf(Monitor& monitor) const;

  /// Provenance for output headers: the program, its result-changing options and the UDF SPEC.
  Provenance provenance() const;

  /// Parses argv, refusing numbers that do not fit their option (a sign on an unsigned option, digits
  /// past its type, a non-finite real); sets threads and verbosity; runs `check` (option validation, may
  /// throw UsageError); creates the outputs' temporary files (OutputSet); echoes the effective options;
  /// runs `body`, whose writes of the outputs go into the set; publishes the set. Returns the exit code.
  int Run(int argc, char** argv, const std::function<void()>& check, const std::function<void(Monitor&)>& body);

 private:
  std::string EffectiveOptions(bool semantic_only) const;

  std::string program_;
  CLI::App app_;
  int threads_ = 0;
  bool verbose_ = false;
  bool quiet_ = false;
  std::string* udf_spec_ = nullptr;
  UdfSourceOptions udf_options_;
  std::string udf_stats_path_;
  std::shared_ptr<UdfUsage> udf_usage_ = std::make_shared<UdfUsage>();
  mutable bool udf_opened_ = false;
  void CheckBeforeWork() const;

  std::vector<std::string*> inputs_;
  std::vector<std::string*> outputs_;
  std::set<std::string> non_semantic_;  ///< options that do not change results (left out of provenance)
};

}  // namespace voroudf
