// The OpenMP wait policy of the learn benches. Why: libtorch's OpenMP threads spin between
// parallel regions unless OMP_WAIT_POLICY=PASSIVE (scripts/env.sh sets it for everything the
// project runs); a bench started outside that environment measured 2-3x the wall time and 3-5x
// the CPU time (learn_train_step_bench: 1178 / 679 ms unset against 459 / 184 ms PASSIVE). libgomp
// reads the variable when it is loaded, before main, so a bench that finds it unset sets it and
// executes itself again.
#ifndef CLOTHWIND_BENCH_OMP_WAIT_POLICY_H_
#define CLOTHWIND_BENCH_OMP_WAIT_POLICY_H_

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace clothwind::bench {

// Call first in main. When OMP_WAIT_POLICY is unset: sets it to PASSIVE and re-executes the
// program with the same arguments (returns only if that fails, saying so). Returns the policy the
// process runs under, for the bench's header line.
inline const char* EnsureOmpWaitPolicy(char** argv) {
  if (const char* set = std::getenv("OMP_WAIT_POLICY")) return set;
  setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
  execv("/proc/self/exe", argv);
  std::perror("bench: re-executing with OMP_WAIT_POLICY=PASSIVE failed; running as started (unset)");
  unsetenv("OMP_WAIT_POLICY");
  return "unset";
}

}  // namespace clothwind::bench

#endif  // CLOTHWIND_BENCH_OMP_WAIT_POLICY_H_
