#include "sensors/anemometer_stream.h"

namespace clothwind::sensors {

RecordFramer::RecordFramer(size_t max_length) : max_length_(max_length) {}

void RecordFramer::Reset() {
  dropped_bytes_ += partial_.size();
  partial_.clear();
  overlong_now_ = false;
  synced_ = false;
}

void RecordFramer::Feed(const uint8_t* bytes, size_t n, double arrival, std::vector<RawRecord>* out) {
  for (size_t i = 0; i < n; ++i) {
    const char c = static_cast<char>(bytes[i]);
    const bool starts = c == '$' || c == '!' || c == '\x02';
    if (!synced_) {  // the tail of a record cut when the port opened
      if (c == '\r' || c == '\n') {
        synced_ = true;
        continue;
      }
      if (!starts) {
        ++dropped_bytes_;
        continue;
      }
      synced_ = true;
    }
    if (c == '\r' || c == '\n') {
      if (overlong_now_) {
        overlong_now_ = false;
      } else if (!partial_.empty()) {
        out->push_back({partial_, partial_stamp_});
      }
      partial_.clear();
      continue;
    }
    if (starts) {
      // A start delimiter always begins a record; whatever came before it on this line is noise.
      dropped_bytes_ += partial_.size();
      partial_.clear();
      overlong_now_ = false;
    }
    if (overlong_now_) {
      ++dropped_bytes_;
      continue;
    }
    if (partial_.empty()) partial_stamp_ = arrival;
    partial_.push_back(c);
    if (partial_.size() > max_length_) {
      dropped_bytes_ += partial_.size();
      partial_.clear();
      overlong_now_ = true;
      ++overlong_;
    }
  }
}

}  // namespace clothwind::sensors
