// Warnings of the simulator's file readers (a material's ignored keys, an OBJ's unwelded
// vertices), printed on stderr once per process: a file read again (each simulation of a dataset
// reads its scene's files) says its warning once. Header-only.
#ifndef CLOTHWIND_SIM_WARN_ONCE_H_
#define CLOTHWIND_SIM_WARN_ONCE_H_

#include <iostream>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace clothwind::sim {

// Prints "warning: <w>" on stderr for each of `warnings` this process has not printed yet.
inline void WarnOnce(const std::vector<std::string>& warnings) {
  static std::mutex mutex;
  static std::set<std::string> given;
  std::lock_guard<std::mutex> lock(mutex);
  for (const std::string& w : warnings)
    if (given.insert(w).second) std::cerr << "warning: " << w << "\n";
}

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_WARN_ONCE_H_
