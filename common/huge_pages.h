#pragma once
// Transparent huge pages for the heap of a stage (docs/performance.md, "Memory pages").

namespace voroudf {

/// Starts the program once more with glibc's malloc tunable `glibc.malloc.hugetlb=1` when the kernel gives
/// huge pages only to memory that asks for them (`/sys/kernel/mm/transparent_hugepage/enabled` is
/// `madvise`), so that malloc asks for its heap. The stages hold hundreds of MB in small allocations that
/// they read in random order (optimize-seeds' sample pool, build-gvd's kNN graph); with 4 KB pages the
/// page faults and TLB misses take 15–35 % of their time on these machines. glibc reads its tunables only
/// when a program starts, hence the second start; in it this function restores the caller's
/// GLIBC_TUNABLES (or its absence), so that child processes (`exec:` sources) see the caller's
/// environment. Nothing changes when the variable VOROUDF_HUGE_PAGES is `0`, when GLIBC_TUNABLES already
/// sets `glibc.malloc.hugetlb`, when the kernel setting is `always` or `never`, or when the new start
/// fails (the program then goes on as it is). Results do not depend on it: only where memory comes from.
/// Returns true in the second start (the heap asks for huge pages), false where nothing changed.
/// \pre called before any thread starts and before any input is read; argv as main received it
bool StartWithHugePages(char** argv);

}  // namespace voroudf
