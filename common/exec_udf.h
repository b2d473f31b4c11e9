#pragma once
// `--udf exec:COMMAND`: a UDF served by an external process (e.g. a neural UDF in Python) over its
// stdin/stdout in the binary protocol of docs/exec-protocol.md.
#include <sys/types.h>

#include <mutex>
#include <string>

#include "common/udf.h"

namespace voroudf {

struct ExecUdfOptions {
  double timeout_s = 60.0;   ///< --udf-timeout: longest wait for the handshake and for each answer
  size_t max_batch = 65536;  ///< points per request (the protocol allows up to kMaxRequest)
};

/// Runs `/bin/sh -c COMMAND` once, in its own process group, with pipes on its stdin and stdout (its
/// stderr is passed through), reads the handshake (magic, version, domain box, server name) and then
/// answers every query by a request/answer exchange. A process that exits, stalls past the timeout,
/// answers with the wrong count or writes garbage (bad magic, non-finite numbers) is an InputError
/// (exit 3), never a hang: every read and write goes through poll() with the deadline, SIGPIPE is
/// blocked around writes, and the process group is killed and reaped. After such an error every
/// further query fails with the same error.
///
/// The server's whole process group ends with us on every path: at the end (EOF on its stdin, up to 2 s
/// to exit, then SIGTERM and SIGKILL 0.5 s later to whatever of the group is left, whether or not sh has
/// exited), on errors, and on SIGINT/SIGTERM/SIGHUP to the stage (common/cleanup.h).
///
/// Thread-safe: queries are serialised by a mutex. Evaluate() sends a whole batch as requests of
/// max_batch points from the calling thread; EvaluateChunk() called from inside an OpenMP parallel
/// region cannot throw across it, so there an error prints `PROGRAM: error: ...` and ends the process
/// with exit code 3 (the same outcome as the top-level handler).
///
/// Precision: the protocol carries float32, so distances and positions are good to ~1e-7 relative.
///
/// The same protocol over a Unix-domain socket (`--udf unix:PATH`, the UnixSocket constructor): the stage
/// connects to a server that is already running and may serve many stages; there is no process to start
/// or end, the rest (handshake, timeouts, errors, goodbye by EOF) is the same.
class ExecUdf : public Udf {
 public:
  struct UnixSocket {
    std::string path;
  };
  static constexpr uint32_t kVersion = 1;             ///< protocol::kVersion
  static constexpr uint32_t kMaxRequest = 1u << 20;   ///< protocol::kMaxRequest

  /// \param command what follows "exec:" in the SPEC, run by /bin/sh -c
  /// Throws InputError if the process cannot start or its handshake is missing, late or malformed.
  ExecUdf(const std::string& command, const ExecUdfOptions& options);
  /// Connects to the server listening at `socket.path`. Throws InputError if it cannot connect (no such
  /// socket, nobody listening) or the handshake is missing, late or malformed.
  ExecUdf(const UnixSocket& socket, const ExecUdfOptions& options);
  ~ExecUdf() override;
  ExecUdf(const ExecUdf&) = delete;
  ExecUdf& operator=(const ExecUdf&) = delete;

  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  using Udf::Evaluate;
  Box Domain() const override { return domain_; }
  std::string Describe() const override;

  const std::string& server_name() const { return server_name_; }

 private:
  void Handshake();  // from the constructors
  // All below run with mutex_ held (or from the constructor).
  void Query(const Vec3* points, size_t count, double* distance, Vec3* gradient) const;
  /// Writes `out` (may be empty) and reads exactly `in_len` bytes into `in`, both before the deadline.
  void Exchange(const std::string& out, char* in, size_t in_len, const std::string& what) const;
  [[noreturn]] void Fail(const std::string& problem) const;
  bool Reap(double wait_s) const;

  std::string label_;  // the SPEC: "exec:COMMAND" or "unix:PATH"
  ExecUdfOptions options_;
  bool over_socket_ = false;
  Box domain_;
  std::string server_name_;
  mutable std::mutex mutex_;
  static constexpr double kGrace_s = 0.5;  ///< SIGTERM to SIGKILL
  mutable pid_t pid_ = -1;   // sh, until reaped
  mutable pid_t pgid_ = -1;  // its process group, until ended
  mutable int to_child_ = -1;
  mutable int from_child_ = -1;
  mutable int exit_status_ = -1;  // raw waitpid status once reaped
  mutable std::string failure_;
  mutable uint64_t answered_ = 0;
};

}  // namespace voroudf
