// What a polled USB instrument's reads have done since it last answered: when to close and open
// it again, and what diagnostics should say. A station that enumerates and opens but answers
// nothing (a wedged HID endpoint, a hub that lost power) is "connected" by every other measure,
// so only its reads can tell.
#ifndef CLOTHWIND_SENSORS_USB_READ_HEALTH_H_
#define CLOTHWIND_SENSORS_USB_READ_HEALTH_H_

#include <string>

namespace clothwind::sensors {

class UsbReadHealth {
 public:
  enum class Level { kOk, kWarn, kError };

  // errors_before_reopen  failed reads in a row after which the device is opened again (>= 1)
  explicit UsbReadHealth(int errors_before_reopen = 3);

  // The device was opened (first time or again): the count towards the next reopen restarts.
  // A station reopened because its reads failed stays failing until a read succeeds.
  void Opened();
  // A read failed with `error`. Returns true when the caller should close the device and open it
  // again (errors_before_reopen failures in a row since the last open).
  bool ReadFailed(const std::string& error);
  // A read succeeded: the device answers.
  void ReadSucceeded();

  // kOk while the last read succeeded (or none was tried); kWarn while reads fail; kError once a
  // reopen has not brought an answer back. message() says which, with the last error.
  Level level() const;
  std::string message() const;
  int errors_in_row() const { return errors_in_row_; }

 private:
  int errors_before_reopen_;
  int errors_in_row_ = 0;
  bool failing_ = false;
  bool reopen_asked_ = false;         // ReadFailed asked for a reopen that has not happened yet
  bool reopened_for_errors_ = false;
  std::string last_error_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_USB_READ_HEALTH_H_
