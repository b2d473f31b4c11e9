#include "common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "common/cleanup.h"
#include "common/errors.h"

namespace voroudf {
namespace {

OutputSet* g_active = nullptr;

std::string DirectoryOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string BaseName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string Errno() { return std::strerror(errno); }

// Descriptor paths that name one of our own open files: written to that descriptor. Following
// /proc/self/fd/1 to a regular file and replacing it would leave the shell's redirection writing nowhere.
int DescriptorOf(const std::string& path) {
  if (path == "-" || path == "/dev/stdout") return 1;
  if (path == "/dev/stderr") return 2;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const size_t n = std::strlen(prefix);
    if (path.compare(0, n, prefix) != 0 || path.size() == n) continue;
    char* end = nullptr;
    const long fd = std::strtol(path.c_str() + n, &end, 10);
    if (*end == '\0' && fd >= 0 && fd < INT_MAX) return static_cast<int>(fd);
  }
  return -1;
}

// The final target of a chain of symbolic links (the link's own path when it is not one).
std::string FollowLinks(const std::string& given) {
  std::string path = given;
  for (int hop = 0; hop < 40; ++hop) {
    struct stat st;
    if (lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
    std::string target(PATH_MAX, '\0');
    const ssize_t n = readlink(path.c_str(), target.data(), target.size());
    if (n < 0) throw OutputError(given, "cannot read the symbolic link: " + Errno());
    target.resize(static_cast<size_t>(n));
    path = (!target.empty() && target[0] == '/') ? target : DirectoryOf(path) + "/" + target;
  }
  throw OutputError(given, "too many levels of symbolic links");
}

void WriteAll(int fd, const std::string& bytes, const std::string& path) {
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw OutputError(path, "write failed: " + Errno());
    }
    written += static_cast<size_t>(n);
  }
}

void WriteStream(const OutputTarget& t, const std::string& bytes) {
  if (t.fd >= 0) {
    WriteAll(t.fd, bytes, t.given);
    return;
  }
  const int fd = open(t.path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(t.given, "cannot open: " + Errno());
  try {
    WriteAll(fd, bytes, t.given);
  } catch (...) {
    close(fd);
    throw;
  }
  if (close(fd) != 0) throw OutputError(t.given, "close failed: " + Errno());
}

}  // namespace

OutputTarget ResolveOutput(const std::string& given) {
  if (given.empty()) throw OutputError("(empty path)", "no output file name given");
  OutputTarget t;
  t.given = given;
  t.fd = DescriptorOf(given);
  if (t.fd >= 0) {
    t.kind = OutputKind::kStream;
    t.path = given;
    if (fcntl(t.fd, F_GETFL) < 0) throw OutputError(given, "descriptor " + std::to_string(t.fd) + " is not open");
    return t;
  }
  t.path = FollowLinks(given);
  struct stat st;
  if (stat(t.path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw OutputError(given, "is a directory");
    if (!S_ISREG(st.st_mode)) {
      t.kind = OutputKind::kStream;
      t.shareable = S_ISCHR(st.st_mode);
      return t;
    }
  }
  const std::string dir = DirectoryOf(t.path);
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw OutputError(given, "directory '" + dir + "' does not exist");
  if (access(dir.c_str(), W_OK | X_OK) != 0) throw OutputError(given, "directory '" + dir + "' is not writable");
  // One spelling per file, so that two outputs naming it differently are caught.
  char real[PATH_MAX];
  if (realpath(dir.c_str(), real) != nullptr) t.path = std::string(real) + (std::strcmp(real, "/") ? "/" : "") + BaseName(t.path);
  return t;
}

void CheckWritable(const std::string& path) { ResolveOutput(path); }

struct OutputSet::Entry {
  OutputTarget target;
  std::string temp;     // kReplace: the temporary file, created by Add
  int fd = -1;          // kReplace: open on `temp` until written
  bool written = false;
  std::string held;     // kStream: the bytes, written at Commit
};

OutputSet::OutputSet() = default;

OutputSet::~OutputSet() {
  if (!committed_) Abandon();
  if (g_active == this) g_active = nullptr;
}

void OutputSet::Abandon() {
  for (auto& e : entries_) {
    if (e->fd >= 0) close(e->fd), e->fd = -1;
    if (!e->temp.empty()) {
      unlink(e->temp.c_str());
      UnregisterTemporaryFile(e->temp.c_str());
      e->temp.clear();
    }
  }
}

void OutputSet::Add(const std::string& path) {
  auto e = std::make_unique<Entry>();
  e->target = ResolveOutput(path);
  for (const auto& other : entries_) {
    const OutputTarget& o = other->target;
    const bool same = o.fd >= 0 || e->target.fd >= 0 ? o.fd == e->target.fd : o.path == e->target.path;
    if (same && !(o.shareable && e->target.shareable))
      throw UsageError("'" + path + "' and '" + o.given + "' name the same output file");
  }
  if (e->target.kind == OutputKind::kReplace) {
    const std::string pattern = DirectoryOf(e->target.path) + "/." + BaseName(e->target.path) + ".tmp.XXXXXX";
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    // A signal between creating the file and registering it would leave the file behind.
    DeferCleanupSignals defer;
    e->fd = mkostemp(name.data(), O_CLOEXEC);
    if (e->fd < 0) throw OutputError(path, "cannot create a temporary file beside it: " + Errno());
    e->temp = name.data();
    try {
      RegisterTemporaryFile(e->temp.c_str());
    } catch (...) {
      close(e->fd), unlink(e->temp.c_str());
      throw;
    }
    // mkstemp creates mode 0600: give the file the mode of the file it replaces, else 0666 less the umask.
    struct stat st;
    mode_t mode;
    if (stat(e->target.path.c_str(), &st) == 0) {
      mode = st.st_mode & 07777;
    } else {
      const mode_t mask = umask(0);
      umask(mask);
      mode = 0666 & ~mask;
    }
    entries_.push_back(std::move(e));  // owned by the set from here: Abandon cleans up on a throw
    if (fchmod(entries_.back()->fd, mode) != 0) throw OutputError(path, "cannot set permissions: " + Errno());
    return;
  }
  entries_.push_back(std::move(e));
}

bool OutputSet::Contains(const std::string& path) const {
  for (const auto& e : entries_)
    if (e->target.given == path) return true;
  return false;
}

void OutputSet::Write(const std::string& path, const std::string& bytes) {
  Entry* e = nullptr;
  for (auto& x : entries_)
    if (x->target.given == path) e = x.get();
  if (e == nullptr) throw Error("internal: '" + path + "' is not an output of this stage");
  if (e->written) throw Error("internal: output '" + path + "' written twice");
  if (e->target.kind == OutputKind::kStream) {
    e->held = bytes;
    e->written = true;
    return;
  }
  if (ftruncate(e->fd, 0) != 0 || lseek(e->fd, 0, SEEK_SET) != 0) throw OutputError(path, "cannot rewind: " + Errno());
  WriteAll(e->fd, bytes, path);
  if (fdatasync(e->fd) != 0) throw OutputError(path, "cannot flush: " + Errno());
  struct stat st;
  if (fstat(e->fd, &st) != 0 || static_cast<size_t>(st.st_size) != bytes.size())
    throw OutputError(path, "the temporary file does not hold the bytes written (disk full?)");
  const int fd = e->fd;
  e->fd = -1;
  if (close(fd) != 0) throw OutputError(path, "close failed: " + Errno());
  e->written = true;
}

void OutputSet::Commit() {
  for (const auto& e : entries_)
    if (!e->written) throw Error("internal: output '" + e->target.given + "' was never written");
  for (const auto& e : entries_)
    if (e->target.kind == OutputKind::kStream) WriteStream(e->target, e->held);
  DeferCleanupSignals defer;  // the renames publish the set together: a signal waits until all are done
  for (auto& e : entries_) {
    if (e->target.kind != OutputKind::kReplace) continue;
    if (rename(e->temp.c_str(), e->target.path.c_str()) != 0)
      throw OutputError(e->target.given, "cannot rename the temporary file into place: " + Errno());
    UnregisterTemporaryFile(e->temp.c_str());
    e->temp.clear();
  }
  committed_ = true;
}

void SetActiveOutputSet(OutputSet* set) { g_active = set; }

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  if (g_active != nullptr && g_active->Contains(path)) {
    g_active->Write(path, contents);
    return;
  }
  OutputSet alone;
  alone.Add(path);
  alone.Write(path, contents);
  alone.Commit();
}

}  // namespace voroudf
