#include "sensors/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// A pseudo-terminal pair: the test plays the instrument on the master side.
class Pty {
 public:
  Pty() {
    char name[256];
    if (::openpty(&master_, &slave_, name, nullptr, nullptr) == 0) path_ = name;
  }
  ~Pty() {
    CloseMaster();
    if (slave_ >= 0) ::close(slave_);
  }
  void CloseMaster() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }
  int master() const { return master_; }
  const std::string& path() const { return path_; }

 private:
  int master_ = -1, slave_ = -1;
  std::string path_;
};

std::string ReadAll(SerialPort* port, size_t want, int timeout_ms) {
  std::string got;
  uint8_t buf[256];
  for (int i = 0; i < timeout_ms / 10 && got.size() < want; ++i) {
    size_t n = 0;
    std::string err;
    if (port->Read(buf, sizeof(buf), 10, &n, &err) == SerialPort::ReadStatus::kData)
      got.append(reinterpret_cast<char*>(buf), n);
  }
  return got;
}

TEST(SerialPort, RoundTripThroughPty) {
  Pty pty;
  ASSERT_FALSE(pty.path().empty());
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 9600, 8, 'N', 1}, &err)) << err;
  // Raw mode: CR, LF and control bytes pass untouched (no echo, no CR->NL translation).
  const std::string sent = std::string("\x02Q,229,002.74,M,00,\x03") + "16\r\n$IIMWV,229.0,R,5.8,N,A*39\r\n";
  ASSERT_EQ(::write(pty.master(), sent.data(), sent.size()), static_cast<ssize_t>(sent.size()));
  EXPECT_EQ(ReadAll(&port, sent.size(), 2000), sent);
  // And the other way.
  ASSERT_TRUE(port.Write("Q\r\n", 3, &err)) << err;
  char back[8] = {0};
  pollfd p{pty.master(), POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 2000), 1);
  ASSERT_EQ(::read(pty.master(), back, sizeof(back)), 3);
  EXPECT_EQ(std::string(back, 3), "Q\r\n");
}

TEST(SerialPort, BytesFromBeforeTheOpenAreDropped) {
  // Bytes the instrument sent before the node listened (half a record, a boot banner) are
  // flushed at Open, not read as the first record.
  Pty pty;
  ASSERT_FALSE(pty.path().empty());
  // The slave must be open for the master's bytes to be queued: as a previous reader left it.
  const int earlier = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(earlier, 0);
  const std::string stale = "stale,half a record";
  ASSERT_EQ(::write(pty.master(), stale.data(), stale.size()), static_cast<ssize_t>(stale.size()));
  ::usleep(50000);
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 9600, 8, 'N', 1}, &err)) << err;
  EXPECT_EQ(ReadAll(&port, stale.size(), 200), "");
  ::close(earlier);
}

TEST(SerialPort, ConfigureTermiosSetsLineSettings) {
  termios t{};
  t.c_lflag = ICANON | ECHO;
  t.c_iflag = IXON | IXOFF | IXANY | ICRNL;  // flow control a previous program left (cfmakeraw keeps IXOFF, IXANY)
  t.c_cflag = CRTSCTS;
  ConfigureTermios({"x", 4800, 7, 'O', 2}, &t);
  EXPECT_EQ(::cfgetispeed(&t), static_cast<speed_t>(B4800));
  EXPECT_EQ(::cfgetospeed(&t), static_cast<speed_t>(B4800));
  EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS7));
  EXPECT_TRUE(t.c_cflag & PARENB);
  EXPECT_TRUE(t.c_cflag & PARODD);
  EXPECT_TRUE(t.c_cflag & CSTOPB);
  EXPECT_FALSE(t.c_cflag & CRTSCTS);
  EXPECT_TRUE(t.c_cflag & CLOCAL);
  EXPECT_TRUE(t.c_cflag & CREAD);
  EXPECT_FALSE(t.c_lflag & (ICANON | ECHO));
  EXPECT_FALSE(t.c_iflag & (IXON | IXOFF | IXANY | ICRNL));
  ConfigureTermios({"x", 115200, 8, 'E', 1}, &t);
  EXPECT_EQ(::cfgetispeed(&t), static_cast<speed_t>(B115200));
  EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_TRUE(t.c_cflag & PARENB);
  EXPECT_FALSE(t.c_cflag & PARODD);
  EXPECT_FALSE(t.c_cflag & CSTOPB);
  ConfigureTermios({"x", 9600, 8, 'N', 1}, &t);
  EXPECT_FALSE(t.c_cflag & PARENB);
  // Mark/space parity and parity checking left by a previous program: Linux keeps a port's
  // termios between opens, and with CMSPAR still set, 'E' would be space parity on the wire.
  // IGNPAR or PARMRK left by `stty`: a byte with a parity error was dropped (or marked), not read
  // as the NUL the parsers refuse.
  t.c_cflag |= CMSPAR | PARENB;
  t.c_iflag |= INPCK | IGNPAR | PARMRK;
  ConfigureTermios({"x", 9600, 8, 'E', 1}, &t);
  EXPECT_FALSE(t.c_cflag & CMSPAR);
  EXPECT_TRUE(t.c_cflag & PARENB);
  EXPECT_TRUE(t.c_iflag & INPCK);
  EXPECT_FALSE(t.c_iflag & (IGNPAR | PARMRK));
  ConfigureTermios({"x", 9600, 8, 'N', 1}, &t);
  EXPECT_FALSE(t.c_iflag & INPCK);
}

TEST(SerialPort, OpenAppliesSpeedAndRawModeToTheDevice) {
  // A pty keeps speed, stop bits and the raw-mode flags (it ignores character size and parity,
  // which ConfigureTermiosSetsLineSettings covers).
  Pty pty;
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 4800, 8, 'N', 2}, &err)) << err;
  termios t{};
  ASSERT_EQ(::tcgetattr(port.fd(), &t), 0);
  EXPECT_EQ(::cfgetispeed(&t), static_cast<speed_t>(B4800));
  EXPECT_TRUE(t.c_cflag & CSTOPB);
  EXPECT_FALSE(t.c_lflag & ICANON);
  EXPECT_FALSE(t.c_lflag & ECHO);
  EXPECT_EQ(t.c_cc[VMIN], 0);
  ASSERT_TRUE(port.Open({pty.path(), 115200, 8, 'N', 1}, &err)) << err;
  ASSERT_EQ(::tcgetattr(port.fd(), &t), 0);
  EXPECT_EQ(::cfgetispeed(&t), static_cast<speed_t>(B115200));
  EXPECT_FALSE(t.c_cflag & CSTOPB);
}

TEST(SerialPort, ReadTimesOutWithoutData) {
  Pty pty;
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 9600, 8, 'N', 1}, &err)) << err;
  uint8_t buf[16];
  size_t n = 99;
  EXPECT_EQ(port.Read(buf, sizeof(buf), 20, &n, &err), SerialPort::ReadStatus::kTimeout);
  EXPECT_EQ(n, 0u);
  EXPECT_TRUE(port.is_open());
}

TEST(SerialPort, VanishedDeviceIsReportedAndClosed) {
  Pty pty;
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 9600, 8, 'N', 1}, &err)) << err;
  pty.CloseMaster();  // like unplugging a USB serial adapter
  uint8_t buf[16];
  size_t n = 0;
  SerialPort::ReadStatus s = SerialPort::ReadStatus::kTimeout;
  for (int i = 0; i < 50 && s == SerialPort::ReadStatus::kTimeout; ++i) s = port.Read(buf, sizeof(buf), 20, &n, &err);
  EXPECT_EQ(s, SerialPort::ReadStatus::kFailed);
  EXPECT_FALSE(err.empty());
  EXPECT_FALSE(port.is_open());
}

TEST(SerialPort, AReaderThatOpenedThePortFirstIsNotAHangUp) {
  // Another program (a ModemManager probe, a forgotten minicom) opened the port before us, which
  // TIOCEXCL cannot refuse: it takes bytes between our poll() and read(), and read() returns 0
  // on the live tty. That used to close the port as "device hung up".
  Pty pty;
  const int other = ::open(pty.path().c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(other, 0);
  SerialPort port;
  std::string err;
  ASSERT_TRUE(port.Open({pty.path(), 9600, 8, 'N', 1}, &err)) << err;
  std::atomic<bool> done{false};
  std::thread thief([&] {
    char b[64];
    while (!done) {
      pollfd p{other, POLLIN, 0};
      if (::poll(&p, 1, 1) > 0) (void)!::read(other, b, sizeof(b));
    }
  });
  std::thread instrument([&] {
    for (int i = 0; i < 3000 && !done; ++i) {
      (void)!::write(pty.master(), "x", 1);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  uint8_t buf[64];
  size_t n = 0, received = 0;
  int failed = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(700);
  while (std::chrono::steady_clock::now() < end && failed == 0) {
    const SerialPort::ReadStatus s = port.Read(buf, sizeof(buf), 5, &n, &err);
    if (s == SerialPort::ReadStatus::kFailed) ++failed;
    if (s == SerialPort::ReadStatus::kData) received += n;
  }
  done = true;
  instrument.join();
  thief.join();
  ::close(other);
  EXPECT_EQ(failed, 0) << err;
  EXPECT_TRUE(port.is_open());
  EXPECT_GT(received, 0u);  // the bytes are shared, not all lost
}

TEST(SerialPort, OpenErrorsNameTheProblem) {
  SerialPort port;
  std::string err;
  EXPECT_FALSE(port.Open({"/nonexistent/ttyCW0", 9600, 8, 'N', 1}, &err));
  EXPECT_NE(err.find("/nonexistent/ttyCW0"), std::string::npos) << err;
  EXPECT_FALSE(port.Open({"/dev/null", 9600, 8, 'N', 1}, &err));
  EXPECT_NE(err.find("not a terminal"), std::string::npos) << err;
  EXPECT_FALSE(port.Open({"/dev/null", 9601, 8, 'N', 1}, &err));
  EXPECT_NE(err.find("baud"), std::string::npos) << err;
  EXPECT_FALSE(port.Open({"/dev/null", 9600, 9, 'N', 1}, &err));
  EXPECT_NE(err.find("data_bits"), std::string::npos) << err;
  EXPECT_FALSE(port.Open({"/dev/null", 9600, 8, 'X', 1}, &err));
  EXPECT_NE(err.find("parity"), std::string::npos) << err;
  EXPECT_FALSE(port.Open({"/dev/null", 9600, 8, 'N', 3}, &err));
  EXPECT_NE(err.find("stop_bits"), std::string::npos) << err;
  char p;
  EXPECT_TRUE(ParseParity("Even", &p));
  EXPECT_EQ(p, 'E');
  EXPECT_FALSE(ParseParity("mark", &p));
}

}  // namespace
}  // namespace clothwind::sensors
