// Clocks shared by the bench programs. CPU time is reported beside wall time because on a shared
// machine (a training on the other core, CI) wall time also counts other jobs' load.
#ifndef CLOTHWIND_BENCH_BENCH_CLOCK_H_
#define CLOTHWIND_BENCH_BENCH_CLOCK_H_

#include <time.h>

#include <chrono>

namespace clothwind::bench {

// Wall clock [ms] on a monotonic clock (only differences mean anything).
inline double WallMs() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// CPU time of the whole process, all threads [ms].
inline double ProcessCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// CPU time of the calling thread [s]: a per-core figure that holds on a busy machine.
inline double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

}  // namespace clothwind::bench

#endif  // CLOTHWIND_BENCH_BENCH_CLOCK_H_
