#include "sensors/usb_read_health.h"

#include <algorithm>

namespace clothwind::sensors {

UsbReadHealth::UsbReadHealth(int errors_before_reopen)
    : errors_before_reopen_(std::max(1, errors_before_reopen)) {}

void UsbReadHealth::Opened() {
  errors_in_row_ = 0;
  // The reopen the failures asked for: from now on a silent station has been reopened in vain.
  if (reopen_asked_) reopened_for_errors_ = true;
  reopen_asked_ = false;
}

bool UsbReadHealth::ReadFailed(const std::string& error) {
  failing_ = true;
  last_error_ = error;
  if (++errors_in_row_ < errors_before_reopen_) return false;
  reopen_asked_ = true;  // an ERROR only once the reopen is done (Opened) and the station still silent
  return true;
}

void UsbReadHealth::ReadSucceeded() {
  errors_in_row_ = 0;
  failing_ = false;
  reopen_asked_ = false;
  reopened_for_errors_ = false;
}

UsbReadHealth::Level UsbReadHealth::level() const {
  if (!failing_) return Level::kOk;
  return reopened_for_errors_ ? Level::kError : Level::kWarn;
}

std::string UsbReadHealth::message() const {
  switch (level()) {
    case Level::kOk: return "USB reads answered";
    case Level::kWarn: return "USB reads failing: " + last_error_;
    case Level::kError: return "USB station answers nothing, even after reopening: " + last_error_;
  }
  return "";
}

}  // namespace clothwind::sensors
