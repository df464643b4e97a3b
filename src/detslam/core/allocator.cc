#include "detslam/core/allocator.h"

#include <cstdlib>  // defines __GLIBC__ with the GNU C library

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace detslam {

bool KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  constexpr int kMiB = 1 << 20;
  // 32 MiB is the largest mmap threshold glibc accepts on 64-bit systems; setting it also stops
  // glibc's dynamic adjustment of the threshold.
  const bool mmap_set = mallopt(M_MMAP_THRESHOLD, 32 * kMiB) == 1;
  const bool trim_set = mallopt(M_TRIM_THRESHOLD, 256 * kMiB) == 1;
  return mmap_set && trim_set;
#else
  return false;
#endif
}

}  // namespace detslam
