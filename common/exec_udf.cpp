#include "common/exec_udf.h"

#include <errno.h>
#include <fcntl.h>
#include <omp.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <thread>
#include <vector>

#include "common/cleanup.h"
#include "common/errors.h"
#include "common/exec_protocol.h"
#include "common/udf_spec.h"

extern char** environ;

namespace voroudf {
namespace {

using Clock = std::chrono::steady_clock;

std::string DescribeStatus(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("was killed by signal ") + strsignal(WTERMSIG(status));
  return "stopped";
}

// write() with SIGPIPE blocked in this thread (a pending SIGPIPE it caused is consumed), so that a
// server that closed its stdin gives EPIPE instead of killing us. Installing SIG_IGN process-wide would
// change the behaviour of every other pipe the program writes to.
ssize_t WriteNoSigpipe(int fd, const char* data, size_t n) {
  sigset_t pipe_set, old_mask, pending;
  sigemptyset(&pipe_set);
  sigaddset(&pipe_set, SIGPIPE);
  sigpending(&pending);
  const bool was_pending = sigismember(&pending, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_set, &old_mask);
  const ssize_t r = ::write(fd, data, n);
  const int saved = errno;
  if (r < 0 && saved == EPIPE && !was_pending) {
    const timespec zero{0, 0};
    while (sigtimedwait(&pipe_set, nullptr, &zero) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  errno = saved;
  return r;
}

}  // namespace

ExecUdf::ExecUdf(const std::string& command, const ExecUdfOptions& options)
    : label_("exec:" + command), options_(options) {
  if (command.empty()) throw InputError("exec:", "no command after 'exec:'");
  int in_pipe[2], out_pipe[2];  // in_pipe: we write, child reads (its stdin); out_pipe: child writes
  if (pipe2(in_pipe, O_CLOEXEC) != 0) throw InputError(label_, std::string("pipe: ") + std::strerror(errno));
  if (pipe2(out_pipe, O_CLOEXEC) != 0) {
    close(in_pipe[0]), close(in_pipe[1]);
    throw InputError(label_, std::string("pipe: ") + std::strerror(errno));
  }
  // Orphans of the server (children it forked, then died) come back to us rather than to init, so that
  // ending its group can reap them: an init that never reaps (as in some containers) would otherwise
  // leave zombies that still count as members of the group.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_pipe[0], 0);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], 1);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  // Own process group, so that a shell pipeline or a server's children can be killed as one.
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  const char* argv[] = {"sh", "-c", command.c_str(), nullptr};
  const int rc = posix_spawn(&pid_, "/bin/sh", &actions, &attr, const_cast<char* const*>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  close(in_pipe[0]);
  close(out_pipe[1]);
  to_child_ = in_pipe[1];
  from_child_ = out_pipe[0];
  if (rc != 0) {
    pid_ = -1;
    close(to_child_), close(from_child_);
    throw InputError(label_, std::string("cannot run /bin/sh: ") + std::strerror(rc));
  }
  pgid_ = pid_;
  try {
    RegisterChildProcessGroup(pgid_);  // a signal to us ends the server's group too
  } catch (const Error&) {
    Fail("too many exec: sources at once");
  }
  Handshake();
}

ExecUdf::ExecUdf(const UnixSocket& socket, const ExecUdfOptions& options)
    : label_("unix:" + socket.path), options_(options), over_socket_(true) {
  if (socket.path.empty()) throw InputError("unix:", "no socket path after 'unix:'");
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket.path.size() >= sizeof address.sun_path)
    throw InputError(label_, "socket path longer than " + std::to_string(sizeof address.sun_path - 1) + " bytes");
  std::memcpy(address.sun_path, socket.path.data(), socket.path.size());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw InputError(label_, std::string("socket: ") + std::strerror(errno));
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const int saved = errno;
    close(fd);
    throw InputError(label_, std::string("cannot connect: ") + std::strerror(saved) +
                                 (saved == ENOENT || saved == ECONNREFUSED ? " (is the server running?)" : ""));
  }
  to_child_ = fd;
  from_child_ = fcntl(fd, F_DUPFD_CLOEXEC, 0);
  if (from_child_ < 0) {
    close(to_child_), to_child_ = -1;
    throw InputError(label_, std::string("dup: ") + std::strerror(errno));
  }
  Handshake();
}

void ExecUdf::Handshake() {
  fcntl(to_child_, F_SETFL, fcntl(to_child_, F_GETFL) | O_NONBLOCK);
  fcntl(from_child_, F_SETFL, fcntl(from_child_, F_GETFL) | O_NONBLOCK);

  // Handshake: "VUDF", uint32 version, 6 float32 box, uint32 name length, name.
  char head[protocol::kHelloBytes];
  Exchange("", head, sizeof head, "the handshake");
  protocol::Hello hello;
  try {
    hello = protocol::ParseHello(head);
  } catch (const protocol::ProtocolError& e) {
    Fail(e.what());
  }
  domain_ = hello.domain;
  server_name_.resize(hello.name_length);
  if (hello.name_length > 0) Exchange("", server_name_.data(), hello.name_length, "the handshake's server name");
  server_name_ = protocol::Printable(server_name_.data(), server_name_.size());
}

ExecUdf::~ExecUdf() {
  // EOF on the server's input: the protocol's "goodbye" (a socket is shut down for writing first: its
  // other descriptor would keep it open).
  if (to_child_ >= 0 && over_socket_) shutdown(to_child_, SHUT_WR);
  if (to_child_ >= 0) close(to_child_);
  to_child_ = -1;
  Reap(2.0);
  if (from_child_ >= 0) close(from_child_);
}

bool ExecUdf::Reap(double wait_s) const {
  // Waits up to wait_s for sh to exit on its own (keeping its status for messages); then whatever is left
  // of its process group (sh itself, or a server or child it started, whether or not sh has exited) gets
  // SIGTERM, and SIGKILL after kGrace_s. Always reaps sh, so no zombie stays behind. Returns whether sh
  // exited on its own.
  if (pgid_ <= 0) return true;
  bool exited = pid_ <= 0;
  const auto give_up = Clock::now() + std::chrono::duration<double>(wait_s);
  while (!exited) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_ || r < 0) {
      if (r == pid_) exit_status_ = status;
      pid_ = -1;
      exited = true;
      break;
    }
    if (Clock::now() >= give_up) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  TerminateProcessGroup(pgid_, kGrace_s);
  if (pid_ > 0) waitpid(pid_, nullptr, 0);  // killed above (or already reaped there: ECHILD)
  pid_ = -1;
  UnregisterChildProcessGroup(pgid_);
  pgid_ = -1;
  return exited;
}

void ExecUdf::Fail(const std::string& problem) const {
  std::string message = problem;
  // A dead server explains itself by its exit status; give it a moment to finish dying, then kill it.
  if (Reap(0.2) && exit_status_ != -1) message += " (the process " + DescribeStatus(exit_status_) + ")";
  if (to_child_ >= 0) close(to_child_), to_child_ = -1;
  if (from_child_ >= 0) close(from_child_), from_child_ = -1;
  failure_ = label_ + ": " + message;
  throw InputError(failure_);
}

void ExecUdf::Exchange(const std::string& out, char* in, size_t in_len, const std::string& what) const {
  const auto deadline = Clock::now() + std::chrono::duration<double>(options_.timeout_s);
  size_t written = 0, got = 0;
  while (written < out.size() || got < in_len) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      std::ostringstream msg;
      msg << "no complete answer within --udf-timeout " << options_.timeout_s << " s while waiting for " << what
          << " (received " << got << " of " << in_len << " bytes)";
      Fail(msg.str());
    }
    pollfd fds[2];
    int nfds = 0;
    int out_slot = -1, in_slot = -1;
    if (written < out.size()) out_slot = nfds, fds[nfds++] = {to_child_, POLLOUT, 0};
    if (got < in_len) in_slot = nfds, fds[nfds++] = {from_child_, POLLIN, 0};
    const int r = poll(fds, nfds, static_cast<int>(std::min<long long>(left, 1000)));
    if (r < 0) {
      if (errno == EINTR) continue;
      Fail(std::string("poll: ") + std::strerror(errno));
    }
    if (r == 0) continue;
    if (in_slot >= 0 && (fds[in_slot].revents & (POLLIN | POLLHUP | POLLERR))) {
      const ssize_t n = ::read(from_child_, in + got, in_len - got);
      if (n > 0) {
        got += static_cast<size_t>(n);
      } else if (n == 0) {
        Fail(std::string(over_socket_ ? "the server closed the connection" : "the process ended (closed its stdout)") +
             " while we waited for " + what + " (received " + std::to_string(got) +
             " of " + std::to_string(in_len) + " bytes)");
      } else if (errno != EAGAIN && errno != EINTR) {
        Fail(std::string("read: ") + std::strerror(errno));
      }
    }
    if (out_slot >= 0 && (fds[out_slot].revents & (POLLOUT | POLLHUP | POLLERR))) {
      const ssize_t n = WriteNoSigpipe(to_child_, out.data() + written, out.size() - written);
      if (n > 0) {
        written += static_cast<size_t>(n);
      } else if (n < 0 && errno == EPIPE) {
        Fail(std::string(over_socket_ ? "the server closed the connection" : "the process ended (closed its stdin)") +
             " before reading the request for " + what);
      } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
        Fail(std::string("write: ") + std::strerror(errno));
      }
    }
  }
}

void ExecUdf::Query(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  if (!failure_.empty()) throw InputError(failure_);
  const std::string request = protocol::EncodeRequest(points, count);
  std::vector<char> answer(4 + protocol::AnswerBodyBytes(count));
  const std::string what = "the answer to a request of " + std::to_string(count) + " points";
  try {
    // The count first: a server answering another count is caught before we wait for bytes that never come.
    Exchange(request, answer.data(), 4, what);
    protocol::CheckAnswerCount(answer.data(), count);
    Exchange("", answer.data() + 4, protocol::AnswerBodyBytes(count), what);
    protocol::DecodeAnswer(answer.data() + 4, count, answered_, distance, gradient);
  } catch (const protocol::ProtocolError& e) {
    Fail(e.what());
  }
  answered_ += count;
}

void ExecUdf::EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    for (size_t begin = 0; begin < count; begin += options_.max_batch) {
      const size_t n = std::min(options_.max_batch, count - begin);
      Query(points + begin, n, distance + begin, gradient + begin);
    }
  } catch (const Error& e) {
    if (!omp_in_parallel()) throw;
    // An exception cannot leave an OpenMP region (std::terminate); end as the top-level handler would.
    std::fprintf(stderr, "%s: error: %s\n", program_invocation_short_name, e.what());
    std::fflush(stderr);
    CleanUpAndExit(kExitBadInput);
  }
}

void ExecUdf::Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  // One thread is enough: the server does the work; large requests amortise the round trips.
  EvaluateChunk(points, count, distance, gradient);
}

std::string ExecUdf::Describe() const {
  return label_ + " (server '" + server_name_ + "', protocol " + std::to_string(kVersion) + "; domain " +
         FormatBox(domain_) + " from the handshake)";
}

}  // namespace voroudf
