#include "common/cli.h"

#include <omp.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <sstream>

#include "common/atomic_file.h"
#include "common/cleanup.h"
#include "common/errors.h"
#include "common/huge_pages.h"
#include "common/shapes.h"

namespace voroudf {
namespace {

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string Quoted(const std::string& s) {
  if (!s.empty() && s.find_first_of(" \t'\"$;&|<>()") == std::string::npos) return s;
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

constexpr int kMaxThreads = 1024;
constexpr double kMaxTimeout_s = 1e6;

// CLI11 converts integers with strtoull/strtoll in base 0 and keeps what they clamp: "-5" becomes
// 2^64 - 5 in an unsigned option, "010" is octal 8 and 1e30 digits become the type's maximum. Every
// numeric option is checked first, as decimal text that fits: one readable line instead.
CLI::Validator NumberCheck(const std::string& type) {
  return CLI::Validator(
      [type](std::string& text) -> std::string {
        const char* s = text.c_str();
        char* end = nullptr;
        errno = 0;
        if (type == "FLOAT") {
          const double v = std::strtod(s, &end);
          if (end == s || end != s + text.size()) return "'" + text + "' is not a number";
          if (!std::isfinite(v) || (errno == ERANGE && std::abs(v) > 1)) return "'" + text + "' is not a finite number";
          return "";
        }
        const bool is_unsigned = type == "UINT";
        size_t digits = (s[0] == '+' || (!is_unsigned && s[0] == '-')) ? 1 : 0;
        if (text.size() == digits || text.find_first_not_of("0123456789", digits) != std::string::npos)
          return "'" + text + "' is not " + (is_unsigned ? "a non-negative integer" : "an integer");
        if (is_unsigned) std::strtoull(s, &end, 10);
        else std::strtoll(s, &end, 10);
        if (errno == ERANGE) return "'" + text + "' is out of range";
        // Strip leading zeros so that CLI11's base-0 conversion reads decimal, never octal.
        while (text.size() > digits + 1 && text[digits] == '0') text.erase(digits, 1);
        return "";
      },
      "");
}

}  // namespace

StageCli::StageCli(std::string program, std::string description)
    : program_(std::move(program)), app_(std::move(description), program_) {
  app_.option_defaults()->always_capture_default();
  app_.get_formatter()->column_width(34);
  app_.add_option("--threads", threads_, "worker threads (0: all cores, at most 1024)");
  app_.add_flag("-v,--verbose", verbose_, "log details (debug level)");
  app_.add_flag("-q,--quiet", quiet_, "log errors only");
  non_semantic_ = {"--threads", "--verbose", "--quiet", "--help", "--output", "--input"};
}

CLI::Option* StageCli::AddInput(std::string* path, const std::string& description) {
  inputs_.push_back(path);
  return app_.add_option("-i,--input", *path, description)->required();
}

CLI::Option* StageCli::AddExtraInput(const std::string& flag, std::string* path, const std::string& description) {
  inputs_.push_back(path);
  CLI::Option* opt = app_.add_option(flag, *path, description);
  non_semantic_.insert(opt->get_name());
  return opt;
}

CLI::Option* StageCli::AddOutput(std::string* path, const std::string& description) {
  outputs_.push_back(path);
  return app_.add_option("-o,--output", *path, description)->required();
}

CLI::Option* StageCli::AddExtraOutput(const std::string& flag, std::string* path, const std::string& description) {
  outputs_.push_back(path);
  CLI::Option* opt = app_.add_option(flag, *path, description);
  non_semantic_.insert(opt->get_name());
  return opt;
}

void StageCli::MarkNonSemantic(const std::string& flag) { non_semantic_.insert(flag); }

CLI::Option* StageCli::AddUdf(std::string* spec) {
  udf_spec_ = spec;
  std::string names;
  for (const auto& [name, description] : ShapeCatalog()) names += (names.empty() ? "" : " ") + name;
  CLI::Option* opt = app_.add_option(
      "--udf", *spec,
      "UDF source: shape:NAME (" + names + "), a mesh .obj/.off/.ply/.stl, a grid .npy, exec:COMMAND, "
      "unix:SOCKET (a running server), or noisy:value=S,grad=A:SPEC (SPEC with errors, docs/udf-sources.md)");
  opt->required();
  app_.add_option("--udf-box", udf_options_.grid_box, "domain box of a .npy grid: xmin,ymin,zmin,xmax,ymax,zmax");
  app_.add_option("--udf-timeout", udf_options_.exec_timeout_s,
                  "seconds to wait for an exec: or unix: source's answer (in (0, 1e6])");
  app_.add_flag("--udf-normalize", udf_options_.normalize,
                "centre the source's box (a mesh's bbox) on the origin and scale its largest extent to 1; "
                "outputs are in that frame");
  non_semantic_.insert("--udf-timeout");
  non_semantic_.insert("--udf");  // recorded on its own provenance line
  AddExtraOutput("--udf-stats", &udf_stats_path_,
                 "also write the UDF queries, batches and seconds inside the UDF to this TSV file");
  return opt;
}

CLI::Option* StageCli::AddSeed(uint64_t* seed) {
  return app_.add_option("--seed", *seed, "seed of the random number generator");
}

CLI::Option* StageCli::AddAscii(bool* ascii) {
  CLI::Option* opt = app_.add_flag("--ascii", *ascii, "write PLY output as ASCII (default: binary little-endian)");
  non_semantic_.insert("--ascii");
  return opt;
}

std::string StageCli::EffectiveOptions(bool semantic_only) const {
  std::ostringstream out;
  bool first = true;
  for (const CLI::Option* opt : app_.get_options()) {
    if (!opt->nonpositional()) continue;
    const std::string name = opt->get_name();
    if (name == "--help" || (semantic_only && non_semantic_.count(name))) continue;
    const bool is_flag = opt->get_expected_max() == 0;  // add_flag: takes no value
    std::string value;
    if (opt->count() > 0) {
      for (const auto& r : opt->results()) value += (value.empty() ? "" : " ") + Quoted(r);
    } else {
      value = opt->get_default_str();
    }
    if (is_flag) {
      if (opt->count() == 0) continue;
      value.clear();
    } else if (value.empty()) {
      continue;
    }
    out << (first ? "" : " ") << name << (value.empty() ? "" : " " + value);
    first = false;
  }
  return out.str();
}

std::unique_ptr<Udf> StageCli::OpenUdf(Monitor& monitor) const {
  std::unique_ptr<Udf> udf = voroudf::OpenUdf(*udf_spec_, udf_options_);
  monitor.Info("UDF: " + udf->Describe());
  udf_opened_ = true;
  return std::make_unique<CountingUdf>(std::move(udf), udf_usage_);
}

Provenance StageCli::provenance() const {
  return Provenance{program_, EffectiveOptions(true), udf_spec_ ? *udf_spec_ : std::string()};
}

void StageCli::CheckBeforeWork() const {
  if (threads_ < 0 || threads_ > kMaxThreads)
    throw UsageError("--threads must be in [0, " + std::to_string(kMaxThreads) + "] (0: all cores), got " +
                     std::to_string(threads_));
  if (udf_spec_ != nullptr) {
    if (!(udf_options_.exec_timeout_s > 0 && udf_options_.exec_timeout_s <= kMaxTimeout_s))
      throw UsageError("--udf-timeout must be in (0, 1e6] seconds");
    if (!udf_options_.grid_box.empty() && !udf_spec_->empty() && ClassifyUdfSpec(BaseUdfSpec(*udf_spec_)) != UdfSourceKind::kGrid)
      throw UsageError("--udf-box applies to a .npy grid source only, not to '" + *udf_spec_ + "'");
  }
  int stdin_inputs = 0;
  for (const std::string* in : inputs_) stdin_inputs += *in == "-";
  if (stdin_inputs > 1) throw UsageError("only one input can be read from stdin ('-')");
}

int StageCli::Run(int argc, char** argv, const std::function<void()>& check,
                  const std::function<void(Monitor&)>& body) {
  for (CLI::Option* opt : app_.get_options()) {
    const std::string type = opt->get_type_name().substr(0, opt->get_type_name().find(':'));
    if (type == "UINT" || type == "INT" || type == "FLOAT") opt->transform(NumberCheck(type));  // may rewrite
  }
  try {
    app_.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app_.exit(e);  // --help: prints the help, exit code 0
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: error: %s (see %s --help)\n", program_.c_str(), OneLine(e.what()).c_str(),
                 program_.c_str());
    return kExitUsage;
  }
  const bool huge_pages = StartWithHugePages(argv);  // may start the program again, with the same arguments
  InstallCleanupHandlers();
  StderrMonitor monitor(program_, quiet_ ? LogLevel::kError : verbose_ ? LogLevel::kDebug : LogLevel::kInfo);
  if (huge_pages) monitor.Debug("heap in transparent huge pages (started again with glibc.malloc.hugetlb=1)");
  try {
    CheckBeforeWork();
    if (threads_ > 0) omp_set_num_threads(threads_);
    check();
    OutputSet outputs;
    for (const std::string* out : outputs_)
      if (!out->empty()) outputs.Add(*out);
    SetActiveOutputSet(&outputs);
    monitor.Info(program_ + " " + EffectiveOptions(false) + "  [" + std::to_string(omp_get_max_threads()) +
                 " threads]");
    body(monitor);
    if (udf_opened_) {
      monitor.Info("UDF usage: " + udf_usage_->Summary());
      if (!udf_stats_path_.empty()) WriteFileAtomically(udf_stats_path_, udf_usage_->Tsv());
    }
    outputs.Commit();
    SetActiveOutputSet(nullptr);
    return kExitOk;
  } catch (const Error& e) {
    SetActiveOutputSet(nullptr);
    std::fprintf(stderr, "%s: error: %s\n", program_.c_str(), OneLine(e.what()).c_str());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    SetActiveOutputSet(nullptr);
    std::fprintf(stderr, "%s: error: out of memory\n", program_.c_str());
    return kExitFailure;
  } catch (const std::exception& e) {
    SetActiveOutputSet(nullptr);
    std::fprintf(stderr, "%s: error: internal: %s\n", program_.c_str(), OneLine(e.what()).c_str());
    return kExitFailure;
  }
}

}  // namespace voroudf
