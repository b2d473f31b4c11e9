#include "common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <vector>

#include "common/errors.h"

namespace voroudf {
namespace {

// The temporary file being written, for the signal handler (which may only use async-signal-safe calls).
char g_temp_path[4096] = {0};
volatile sig_atomic_t g_temp_active = 0;

void RemoveTemporaryAndReraise(int sig) {
  if (g_temp_active) unlink(g_temp_path);
  std::signal(sig, SIG_DFL);
  raise(sig);
}

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

}  // namespace

void InstallTemporaryFileCleanup() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, RemoveTemporaryAndReraise);
}

void CheckWritable(const std::string& path) {
  if (path.empty()) throw OutputError("(empty path)", "no output file name given");
  struct stat st;
  if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw OutputError(path, "is a directory");
  const std::string dir = DirectoryOf(path);
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    throw OutputError(path, "directory '" + dir + "' does not exist");
  if (access(dir.c_str(), W_OK | X_OK) != 0) throw OutputError(path, "directory '" + dir + "' is not writable");
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  CheckWritable(path);
  const std::string temp = DirectoryOf(path) + "/." + BaseName(path) + ".tmp.XXXXXX";
  if (temp.size() >= sizeof(g_temp_path)) throw OutputError(path, "path too long");
  std::vector<char> name(temp.begin(), temp.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0) throw OutputError(path, std::string("cannot create temporary file: ") + std::strerror(errno));
  std::memcpy(g_temp_path, name.data(), name.size());
  g_temp_active = 1;
  auto fail = [&](const std::string& what) {
    const int err = errno;
    close(fd);
    unlink(name.data());
    g_temp_active = 0;
    throw OutputError(path, what + ": " + std::strerror(err));
  };
  // mkstemp creates mode 0600; give the file the usual permissions (0666 less the umask).
  const mode_t mask = umask(0);
  umask(mask);
  if (fchmod(fd, 0666 & ~mask) != 0) fail("cannot set permissions");
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed");
    }
    written += static_cast<size_t>(n);
  }
  if (fdatasync(fd) != 0) fail("cannot flush");
  if (close(fd) != 0) {
    const int err = errno;
    unlink(name.data());
    g_temp_active = 0;
    throw OutputError(path, std::string("close failed: ") + std::strerror(err));
  }
  if (rename(name.data(), path.c_str()) != 0) {
    const int err = errno;
    unlink(name.data());
    g_temp_active = 0;
    throw OutputError(path, std::string("cannot rename temporary file into place: ") + std::strerror(err));
  }
  g_temp_active = 0;
}

}  // namespace voroudf
