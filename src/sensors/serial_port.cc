#include "sensors/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>

namespace clothwind::sensors {
namespace {

bool BaudToSpeed(int baud, speed_t* speed) {
  switch (baud) {
    case 1200: *speed = B1200; return true;
    case 2400: *speed = B2400; return true;
    case 4800: *speed = B4800; return true;
    case 9600: *speed = B9600; return true;
    case 19200: *speed = B19200; return true;
    case 38400: *speed = B38400; return true;
    case 57600: *speed = B57600; return true;
    case 115200: *speed = B115200; return true;
    case 230400: *speed = B230400; return true;
    case 460800: *speed = B460800; return true;
    case 921600: *speed = B921600; return true;
    default: return false;
  }
}

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

}  // namespace

bool ValidateSerialConfig(const SerialConfig& c, std::string* error) {
  speed_t s = B9600;
  if (c.port.empty()) {
    *error = "port: empty device path";
    return false;
  }
  if (!BaudToSpeed(c.baud, &s)) {
    *error = "baud: " + std::to_string(c.baud) +
             " not supported (expected 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600)";
    return false;
  }
  if (c.data_bits < 5 || c.data_bits > 8) {
    *error = "data_bits: " + std::to_string(c.data_bits) + " (expected 5..8)";
    return false;
  }
  if (c.parity != 'N' && c.parity != 'E' && c.parity != 'O') {
    *error = std::string("parity: '") + c.parity + "' (expected none, even or odd)";
    return false;
  }
  if (c.stop_bits != 1 && c.stop_bits != 2) {
    *error = "stop_bits: " + std::to_string(c.stop_bits) + " (expected 1 or 2)";
    return false;
  }
  return true;
}

bool ParseParity(const std::string& name, char* parity) {
  std::string n;
  for (char c : name) n.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  if (n == "n" || n == "none") *parity = 'N';
  else if (n == "e" || n == "even") *parity = 'E';
  else if (n == "o" || n == "odd") *parity = 'O';
  else return false;
  return true;
}

void ConfigureTermios(const SerialConfig& c, termios* tio_ptr) {
  termios& tio = *tio_ptr;
  ::cfmakeraw(&tio);
  speed_t speed = B9600;
  BaudToSpeed(c.baud, &speed);
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  // Linux keeps a port's termios between opens: clear every framing bit a previous program may
  // have left, CMSPAR included (with it, parity 'E' would put space parity on the wire).
  tio.c_cflag &= ~(CSIZE | PARENB | PARODD | CMSPAR | CSTOPB | CRTSCTS);
  // IGNPAR (which cfmakeraw keeps, and an earlier `stty` may have set) dropped a byte with a
  // parity error without a trace: a CSV record has no checksum, and "12.35,270" read as
  // "1.35,270". Clear, such a byte arrives as NUL, which every parser refuses (PARMRK would
  // insert 0xFF 0x00 before it instead).
  tio.c_iflag &= ~(INPCK | IGNPAR | PARMRK);
  switch (c.data_bits) {
    case 5: tio.c_cflag |= CS5; break;
    case 6: tio.c_cflag |= CS6; break;
    case 7: tio.c_cflag |= CS7; break;
    default: tio.c_cflag |= CS8; break;
  }
  if (c.parity != 'N') {
    tio.c_cflag |= PARENB;
    if (c.parity == 'O') tio.c_cflag |= PARODD;
    tio.c_iflag |= INPCK;  // check parity on input
  }
  if (c.stop_bits == 2) tio.c_cflag |= CSTOPB;
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
}

SerialPort::~SerialPort() { Close(); }

void SerialPort::Close() {
  if (fd_ >= 0) {
    ::ioctl(fd_, TIOCNXCL);
    ::close(fd_);
    fd_ = -1;
  }
}

bool SerialPort::Open(const SerialConfig& c, std::string* error) {
  Close();
  if (!ValidateSerialConfig(c, error)) return false;
  path_ = c.port;
  // O_NONBLOCK: do not wait for carrier detect on open; reads are paced by poll() instead.
  const int fd = ::open(c.port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *error = Errno("open " + c.port);
    return false;
  }
  if (!::isatty(fd)) {
    *error = "open " + c.port + ": not a terminal device";
    ::close(fd);
    return false;
  }
  if (::ioctl(fd, TIOCEXCL) != 0) {
    *error = Errno("TIOCEXCL " + c.port);
    ::close(fd);
    return false;
  }
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) {
    *error = Errno("tcgetattr " + c.port);
    ::close(fd);
    return false;
  }
  ConfigureTermios(c, &tio);
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
    *error = Errno("tcsetattr " + c.port);
    ::close(fd);
    return false;
  }
  ::tcflush(fd, TCIOFLUSH);  // drop bytes from before we were listening (a half sentence)
  fd_ = fd;
  return true;
}

SerialPort::ReadStatus SerialPort::Read(uint8_t* buffer, size_t capacity, int timeout_ms, size_t* n,
                                        std::string* error) {
  *n = 0;
  if (fd_ < 0) {
    *error = "read: port not open";
    return ReadStatus::kFailed;
  }
  pollfd p{fd_, POLLIN, 0};
  const int rc = ::poll(&p, 1, timeout_ms);
  if (rc < 0) {
    if (errno == EINTR) return ReadStatus::kTimeout;
    *error = Errno("poll " + path_);
    Close();
    return ReadStatus::kFailed;
  }
  if (rc == 0) return ReadStatus::kTimeout;
  if (p.revents & POLLNVAL) {
    *error = "poll " + path_ + ": descriptor no longer valid";
    Close();
    return ReadStatus::kFailed;
  }
  const ssize_t got = ::read(fd_, buffer, capacity);
  if (got > 0) {
    *n = static_cast<size_t>(got);
    return ReadStatus::kData;
  }
  if (got < 0 && (errno == EAGAIN || errno == EINTR)) return ReadStatus::kTimeout;
  // With VMIN = VTIME = 0, read() returns 0 on a live tty whose bytes were taken between poll()
  // and read() (another program that opened the port before us, which TIOCEXCL cannot refuse).
  // Only with POLLHUP or POLLERR does 0 mean the device went away (USB adapter unplugged,
  // pseudo-terminal master closed); EIO always does.
  if (got == 0 && !(p.revents & (POLLHUP | POLLERR))) return ReadStatus::kTimeout;
  *error = got == 0 ? "read " + path_ + ": device hung up" : Errno("read " + path_);
  Close();
  return ReadStatus::kFailed;
}

bool SerialPort::Write(const void* data, size_t size, std::string* error) {
  const uint8_t* p = static_cast<const uint8_t*>(data);
  while (size > 0) {
    if (fd_ < 0) {
      *error = "write: port not open";
      return false;
    }
    const ssize_t w = ::write(fd_, p, size);
    if (w < 0) {
      if (errno == EAGAIN || errno == EINTR) {
        pollfd pf{fd_, POLLOUT, 0};
        ::poll(&pf, 1, 100);
        continue;
      }
      *error = Errno("write " + path_);
      return false;
    }
    p += w;
    size -= static_cast<size_t>(w);
  }
  return true;
}

}  // namespace clothwind::sensors
