// main() of every GoogleTest binary (instead of gtest_main): as gtest's, plus exit code 77 when
// every test that was to run skipped itself, which CTest reports as "Skipped" (SKIP_RETURN_CODE,
// cmake/ClothwindHelpers.cmake). A binary whose tests all need what the machine lacks (ArcSim's
// files in ../shared, a GPU, a V4L2 loopback device) then no longer shows as "Passed" in a
// fraction of a second. A binary where some tests ran and some skipped passes as before; its log
// and XML name the skipped ones.
#include <gtest/gtest.h>

#if defined(__SANITIZE_THREAD__)
#include <oneapi/tbb/global_control.h>
#endif

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
#if defined(__SANITIZE_THREAD__)
  // Under ThreadSanitizer (scripts/sanitize thread) oneTBB runs every parallel loop on the calling
  // thread: Debian's libtbb is not instrumented, so TSan misses the join at a parallel_for's end
  // and reported each result a worker wrote as a race with the caller that read it. The threads
  // clothwind starts itself (std::thread) are all still checked.
  tbb::global_control serial_tbb(tbb::global_control::max_allowed_parallelism, 1);
#endif
  const int result = RUN_ALL_TESTS();
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  if (result == 0 && unit.test_to_run_count() > 0 && unit.skipped_test_count() == unit.test_to_run_count())
    return 77;
  return result;
}
