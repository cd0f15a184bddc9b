// Transparent huge pages for a solve's large buffers (Linux). At N = 10⁶ a solve first touches
// some hundreds of megabytes (the trajectory it returns, the band factors, the Jacobian's
// entries); in 4 KB pages that is ~10⁵ page faults, a third of the electron's solve time on a
// 2-core VM, and faults do not run in parallel (bench/RESULTS.md, "N = 10⁶ on this machine").
// Where the kernel's THP mode is "madvise" (or "always"), advising a buffer before it is first
// touched has it faulted in 2 MB at a time. Advice only: ignored where unsupported, and a
// failure changes nothing but speed. The library sets no process-wide allocator policy.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace lpshoot {

// Advises the 2 MB-aligned pages inside [p, p + bytes) to be huge; ranges under 4 MB are left
// alone (no whole huge page inside, or too few faults to matter).
inline void advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t huge = std::uintptr_t(1) << 21;
  if (!p || bytes < 2 * huge) return;
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t lo = (a + huge - 1) & ~(huge - 1), hi = (a + bytes) & ~(huge - 1);
  if (hi > lo) (void)madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

}  // namespace lpshoot
