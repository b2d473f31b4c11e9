#pragma once
// What a stage must undo however it ends: temporary output files to remove and helper processes (exec:
// UDF servers) to end. Kept in fixed arrays so that the signal handlers may use them (async-signal-safe).
namespace voroudf {

/// At most this many temporary files and this many process groups are tracked at once.
constexpr int kMaxCleanupEntries = 16;

/// Installs SIGINT/SIGTERM/SIGHUP handlers that remove the registered temporary files, end the registered
/// process groups (SIGTERM, then SIGKILL after a grace period), then end the process with the signal's
/// default action. Idempotent.
void InstallCleanupHandlers();

/// While one exists, a SIGINT/SIGTERM/SIGHUP is held back and acted on when the last one ends, so that a
/// step such as "create a file, then register it" or "publish every output of a set" is never cut in the
/// middle. A flag rather than a signal mask, because any thread of the process may receive the signal.
class DeferCleanupSignals {
 public:
  DeferCleanupSignals();
  ~DeferCleanupSignals();
  DeferCleanupSignals(const DeferCleanupSignals&) = delete;
  DeferCleanupSignals& operator=(const DeferCleanupSignals&) = delete;
};

/// Tracks a temporary file to remove if a signal ends the process. Throws Error if kMaxCleanupEntries are
/// already tracked. `path` is copied.
void RegisterTemporaryFile(const char* path);
void UnregisterTemporaryFile(const char* path);

/// Tracks the process group `pgid` (a helper started with its own group) to end with us.
void RegisterChildProcessGroup(int pgid);
void UnregisterChildProcessGroup(int pgid);

/// Ends the process group `pgid`: SIGTERM, up to `grace_s` for every member to go, then SIGKILL.
/// Returns whether members were still alive when SIGTERM was sent. Async-signal-safe. Does not reap.
bool TerminateProcessGroup(int pgid, double grace_s);

/// TerminateProcessGroup on every registered group, for exits that do not unwind (an error inside an
/// OpenMP region ends the process with _exit). Async-signal-safe.
void TerminateChildProcessGroups(double grace_s);

/// Removes the registered temporary files, ends the registered process groups and ends the process with
/// `code` without unwinding: for an error inside an OpenMP region, where an exception cannot go.
[[noreturn]] void CleanUpAndExit(int code);

}  // namespace voroudf
