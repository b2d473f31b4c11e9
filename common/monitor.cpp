#include "common/monitor.h"

#include <unistd.h>

#include <cstdarg>
#include <cstdio>

namespace voroudf {

std::string Format(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string out(size > 0 ? static_cast<size_t>(size) : 0, '\0');
  if (size > 0) std::vsnprintf(out.data(), out.size() + 1, format, again);
  va_end(again);
  return out;
}

namespace {

class NullMonitor : public Monitor {
 public:
  void Log(LogLevel, const std::string&) override {}
  void BeginTask(const std::string&, uint64_t) override {}
  void Advance(uint64_t) override {}
  void EndTask() override {}
};

const char* LevelTag(LogLevel level) {
  switch (level) {
    case LogLevel::kError: return "error: ";
    case LogLevel::kWarning: return "warning: ";
    default: return "";
  }
}

}  // namespace

Monitor& Monitor::Null() {
  static NullMonitor null_monitor;
  return null_monitor;
}

StderrMonitor::StderrMonitor(std::string program, LogLevel level)
    : program_(std::move(program)), level_(level), tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {}

double StderrMonitor::Elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void StderrMonitor::Log(LogLevel level, const std::string& message) {
  if (level > level_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (line_open_) {
    std::fputc('\n', stderr);
    line_open_ = false;
  }
  std::fprintf(stderr, "[%s %7.2fs] %s%s\n", program_.c_str(), Elapsed(), LevelTag(level), message.c_str());
  std::fflush(stderr);
}

void StderrMonitor::BeginTask(const std::string& name, uint64_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  task_ = name;
  total_ = total;
  done_ = 0;
  task_start_ = std::chrono::steady_clock::now();
  last_draw_ = -1.0;
  last_decile_ = 0;
}

void StderrMonitor::Advance(uint64_t units) {
  const uint64_t done = done_.fetch_add(units) + units;
  if (level_ < LogLevel::kInfo || total_ == 0) return;
  // Cheap check first: most calls return here without taking the lock.
  const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - task_start_).count();
  if (tty_ ? since - last_draw_ < 0.1 : since < 2.0) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  if (tty_) {
    last_draw_ = since;
    Report(done, false);
  } else {
    const int decile = static_cast<int>(10 * done / total_);
    if (decile > last_decile_) {
      last_decile_ = decile;
      Report(done, false);
    }
  }
}

void StderrMonitor::Report(uint64_t done, bool final) {
  const double pct = total_ ? 100.0 * static_cast<double>(std::min(done, total_)) / static_cast<double>(total_) : 100.0;
  if (tty_) {
    std::fprintf(stderr, "\r[%s %7.2fs] %s: %5.1f%% (%llu/%llu)%s", program_.c_str(), Elapsed(), task_.c_str(), pct,
                 static_cast<unsigned long long>(done), static_cast<unsigned long long>(total_), final ? "\n" : "");
    line_open_ = !final;
  } else {
    std::fprintf(stderr, "[%s %7.2fs] %s: %.0f%%\n", program_.c_str(), Elapsed(), task_.c_str(), pct);
  }
  std::fflush(stderr);
}

void StderrMonitor::EndTask() {
  std::lock_guard<std::mutex> lock(mutex_);
  // Close a redrawn progress line; tasks that ended quietly print nothing.
  if (line_open_ && level_ >= LogLevel::kInfo) Report(done_.load(), true);
  line_open_ = false;
  task_.clear();
  total_ = 0;
}

}  // namespace voroudf
