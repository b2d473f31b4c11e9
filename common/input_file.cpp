#include "common/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "common/errors.h"

namespace voroudf {
namespace {

constexpr size_t kHeadBytes = 64 * 1024;

std::string Errno() { return std::strerror(errno); }

// Reads until `want` bytes are in `out` or the input ends; returns false at the end of the input.
bool ReadUpTo(int fd, std::string& out, size_t want, const std::string& path) {
  while (out.size() < want) {
    const size_t old = out.size();
    out.resize(want);
    const ssize_t n = ::read(fd, out.data() + old, want - old);
    if (n < 0) {
      out.resize(old);
      if (errno == EINTR) continue;
      throw InputError(path, "read error: " + Errno());
    }
    out.resize(old + static_cast<size_t>(n));
    if (n == 0) return false;
  }
  return true;
}

}  // namespace

std::string ReadInputBytes(const std::string& path, const std::function<void(const std::string&)>& check_head) {
  const bool from_stdin = path == "-";
  const std::string name = from_stdin ? "stdin" : path;
  if (path.empty()) throw InputError("(empty path)", "no input file name given");
  const int fd = from_stdin ? 0 : open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(name, "cannot open: " + Errno());
  struct Closer {
    int fd;
    bool own;
    ~Closer() { if (own) close(fd); }
  } closer{fd, !from_stdin};
  struct stat st;
  if (fstat(fd, &st) != 0) throw InputError(name, "cannot stat: " + Errno());
  if (S_ISDIR(st.st_mode)) throw InputError(name, "is a directory, not a file");
  const bool regular = S_ISREG(st.st_mode);
  std::string bytes;
  const bool more = ReadUpTo(fd, bytes, kHeadBytes, name);
  if (check_head) check_head(bytes);
  if (!more) return bytes;
  if (regular) {
    // The size is known: one allocation, and a file that grows while read is read to its new end.
    bytes.reserve(static_cast<size_t>(st.st_size) + 1);
    while (ReadUpTo(fd, bytes, std::max(bytes.size() * 2, static_cast<size_t>(st.st_size) + 1), name)) {
    }
    return bytes;
  }
  while (ReadUpTo(fd, bytes, std::min(bytes.size() * 2, kMaxStreamBytes + 1), name)) {
    if (bytes.size() > kMaxStreamBytes)
      throw InputError(name, "a stream input longer than 2 GiB is refused (write it to a file and pass its path)");
  }
  return bytes;
}

void CheckInputFile(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) throw InputError(path, "cannot open: " + Errno());
  if (S_ISDIR(st.st_mode)) throw InputError(path, "is a directory, not a file");
  if (!S_ISREG(st.st_mode)) throw InputError(path, "is not a regular file (this reader needs one)");
  if (access(path.c_str(), R_OK) != 0) throw InputError(path, "cannot open: " + Errno());
}

}  // namespace voroudf
