#include "learn/heap_reuse.h"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace clothwind::learn {

bool KeepFreedHeapForReuse(size_t mmap_threshold, size_t trim_threshold) {
#if defined(__GLIBC__)
  if (mmap_threshold > INT_MAX || trim_threshold > INT_MAX) return false;  // mallopt takes an int
  // Setting a threshold fixes it: glibc stops adapting it to the blocks freed so far.
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, static_cast<int>(mmap_threshold)) == 1;
  const bool trim_ok = mallopt(M_TRIM_THRESHOLD, static_cast<int>(trim_threshold)) == 1;
  // The heap then grows in 64-MiB steps rather than one block at a time.
  const bool pad_ok = mallopt(M_TOP_PAD, 64 << 20) == 1;
  return mmap_ok && trim_ok && pad_ok;
#else
  (void)mmap_threshold;
  (void)trim_threshold;
  return false;
#endif
}

}  // namespace clothwind::learn
