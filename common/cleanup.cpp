#include "common/cleanup.h"

#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include "common/errors.h"

namespace voroudf {
namespace {

// Slots are claimed with a compare-and-swap on `state` (0 free, 1 being written, 2 in use), so the
// handler, which may run at any time, only reads slots that are complete.
struct TempSlot {
  std::atomic<int> state{0};
  char path[4096];
};
TempSlot g_temps[kMaxCleanupEntries];
std::atomic<int> g_groups[kMaxCleanupEntries];  // 0 = free
std::atomic<bool> g_installed{false};
std::atomic<int> g_deferring{0};      // DeferCleanupSignals alive
std::atomic<int> g_pending_signal{0};  // a signal that arrived while deferring

constexpr double kSignalGrace_s = 0.5;

void RemoveTemporaryFiles() {
  for (TempSlot& slot : g_temps)
    if (slot.state.load() == 2) unlink(slot.path);
}

void OnSignal(int sig) {
  // Recorded before the check, so that a deferral ending meanwhile still sees it.
  g_pending_signal.store(sig);
  if (g_deferring.load() > 0) return;
  RemoveTemporaryFiles();
  TerminateChildProcessGroups(kSignalGrace_s);
  signal(sig, SIG_DFL);
  raise(sig);
}

void SleepMs(long ms) {
  timespec t{ms / 1000, (ms % 1000) * 1000000L};
  while (nanosleep(&t, &t) != 0 && errno == EINTR) {
  }
}

// Whether some member of the group still exists, after reaping those that are our own dead children
// (a zombie still counts as a member for kill()).
bool GroupAlive(int pgid) {
  while (waitpid(-pgid, nullptr, WNOHANG) > 0) {
  }
  return kill(-pgid, 0) == 0;
}

}  // namespace

void InstallCleanupHandlers() {
  if (g_installed.exchange(true)) return;
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = OnSignal;
  action.sa_flags = SA_RESTART;  // a deferred signal returns into the interrupted call
  sigemptyset(&action.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&action.sa_mask, sig);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &action, nullptr);
}

DeferCleanupSignals::DeferCleanupSignals() { g_deferring.fetch_add(1); }

DeferCleanupSignals::~DeferCleanupSignals() {
  if (g_deferring.fetch_sub(1) != 1) return;
  if (const int sig = g_pending_signal.exchange(0); sig != 0) OnSignal(sig);
}

void RegisterTemporaryFile(const char* path) {
  if (std::strlen(path) >= sizeof(TempSlot::path)) throw Error(std::string(path) + ": temporary file path too long");
  for (TempSlot& slot : g_temps) {
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::strcpy(slot.path, path);
    slot.state.store(2);
    return;
  }
  throw Error("more than 16 temporary output files at once");
}

void UnregisterTemporaryFile(const char* path) {
  for (TempSlot& slot : g_temps)
    if (slot.state.load() == 2 && std::strcmp(slot.path, path) == 0) {
      slot.state.store(0);
      return;
    }
}

void RegisterChildProcessGroup(int pgid) {
  for (auto& slot : g_groups) {
    int expected = 0;
    if (slot.compare_exchange_strong(expected, pgid)) return;
  }
  throw Error("more than 16 helper processes at once");
}

void UnregisterChildProcessGroup(int pgid) {
  for (auto& slot : g_groups) {
    int expected = pgid;
    if (slot.compare_exchange_strong(expected, 0)) return;
  }
}

bool TerminateProcessGroup(int pgid, double grace_s) {
  if (pgid <= 0 || !GroupAlive(pgid)) return false;
  kill(-pgid, SIGTERM);
  kill(-pgid, SIGCONT);  // a stopped member would never see the SIGTERM
  for (double waited = 0; waited < grace_s; waited += 0.005) {
    if (!GroupAlive(pgid)) return true;
    SleepMs(5);
  }
  kill(-pgid, SIGKILL);
  for (int i = 0; i < 200 && GroupAlive(pgid); ++i) SleepMs(5);  // SIGKILL cannot be ignored: a moment at most
  return true;
}

void TerminateChildProcessGroups(double grace_s) {
  for (auto& slot : g_groups) {
    const int pgid = slot.exchange(0);
    if (pgid > 0) TerminateProcessGroup(pgid, grace_s);
  }
}

void CleanUpAndExit(int code) {
  RemoveTemporaryFiles();
  TerminateChildProcessGroups(kSignalGrace_s);
  _exit(code);
}

}  // namespace voroudf
