#pragma once
// Output files: what a path given as an output means, and how a stage's outputs appear whole, all
// together, or not at all (docs/conventions.md "Output files"). The one place where files are written.
//
// - A regular file or a new path: the bytes go to a hidden temporary file beside it
//   (.NAME.tmp.XXXXXX), are flushed and their size checked, then the temporary is renamed over it.
// - A symbolic link: followed to its final target, which is replaced the same way; the link stays.
// - `-`, /dev/stdout, /dev/stderr, /dev/fd/N: written straight to that descriptor.
// - A character device, FIFO or socket (e.g. /dev/null): written straight through, never replaced.
// - A directory, or a path whose directory is missing or not writable: OutputError (exit 1).
//
// A stage's outputs form an OutputSet: their temporary files are created before the computation (so an
// unwritable path fails at once), every output is written and verified, and only then are all of them
// published back to back. SIGINT, SIGTERM and SIGHUP remove the temporary files (common/cleanup.h).
// Nothing survives SIGKILL: a killed stage may leave a hidden .NAME.tmp.* file, never a partial NAME.
#include <memory>
#include <string>
#include <vector>

namespace voroudf {

/// How an output path is written.
enum class OutputKind {
  kReplace,  ///< regular file or new path (after following symlinks): temporary file + rename
  kStream,   ///< stdout/stderr/descriptor, character device, FIFO or socket: written straight through
};

struct OutputTarget {
  std::string given;     ///< as on the command line
  std::string path;      ///< kReplace: the final target after following symlinks; kStream: the path to open
  OutputKind kind = OutputKind::kReplace;
  int fd = -1;           ///< kStream to a descriptor of ours (`-` = 1, /dev/stderr = 2, /dev/fd/N = N); else -1
  bool shareable = false;  ///< a character device (/dev/null): several outputs may name it
};

/// What `path` means as an output. Throws OutputError (exit 1) for an empty path, a directory, a missing or
/// unwritable directory, or a symlink chain that does not end (loop).
OutputTarget ResolveOutput(const std::string& path);

/// The outputs of one stage, published together. Not thread-safe (a stage writes its outputs from one
/// thread, after the computation).
class OutputSet {
 public:
  OutputSet();
  ~OutputSet();  ///< an uncommitted set removes its temporary files: nothing is published
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Registers an output and, for a kReplace target, creates its temporary file now.
  /// Throws UsageError (exit 2) if it names the same file as an output already in the set (after
  /// following symlinks; character devices excepted), OutputError (exit 1) if it cannot be created.
  void Add(const std::string& path);
  /// Whether `path` (as given to Add) is in the set.
  bool Contains(const std::string& path) const;
  /// Stores the bytes of output `path` (as given to Add): written to its temporary file, flushed and their
  /// size verified, or held for a stream until Commit. Throws OutputError.
  void Write(const std::string& path, const std::string& bytes);
  /// Publishes every output: first the streams are written, then every temporary file is renamed over its
  /// target, back to back. Throws Error (and publishes no replaced file) if an output was never written
  /// or a stream cannot take its bytes.
  void Commit();

 private:
  struct Entry;
  void Abandon();
  std::vector<std::unique_ptr<Entry>> entries_;
  bool committed_ = false;
};

/// The set that WriteFileAtomically writes into while a stage runs (StageCli::Run sets it); null for none.
void SetActiveOutputSet(OutputSet* set);

/// Writes `contents` to `path`: into the active OutputSet if it holds `path` (published at its Commit),
/// otherwise on its own with the same semantics (temporary file + rename, or straight to a stream).
/// Throws OutputError (exit 1) if it cannot.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Throws OutputError if `path` could not be created as an output (ResolveOutput).
void CheckWritable(const std::string& path);

}  // namespace voroudf
