// The machine's physical memory, for refusing work that could never fit in it.
#pragma once

#include <unistd.h>

namespace envgi {

// In bytes; 0 where the system does not say.
inline double physicalMemoryBytes() {
  long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? double(pages) * double(size) : 0.0;
}

}  // namespace envgi
