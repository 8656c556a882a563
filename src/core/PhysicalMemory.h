// The machine's physical memory, for refusing work that could never fit in it.
#pragma once

#include <unistd.h>

namespace envgi {

// In bytes; 0 where the system does not say.
inline double physicalMemoryBytes() {
  long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? double(pages) * double(size) : 0.0;
}

// The bound envgi holds large allocations to: at most half of memoryBytes (0: unknown, anything
// fits), so that work which could never fit ends with an error line instead of a killed process.
inline bool fitsInHalfOfMemory(double bytes, double memoryBytes) {
  return !(memoryBytes > 0.0 && bytes > 0.5 * memoryBytes);
}

}  // namespace envgi
