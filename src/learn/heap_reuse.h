#ifndef CLOTHWIND_LEARN_HEAP_REUSE_H_
#define CLOTHWIND_LEARN_HEAP_REUSE_H_

#include <cstddef>

namespace clothwind::learn {

// Makes glibc's malloc keep freed memory for reuse instead of handing it back to the kernel, for
// a process that trains with libtorch.
//
// Why: a training step allocates and frees the same megabyte-sized tensors every batch. Under
// glibc's adaptive defaults many of them go back to the kernel when freed, so the next step
// faults their pages in again and the kernel zeroes them. `learn_train_step_bench --repeats 20
// --threads 2 --cases 64:1,96:1` on the 2-core VM, three runs each way: 1.1-1.3 million page
// faults with glibc's defaults, 0.25 million after this call, and the median whole step 7 %
// faster at 64 px and 13 % at 96 px (docs/sdn.md, "Speed"). Inference, one clip at a time,
// gains nothing measurable (sdn_bench), so only `clothwind train` calls it. Numerics are
// untouched: only where the bytes live changes.
//
// Inputs:
//   mmap_threshold  bytes; allocations of at least this size are still mmap-ed (default 32 MiB,
//                   the most glibc's own adaptive threshold reaches: a frame cache stays mapped)
//   trim_threshold  bytes of free memory at the heap's top kept before trimming (default 1 GiB)
// Returns true when glibc accepted every setting, false for a value above INT_MAX (mallopt takes
// an int). Process-wide and permanent: call it once, before training starts. Outside glibc it does
// nothing and returns false.
bool KeepFreedHeapForReuse(size_t mmap_threshold = size_t{32} << 20, size_t trim_threshold = size_t{1} << 30);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_HEAP_REUSE_H_
