#pragma once
// Logging and progress reporting, passed into the library functions (as OpenMVG passes its progress
// interface) so that algorithms never print by themselves and tests can run them silently.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace voroudf {

enum class LogLevel { kError = 0, kWarning = 1, kInfo = 2, kDebug = 3 };

class Monitor {
 public:
  virtual ~Monitor() = default;
  /// Thread-safe.
  virtual void Log(LogLevel level, const std::string& message) = 0;
  /// Starts a task of `total` units; only one task is active at a time.
  virtual void BeginTask(const std::string& name, uint64_t total) = 0;
  /// Thread-safe; may be called from inside parallel loops.
  virtual void Advance(uint64_t units) = 0;
  virtual void EndTask() = 0;

  void Info(const std::string& m) { Log(LogLevel::kInfo, m); }
  void Warn(const std::string& m) { Log(LogLevel::kWarning, m); }
  void Debug(const std::string& m) { Log(LogLevel::kDebug, m); }

  /// A monitor that drops everything (for tests and nested calls).
  static Monitor& Null();
};

/// RAII task: Begin on construction, End on destruction (also when an exception passes through).
class Task {
 public:
  Task(Monitor& monitor, const std::string& name, uint64_t total) : monitor_(monitor) {
    monitor_.BeginTask(name, total);
  }
  ~Task() { monitor_.EndTask(); }
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;
  void Advance(uint64_t units = 1) { monitor_.Advance(units); }

 private:
  Monitor& monitor_;
};

/// printf into a std::string, for log messages (any length).
std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));

/// Logs to stderr with the program name and elapsed time. Progress: a redrawn percentage on a terminal;
/// otherwise one line per 10 % once a task has run for more than two seconds (so pipelines' logs stay short).
class StderrMonitor : public Monitor {
 public:
  StderrMonitor(std::string program, LogLevel level);
  void Log(LogLevel level, const std::string& message) override;
  void BeginTask(const std::string& name, uint64_t total) override;
  void Advance(uint64_t units) override;
  void EndTask() override;

 private:
  void Report(uint64_t done, bool final);
  double Elapsed() const;

  std::string program_;
  LogLevel level_;
  bool tty_;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_;
  // Current task.
  std::string task_;
  uint64_t total_ = 0;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point task_start_;
  double last_draw_ = -1.0;
  int last_decile_ = 0;
  bool line_open_ = false;
};

}  // namespace voroudf
