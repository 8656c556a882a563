// The machine's physical memory, for refusing work that could never fit in it.
#pragma once

#include <fmt/format.h>
#include <unistd.h>

#include <stdexcept>
#include <string>

namespace envgi {

// In bytes; 0 where the system does not say.
inline double physicalMemoryBytes() {
  long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? double(pages) * double(size) : 0.0;
}

// The bound envgi holds large allocations to: at most half of memoryBytes (0: unknown, anything
// fits), so that work which could never fit ends with an error line instead of a killed process.
// Throws "<what> <bytes> GB, more than half of this machine's <memory> GB: <advice>" where the
// bytes do not fit; what names the thing and ends "would take" (or "would take about").
inline void requireFitsInHalfOfMemory(double bytes, double memoryBytes, const std::string& what,
                                      const std::string& advice) {
  if (memoryBytes > 0.0 && bytes > 0.5 * memoryBytes)
    throw std::runtime_error(fmt::format("{} {:.1f} GB, more than half of this machine's {:.1f} GB: {}", what,
                                         bytes / 1e9, memoryBytes / 1e9, advice));
}

}  // namespace envgi
