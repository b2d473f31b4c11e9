#include "common/huge_pages.h"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

namespace voroudf {
namespace {

// Set in the second start only: "=" followed by the caller's GLIBC_TUNABLES, or "-" when it had none.
constexpr const char* kSaved = "VOROUDF_SAVED_GLIBC_TUNABLES";
constexpr const char* kTunable = "glibc.malloc.hugetlb";

bool KernelWantsMadvise() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(in, line) && line.find("[madvise]") != std::string::npos;
}

void Restore(const char* saved) {
  if (saved[0] == '=')
    setenv("GLIBC_TUNABLES", saved + 1, 1);
  else
    unsetenv("GLIBC_TUNABLES");
  unsetenv(kSaved);
}

}  // namespace

bool StartWithHugePages(char** argv) {
  if (const char* saved = std::getenv(kSaved)) {  // the second start: the tunable is read, hand the caller's back
    Restore(saved);
    return true;
  }
  const char* off = std::getenv("VOROUDF_HUGE_PAGES");
  if (off && std::strcmp(off, "0") == 0) return false;
  const char* current = std::getenv("GLIBC_TUNABLES");
  if (current && std::strstr(current, kTunable)) return false;
  if (!KernelWantsMadvise()) return false;
  const std::string saved = current ? std::string("=") + current : std::string("-");
  const std::string tunables = (current && *current ? std::string(current) + ":" : std::string()) + kTunable + "=1";
  if (setenv(kSaved, saved.c_str(), 1) != 0 || setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return false;
  execv("/proc/self/exe", argv);
  Restore(saved.c_str());  // execv returned: it failed, go on in this process
  return false;
}

}  // namespace voroudf
