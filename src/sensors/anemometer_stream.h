// Splits the byte stream of a serial anemometer into records, remembering when each record's
// first byte arrived (the stamp RawSentence and WindMeasurement carry).
#ifndef CLOTHWIND_SENSORS_ANEMOMETER_STREAM_H_
#define CLOTHWIND_SENSORS_ANEMOMETER_STREAM_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace clothwind::sensors {

// One record without its line terminator, and the arrival time of its first byte.
struct RawRecord {
  std::string data;
  double stamp = 0.0;  // [s], on whatever clock the caller passes to Feed()
};

// Frames records: CR or LF ends a record (CR LF gives one record); '$', '!' and STX start a new
// record, dropping a partial one before them (line noise, or a sentence cut when the port was
// opened mid-stream); a record longer than `max_length` is dropped whole. A new framer, and one
// Reset, takes the stream to start mid-record (a port opened, whose kernel buffer is flushed,
// while the instrument is half-way through a line): its bytes are dropped up to the first line end
// or start delimiter. A CSV record has no start delimiter, and its cut tail read as a reading of
// its own: "35,270" of "12.35,270", 35 m/s.
class RecordFramer {
 public:
  // Inputs:
  //   max_length  longest record kept [bytes]
  explicit RecordFramer(size_t max_length = 256);

  // Feeds bytes that arrived (all of them) at `arrival`.
  // Inputs:
  //   bytes, n  the bytes
  //   arrival   arrival time [s]
  // Outputs:
  //   out  complete records are appended
  void Feed(const uint8_t* bytes, size_t n, double arrival, std::vector<RawRecord>* out);

  // Forgets a partial record (after a reconnect its continuation will never come), and drops what
  // comes next up to the first line end or start delimiter (the reopened port's first line may be
  // cut).
  void Reset();

  size_t dropped_bytes() const { return dropped_bytes_; }  // partial/overlong/cut records dropped
  size_t overlong_records() const { return overlong_; }

 private:
  size_t max_length_;
  std::string partial_;
  double partial_stamp_ = 0.0;
  bool overlong_now_ = false;
  bool synced_ = false;  // a line end or start delimiter seen since construction or Reset
  size_t dropped_bytes_ = 0;
  size_t overlong_ = 0;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_ANEMOMETER_STREAM_H_
