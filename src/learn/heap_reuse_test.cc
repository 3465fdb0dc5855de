#include "learn/heap_reuse.h"

#include <sys/resource.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// glibc's allocator is the one that answers mallopt, except under a sanitizer (scripts/sanitize),
// whose own malloc takes its place and whose mallopt does nothing.
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define CLOTHWIND_GLIBC_MALLOC 1
#else
#define CLOTHWIND_GLIBC_MALLOC 0
#endif

namespace clothwind::learn {
namespace {

constexpr size_t kBlock = size_t{8} << 20;  // about one batch of 16 64-px 30-frame clips in float
constexpr int kRounds = 20;

long MinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Allocates kBlock bytes, writes one byte a page (as a tensor's first use does) and frees it,
// kRounds times; returns the page faults that took.
long FaultsOfAllocateTouchFree() {
  const long page = sysconf(_SC_PAGESIZE);
  const long before = MinorFaults();
  for (int r = 0; r < kRounds; ++r) {
    volatile char* block = static_cast<volatile char*>(std::malloc(kBlock));
    if (block == nullptr) return -1;
    for (size_t i = 0; i < kBlock; i += page) block[i] = static_cast<char>(r);
    std::free(const_cast<char*>(block));
  }
  return MinorFaults() - before;
}

long PagesPerBlock() { return static_cast<long>(kBlock) / sysconf(_SC_PAGESIZE); }

#if CLOTHWIND_GLIBC_MALLOC
// The control: with glibc's initial thresholds fixed (so they cannot adapt), every round maps
// the block afresh and faults all its pages again. Skipped where transparent huge pages back
// such a mapping in 2-MiB faults, which hides the count.
TEST(HeapReuseTest, SmallThresholdsFaultTheSameBlockAgainEveryRound) {
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 128 << 10), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 128 << 10), 1);
  const long faults = FaultsOfAllocateTouchFree();
  ASSERT_GE(faults, 0);
  if (faults < kRounds * 4) GTEST_SKIP() << "huge pages back the block: " << faults << " faults";
  EXPECT_GE(faults, kRounds * PagesPerBlock() / 2) << "pages per block " << PagesPerBlock();
}
#endif

TEST(HeapReuseTest, FreedBlocksAreReusedWithoutFaultingTheirPagesAgain) {
#if !CLOTHWIND_GLIBC_MALLOC
  GTEST_SKIP() << "glibc's malloc only (not under a sanitizer)";
#endif
  // Where transparent huge pages back every mapping, a block faults in a few 2-MiB pieces whether
  // or not it is reused, and the check below would pass without the reuse.
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(thp, modes);
  if (modes.find("[always]") != std::string::npos) GTEST_SKIP() << "transparent huge pages: " << modes;
  // Start from the control's fixed small thresholds, whatever ran before: glibc's own adaptive
  // ones rise after the first freed mapping and reuse the heap anyway, so run alone this test
  // passed with a KeepFreedHeapForReuse that did nothing.
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 128 << 10), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 128 << 10), 1);
  const long before_call = FaultsOfAllocateTouchFree();
  if (before_call < kRounds * 4) GTEST_SKIP() << "huge pages back the block: " << before_call << " faults";
  ASSERT_GE(before_call, kRounds * PagesPerBlock() / 2) << "the thresholds did not take";
  ASSERT_TRUE(KeepFreedHeapForReuse());
  FaultsOfAllocateTouchFree();  // the heap grows once
  const long faults = FaultsOfAllocateTouchFree();
  ASSERT_GE(faults, 0);
  // Twenty rounds fault fewer pages than one block has: the freed block is handed back as it is.
  EXPECT_LT(faults, PagesPerBlock()) << kRounds << " rounds of " << PagesPerBlock() << " pages";
}

TEST(HeapReuseTest, RefusesThresholdsGlibcCannotTake) {
#if !CLOTHWIND_GLIBC_MALLOC
  GTEST_SKIP() << "glibc's malloc only (not under a sanitizer)";
#endif
  EXPECT_FALSE(KeepFreedHeapForReuse(size_t{INT_MAX} + 1));  // mallopt takes an int
  EXPECT_FALSE(KeepFreedHeapForReuse(size_t{32} << 20, size_t{INT_MAX} + 1));
  EXPECT_TRUE(KeepFreedHeapForReuse());  // the defaults are within both
}

}  // namespace
}  // namespace clothwind::learn
