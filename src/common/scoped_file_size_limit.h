#ifndef CLOTHWIND_COMMON_SCOPED_FILE_SIZE_LIMIT_H_
#define CLOTHWIND_COMMON_SCOPED_FILE_SIZE_LIMIT_H_

#include <signal.h>
#include <sys/resource.h>

namespace clothwind {

// A full disk for tests: RLIMIT_FSIZE lowered to `bytes` while this lives (it binds root too,
// where file permissions would not), with SIGXFSZ ignored so a write past it fails with EFBIG
// instead of killing the process. Both are restored however the scope is left.
class ScopedFileSizeLimit {
 public:
  explicit ScopedFileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    handler_ = ::signal(SIGXFSZ, SIG_IGN);
    rlimit small = saved_;
    small.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &small);
  }
  ~ScopedFileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    ::signal(SIGXFSZ, handler_);
  }
  ScopedFileSizeLimit(const ScopedFileSizeLimit&) = delete;
  ScopedFileSizeLimit& operator=(const ScopedFileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  sighandler_t handler_;
};

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_SCOPED_FILE_SIZE_LIMIT_H_
