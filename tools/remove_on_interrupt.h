// Temporary files a verb is writing, removed when the process is interrupted (Ctrl-C's SIGINT,
// SIGTERM, SIGHUP): a make-session stopped midway left its temporary bag, hundreds of MB of a
// large session, until a later run into the same name cleared it. The process then still ends by
// the signal, as it would have (its exit status says so to the shell).
#ifndef CLOTHWIND_TOOLS_REMOVE_ON_INTERRUPT_H_
#define CLOTHWIND_TOOLS_REMOVE_ON_INTERRUPT_H_

#include <string>

namespace clothwind::tools {

// Registers `path` while alive. At most 8 at once (more are not removed, and say so on stderr).
// A signal the process ignores (nohup's SIGHUP, a background job's SIGINT) stays ignored.
class RemoveOnInterrupt {
 public:
  // Inputs: path  the temporary file (it need not exist yet); the first registration installs
  //         the handlers.
  explicit RemoveOnInterrupt(const std::string& path);
  ~RemoveOnInterrupt();
  RemoveOnInterrupt(const RemoveOnInterrupt&) = delete;
  RemoveOnInterrupt& operator=(const RemoveOnInterrupt&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_REMOVE_ON_INTERRUPT_H_
