#ifndef CLOTHWIND_SENSORS_V4L2_IO_H_
#define CLOTHWIND_SENSORS_V4L2_IO_H_

#include <sys/types.h>

#include <cstddef>
#include <string>

namespace clothwind {
namespace sensors {

// The system calls V4L2 capture needs, behind an interface so the capture logic can be tested
// against an emulated driver (v4l2_fake_device.h). Same conventions as the syscalls: -1 and
// errno on failure, MAP_FAILED from Mmap.
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;

  // Opens a device node read/write and non-blocking. Returns the descriptor, or -1 (errno).
  virtual int Open(const std::string& path) = 0;

  // Closes a descriptor. Returns 0, or -1 (errno).
  virtual int Close(int fd) = 0;

  // ioctl(fd, request, arg), retried while interrupted (EINTR). Returns >= 0, or -1 (errno).
  virtual int Ioctl(int fd, unsigned long request, void* arg) = 0;

  // Maps length bytes of a driver buffer at offset (from VIDIOC_QUERYBUF), read/write, shared.
  // Returns the address, or MAP_FAILED (errno).
  virtual void* Mmap(size_t length, int fd, off_t offset) = 0;

  // Unmaps what Mmap mapped. Returns 0, or -1 (errno).
  virtual int Munmap(void* address, size_t length) = 0;

  // Waits up to timeout_ms [ms] for fd to become readable (a filled buffer can be dequeued).
  // Outputs:
  //   revents  poll(2) revents (POLLIN, POLLERR, POLLHUP, ...)
  // Returns > 0 when ready or in error, 0 on timeout, -1 on failure (errno).
  virtual int Poll(int fd, int timeout_ms, short* revents) = 0;
};

// The real thing: open(2), close(2), ioctl(2), mmap(2), munmap(2), poll(2).
class SyscallV4l2Io : public V4l2Io {
 public:
  int Open(const std::string& path) override;
  int Close(int fd) override;
  int Ioctl(int fd, unsigned long request, void* arg) override;
  void* Mmap(size_t length, int fd, off_t offset) override;
  int Munmap(void* address, size_t length) override;
  int Poll(int fd, int timeout_ms, short* revents) override;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_V4L2_IO_H_
