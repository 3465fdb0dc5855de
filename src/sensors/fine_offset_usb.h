// libusb I/O for Fine Offset WH1080/WH3080-class stations (USB 1941:8021). Only moves bytes:
// the decoding lives in fine_offset_record.h so it can be tested without a station.
// Protocol (HID device without report descriptors worth using): send the 8-byte read command
// as a SET_REPORT control transfer (bmRequestType 0x21, bRequest 0x09, wValue 0x0200, wIndex 0),
// then read 32 bytes from interrupt endpoint 0x81 (in 8-byte packets).
#ifndef CLOTHWIND_SENSORS_FINE_OFFSET_USB_H_
#define CLOTHWIND_SENSORS_FINE_OFFSET_USB_H_

#include <cstdint>
#include <string>
#include <vector>

struct libusb_context;
struct libusb_device_handle;

namespace clothwind::sensors {

class FineOffsetUsb {
 public:
  FineOffsetUsb() = default;
  ~FineOffsetUsb();
  FineOffsetUsb(const FineOffsetUsb&) = delete;
  FineOffsetUsb& operator=(const FineOffsetUsb&) = delete;

  // Opens the first 1941:8021 device, detaching the kernel HID driver and claiming interface 0.
  // Outputs:
  //   error  why it failed (not found, permission: see docs/anemometer.md for the udev rule)
  // Returns true on success.
  bool Open(std::string* error);

  // Releases the interface and closes (safe to call twice).
  void Close();

  bool is_open() const { return handle_ != nullptr; }

  // Reads 32 bytes of station memory.
  // Inputs:
  //   address  0x0000..0xFFE0
  // Outputs:
  //   chunk  32 bytes
  //   error  on failure (the device is closed when it vanished or a read stopped part way)
  // Returns true on success.
  bool ReadChunk(uint16_t address, std::vector<uint8_t>* chunk, std::string* error);

  // The current record (ReadFineOffsetCurrentRecord, fine_offset_memory.h, through ReadChunk).
  // Outputs:
  //   record   16 bytes of the current record
  //   address  its address
  //   error    on failure
  // Returns true on success.
  bool ReadCurrentRecord(std::vector<uint8_t>* record, uint16_t* address, std::string* error);

 private:
  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  bool claimed_ = false;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_FINE_OFFSET_USB_H_
