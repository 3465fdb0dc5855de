#include "sensors/v4l2_io.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>

namespace clothwind {
namespace sensors {

int SyscallV4l2Io::Open(const std::string& path) {
  // Non-blocking: DQBUF answers EAGAIN instead of blocking, so waiting happens in Poll with a
  // timeout and a dead device cannot hang the thread.
  return ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
}

int SyscallV4l2Io::Close(int fd) { return ::close(fd); }

int SyscallV4l2Io::Ioctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

void* SyscallV4l2Io::Mmap(size_t length, int fd, off_t offset) {
  return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
}

int SyscallV4l2Io::Munmap(void* address, size_t length) { return ::munmap(address, length); }

int SyscallV4l2Io::Poll(int fd, int timeout_ms, short* revents) {
  pollfd p{};
  p.fd = fd;
  p.events = POLLIN;
  const int r = ::poll(&p, 1, timeout_ms);
  *revents = r > 0 ? p.revents : 0;
  return r;
}

}  // namespace sensors
}  // namespace clothwind
