#include "process_memory.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>  // before the test of __GLIBC__, which the C library's headers define

#ifdef __GLIBC__
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace friction {

// A run allocates and frees arrays of 0.1 to 30 MB: the stiffness matrix, the factor's analysis and
// panels, the solves' vectors. glibc maps each one above 128 KiB afresh until its threshold adapts, and
// every fresh page is a fault, which costs 10–14 µs on some virtual machines. Served from the heap, they
// reuse pages already touched; arrays above 32 MiB (glibc's largest threshold) are still mapped apart.
// The heap's next growth reserves 256 MiB of addresses (pages are taken only when touched), advised for
// huge pages where the kernel allows them (its `madvise` mode, Debian's and Ubuntu's default): a fault
// then brings 2 MiB. Later growths take 16 MiB at a time, in 4 KiB pages, and the heap is not trimmed
// below 512 MiB, so that the advised range stays: a process keeps up to that much of its peak, which a
// simulation reuses at its next reset or run. glibc does the same under
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1, which a program cannot set for itself. The heap below its first
// 2 MiB boundary would be served in 4 KiB pages (100 to 500 faults in friction_run's 57 × 31 start-up,
// by where the heap starts), so a block that is never touched holds it. In a process whose libraries
// left room at the heap's top before `main`, the growth comes later and only the thresholds apply.
void reuseFreedMemoryOnHugePages() {
#ifdef __GLIBC__
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  mallopt(M_TOP_PAD, 256 << 20);
  const auto heap_start = reinterpret_cast<std::uintptr_t>(sbrk(0));
  void* volatile growth = std::malloc(256 << 10);  // volatile: a malloc freed unused may be left out
  // The first address malloc hands out from the heap's free top.
  const auto top = reinterpret_cast<std::uintptr_t>(growth);
  std::free(growth);
  mallopt(M_TOP_PAD, 16 << 20);
  const auto heap_end = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const std::uintptr_t aligned_start = (heap_start + kHugePage - 1) & ~(kHugePage - 1);
  if (heap_end > aligned_start) {
    madvise(reinterpret_cast<void*>(aligned_start), heap_end - aligned_start, MADV_HUGEPAGE);
    // Held from the free top's start to 16 bytes below aligned_start (glibc: 16-byte chunk headers, sizes
    // in 16s), so that the next array's data begins at aligned_start. Static: held for the whole run.
    constexpr std::uintptr_t kChunkHeader = 2 * sizeof(std::size_t);
    [[maybe_unused]] static void* volatile head = nullptr;
    if (aligned_start > top + kChunkHeader) head = std::malloc(aligned_start - top - kChunkHeader);
  }
#endif
}

}  // namespace friction
