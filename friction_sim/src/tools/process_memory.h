// How a process that runs simulations (the offline runner, the simulator node, the benchmarks) takes its
// memory from glibc.
#pragma once

namespace friction {

/// Serves arrays of 128 KiB to 32 MiB from the heap rather than from mappings of their own, keeps what
/// they free there for the next ones, and puts the heap's next growth on transparent huge pages where
/// the kernel allows them (process_memory.cpp says why). Call it first in `main`: the earlier, the more
/// of the run's arrays it places. It changes no result. Without glibc it does nothing.
void reuseFreedMemoryOnHugePages();

}  // namespace friction
