// A serial port configured through termios: raw bytes, no flow control, non-blocking reads with
// a timeout. Opened exclusively (TIOCEXCL), so a program that tries to open it after us is
// refused; one that opened it before us still shares its bytes (the kernel cannot say), and its
// reads show here as timeouts, not as a hang-up.
#ifndef CLOTHWIND_SENSORS_SERIAL_PORT_H_
#define CLOTHWIND_SENSORS_SERIAL_PORT_H_

#include <cstddef>
#include <cstdint>
#include <string>

struct termios;

namespace clothwind::sensors {

// Line settings.
struct SerialConfig {
  std::string port;   // device path, e.g. /dev/ttyUSB0 (symlinks are followed)
  int baud = 4800;    // NMEA 0183 default; Gill WindSonic default 9600
  int data_bits = 8;  // 5..8
  char parity = 'N';  // 'N' none, 'E' even, 'O' odd
  int stop_bits = 1;  // 1 or 2
};

// Checks a configuration (baud in the termios table, data bits, parity, stop bits).
// Outputs:
//   error  what is wrong, naming the field and the accepted values
// Returns true when it is usable.
bool ValidateSerialConfig(const SerialConfig& config, std::string* error);

// Parses a parity name: "none"/"N", "even"/"E", "odd"/"O" (case-insensitive).
// Outputs:
//   parity  'N', 'E' or 'O'
// Returns false for anything else.
bool ParseParity(const std::string& name, char* parity);

// Fills termios for raw 8-bit-clean reading with the given line settings (cfmakeraw, speed,
// character size, parity, stop bits, CLOCAL|CREAD, no flow control, VMIN = VTIME = 0). Kept
// apart from Open() so the settings can be checked without hardware: a pseudo-terminal, the only
// "serial port" a test machine has, ignores character size and parity.
// Inputs:
//   config  validated line settings
// Outputs:
//   tio     modified in place (start from tcgetattr's result)
void ConfigureTermios(const SerialConfig& config, struct termios* tio);

class SerialPort {
 public:
  enum class ReadStatus { kData, kTimeout, kFailed };

  SerialPort() = default;
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens and configures the port; discards anything already buffered.
  // Inputs:
  //   config  line settings
  // Outputs:
  //   error  on failure, names the port and the failing call (e.g. "open /dev/ttyUSB0: No such file")
  // Returns true on success.
  bool Open(const SerialConfig& config, std::string* error);

  // Closes the port (safe to call twice).
  void Close();

  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }

  // Waits up to `timeout_ms` for bytes and reads what is there.
  // Inputs:
  //   buffer, capacity  where to put bytes
  //   timeout_ms        longest wait [ms]
  // Outputs:
  //   n      bytes read (kData)
  //   error  on kFailed: why (device vanished, I/O error); the port is then closed
  // Returns kData, kTimeout, or kFailed.
  ReadStatus Read(uint8_t* buffer, size_t capacity, int timeout_ms, size_t* n, std::string* error);

  // Writes all bytes (for polled instruments and tests).
  // Returns false with error on failure.
  bool Write(const void* data, size_t size, std::string* error);

 private:
  int fd_ = -1;
  std::string path_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_SERIAL_PORT_H_
