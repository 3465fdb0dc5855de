#include "sensors/usb_read_health.h"

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(UsbReadHealth, FailedReadsWarnThenReopenThenErrorUntilAReadSucceeds) {
  UsbReadHealth h(3);
  h.Opened();
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kOk);
  EXPECT_FALSE(h.ReadFailed("LIBUSB_ERROR_TIMEOUT"));
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kWarn);
  EXPECT_NE(h.message().find("LIBUSB_ERROR_TIMEOUT"), std::string::npos) << h.message();
  EXPECT_FALSE(h.ReadFailed("LIBUSB_ERROR_TIMEOUT"));
  EXPECT_TRUE(h.ReadFailed("LIBUSB_ERROR_TIMEOUT"));  // the third in a row: reopen
  // Not yet reopened (the node backs off first): still a WARN, not "even after reopening".
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kWarn);
  EXPECT_EQ(h.message().find("reopening"), std::string::npos) << h.message();
  // A successful open is not an answer: the station that opens but stays silent is an error, not
  // "connected" and OK (the node used to reset everything on open).
  h.Opened();
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kError);
  EXPECT_NE(h.message().find("reopening"), std::string::npos) << h.message();
  EXPECT_FALSE(h.ReadFailed("LIBUSB_ERROR_TIMEOUT"));  // the count restarts after an open
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kError);
  h.ReadSucceeded();
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kOk);
  EXPECT_EQ(h.errors_in_row(), 0);
}

TEST(UsbReadHealth, ASuccessBetweenFailuresRestartsTheCount) {
  UsbReadHealth h(2);
  EXPECT_FALSE(h.ReadFailed("e"));
  h.ReadSucceeded();
  EXPECT_FALSE(h.ReadFailed("e"));
  EXPECT_EQ(h.level(), UsbReadHealth::Level::kWarn);
  EXPECT_TRUE(h.ReadFailed("e"));
}

}  // namespace
}  // namespace clothwind::sensors
