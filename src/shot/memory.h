// Memory a piece of work needs, checked before the work starts: a shot too large for the machine
// fails at once with one line naming the size, not after minutes with std::bad_alloc.
#pragma once

#include <cstdint>
#include <string>

namespace emaki::shot {

// Bytes this process can still take: MemAvailable in /proc/meminfo, else the physical memory.
int64_t available_memory_bytes();

// "512 MB", "81.3 GB".
std::string memory_text(int64_t bytes);

// Throws emaki::Error unless `bytes` (what `what` needs at its peak, an estimate) fits within
// `max_bytes` (when > 0: the caller's limit, named by the field "max_memory") and within
// available_memory_bytes() (then the error names `subject`).
void check_memory(int64_t bytes, int64_t max_bytes, const std::string& subject,
                  const std::string& what);

}  // namespace emaki::shot
