#include "sensors/fine_offset_usb.h"

#include <libusb.h>

#include <algorithm>

#include "sensors/fine_offset_memory.h"
#include "sensors/fine_offset_record.h"

namespace clothwind::sensors {
namespace {

constexpr unsigned kTimeoutMs = 1000;

std::string UsbError(const std::string& what, int rc) {
  return "fine_offset USB " + what + ": " + libusb_error_name(rc);
}

}  // namespace

FineOffsetUsb::~FineOffsetUsb() {
  Close();
  if (context_) libusb_exit(context_);
}

void FineOffsetUsb::Close() {
  if (handle_) {
    if (claimed_) libusb_release_interface(handle_, 0);
    libusb_close(handle_);
  }
  handle_ = nullptr;
  claimed_ = false;
}

bool FineOffsetUsb::Open(std::string* error) {
  Close();
  if (!context_) {
    const int rc = libusb_init(&context_);
    if (rc != 0) {
      context_ = nullptr;
      *error = UsbError("init", rc);
      return false;
    }
  }
  handle_ = libusb_open_device_with_vid_pid(context_, kFineOffsetVendorId, kFineOffsetProductId);
  if (!handle_) {
    *error = "fine_offset USB: no device 1941:8021 found (or no permission: see docs/anemometer.md)";
    return false;
  }
  // The kernel binds usbhid to the station; we need the interface ourselves.
  libusb_set_auto_detach_kernel_driver(handle_, 1);
  int rc = libusb_claim_interface(handle_, 0);
  if (rc != 0) {
    *error = UsbError("claim interface 0", rc);
    Close();
    return false;
  }
  claimed_ = true;
  return true;
}

bool FineOffsetUsb::ReadChunk(uint16_t address, std::vector<uint8_t>* chunk, std::string* error) {
  if (!handle_) {
    *error = "fine_offset USB: not open";
    return false;
  }
  auto command = FineOffsetReadCommand(address);
  int rc = libusb_control_transfer(handle_, LIBUSB_ENDPOINT_OUT | LIBUSB_REQUEST_TYPE_CLASS | LIBUSB_RECIPIENT_INTERFACE,
                                   0x09 /* HID SET_REPORT */, 0x0200, 0, command.data(), command.size(), kTimeoutMs);
  if (rc < 0) {
    *error = UsbError("read command", rc);
    if (rc == LIBUSB_ERROR_NO_DEVICE || rc == LIBUSB_ERROR_IO) Close();
    return false;
  }
  if (rc != static_cast<int>(command.size())) {
    *error = "fine_offset USB read command: " + std::to_string(rc) + " of 8 bytes sent";
    Close();  // what the console makes of half a command is unknown: start afresh
    return false;
  }
  chunk->assign(kFineOffsetChunkSize, 0);
  int got = 0;
  while (got < static_cast<int>(kFineOffsetChunkSize)) {
    int transferred = 0;
    rc = libusb_interrupt_transfer(handle_, 0x81, chunk->data() + got, kFineOffsetChunkSize - got, &transferred,
                                   kTimeoutMs);
    // A read that fails part way may leave the rest of the answer queued on the endpoint, and
    // every later read would then start that many bytes early (two such reads agree with each
    // other): the station is closed, and the next poll opens it afresh.
    // libusb reports the bytes a timed-out transfer did move: they count as part way too.
    if (transferred > 0) got += transferred;
    if (rc != 0) {
      *error = UsbError("interrupt read", rc) + (got > 0 ? " after " + std::to_string(got) + " of 32 bytes" : "");
      if (rc == LIBUSB_ERROR_NO_DEVICE || rc == LIBUSB_ERROR_IO || got > 0) Close();
      return false;
    }
    if (transferred <= 0) {
      *error = "fine_offset USB interrupt read: no data";
      if (got > 0) Close();
      return false;
    }
  }
  return true;
}

bool FineOffsetUsb::ReadCurrentRecord(std::vector<uint8_t>* record, uint16_t* address, std::string* error) {
  return ReadFineOffsetCurrentRecord(
      [this](uint16_t at, std::vector<uint8_t>* chunk, std::string* e) { return ReadChunk(at, chunk, e); }, record,
      address, error);
}

}  // namespace clothwind::sensors
