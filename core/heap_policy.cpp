#include "core/heap_policy.hpp"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace yarnhom {

bool retain_freed_memory() {
#if defined(__GLIBC__)
  // Both or neither: a fixed trim threshold alone also freezes glibc's adaptive mmap threshold
  // at its 128 kB start, which made the same strip step slower, not faster (25 s against 15 s).
  return mallopt(M_MMAP_MAX, 0) == 1 && mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
#else
  return false;
#endif
}

}  // namespace yarnhom
