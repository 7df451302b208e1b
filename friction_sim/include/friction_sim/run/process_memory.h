// How a process that runs simulations gets its memory (glibc on Linux).
#pragma once

namespace friction {

/// Lets the process reuse the memory it frees, on transparent huge pages where the kernel allows them
/// (process_memory.cpp says how and what it saves). Call it first in `main`, before other allocations:
/// it shapes the heap's first growth. It changes no result, only where arrays are placed.
void reuseFreedMemoryOnHugePages();

}  // namespace friction
