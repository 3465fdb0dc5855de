#include "sensors/fine_offset_usb.h"

#include <libusb.h>

#include <algorithm>

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
  chunk->assign(kFineOffsetChunkSize, 0);
  int got = 0;
  while (got < static_cast<int>(kFineOffsetChunkSize)) {
    int transferred = 0;
    rc = libusb_interrupt_transfer(handle_, 0x81, chunk->data() + got, kFineOffsetChunkSize - got, &transferred,
                                   kTimeoutMs);
    if (rc != 0) {
      *error = UsbError("interrupt read", rc);
      if (rc == LIBUSB_ERROR_NO_DEVICE || rc == LIBUSB_ERROR_IO) Close();
      return false;
    }
    if (transferred <= 0) {
      *error = "fine_offset USB interrupt read: no data";
      return false;
    }
    got += transferred;
  }
  return true;
}

bool FineOffsetUsb::ReadCurrentRecord(std::vector<uint8_t>* record, uint16_t* address, std::string* error) {
  std::vector<uint8_t> fixed;
  if (!ReadChunk(0x0000, &fixed, error)) return false;
  if (!FineOffsetCurrentAddress(fixed, address, error)) return false;
  // Reads are 32 bytes from any address; reading at the record itself gets it whole even when
  // it straddles a 32-byte boundary (the memory wraps at the top, so clamp to 0xFFE0).
  const uint16_t start = *address > 0xFFE0 ? 0xFFE0 : *address;
  const size_t offset = *address - start;
  // The console may be writing the record while we read it: accept two identical reads.
  std::vector<uint8_t> chunk, again;
  for (int attempt = 0; attempt < 3; ++attempt) {
    if (!ReadChunk(start, &chunk, error)) return false;
    if (!ReadChunk(start, &again, error)) return false;
    if (std::equal(chunk.begin() + offset, chunk.begin() + offset + kFineOffsetRecordSize, again.begin() + offset)) {
      record->assign(chunk.begin() + offset, chunk.begin() + offset + kFineOffsetRecordSize);
      return true;
    }
  }
  *error = "fine_offset USB: current record kept changing between reads";
  return false;
}

}  // namespace clothwind::sensors
