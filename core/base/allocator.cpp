#include "core/base/allocator.h"

#include <cstdlib>  // defines __GLIBC__ on glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace calibench {

void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Blocks below this come from the heap; 32 MB is the most mallopt accepts on 64-bit glibc.
  constexpr int kMmapThresholdBytes = 32 << 20;
  constexpr int kTrimThresholdBytes = 512 << 20;  // free heap top kept up to this
  mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes);
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
#endif
}

void ReleaseFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace calibench
