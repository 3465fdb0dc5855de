// Protocol selection and auto-detection for anemometer records, and the decoder the node uses:
// it classifies each record by its bytes, locks onto a protocol once a few records of it have
// parsed, and keeps the counters the node reports as diagnostics.
#ifndef CLOTHWIND_SENSORS_ANEMOMETER_PROTOCOL_H_
#define CLOTHWIND_SENSORS_ANEMOMETER_PROTOCOL_H_

#include <cstdint>
#include <map>
#include <string>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

enum class AnemometerProtocol { kAuto, kNmea, kGill, kCsv, kFineOffset };

// "auto", "nmea", "gill", "csv", "fine_offset" (also RawSentence.protocol's vocabulary).
const char* AnemometerProtocolName(AnemometerProtocol p);

// Parses a protocol name as above ("" means auto).
// Outputs:
//   p  the protocol
// Returns false for an unknown name.
bool ParseAnemometerProtocol(const std::string& name, AnemometerProtocol* p);

// The protocol a record's bytes look like: '$'/'!' -> nmea, STX -> gill, 32 or 40 hex digits ->
// fine_offset, numeric "a,b[,c]" -> csv; kAuto when it looks like none.
// Inputs:
//   record  one record without terminator
AnemometerProtocol ClassifyAnemometerRecord(const std::string& record);

// Parses a record with a given protocol (kAuto: with its classified protocol).
// Inputs:
//   record    one record without terminator
//   protocol  protocol to use
// Returns the parse result.
ParseResult ParseAnemometerRecord(const std::string& record, AnemometerProtocol protocol);

// Counters for diagnostics.
struct DecoderCounters {
  uint64_t records = 0;            // records seen
  uint64_t readings = 0;           // kOk results
  uint64_t invalid_readings = 0;   // kOk results flagged invalid by the instrument
  uint64_t not_wind = 0;           // well-formed records without wind
  uint64_t checksum_failures = 0;
  uint64_t parse_errors = 0;       // malformed, unrecognised, implausible (ImplausibleWindReason), or of
                                   // another protocol once locked
};

// Decodes a stream of records. With a configured protocol, every record is parsed with it. In
// auto mode each record is parsed with the protocol its bytes look like; after `lock_after`
// consecutive good records of one protocol the decoder locks onto it and rejects records of other
// protocols (noise that happens to look like a CSV line cannot then produce readings). After
// `unlock_after` consecutive good records of one other protocol it switches (the instrument was
// reconfigured). NMEA checksums are optional, but an instrument that sends them sends them on
// every sentence: once `lock_after` good sentences of one talker (the two letters after '$')
// carried one, a sentence of that talker without (its '*' lost to line noise, and with it the
// check of every other byte) is a checksum failure, until `unlock_after` such sentences in a row
// would have been good (the instrument was reconfigured). Talkers are told apart because a
// multiplexer merges instruments that differ (a GPS with checksums, a wind sensor without).
class AnemometerDecoder {
 public:
  // Inputs:
  //   protocol      kAuto to detect, or a fixed protocol
  //   lock_after    good records needed to lock (auto mode)
  //   unlock_after  good records of another protocol needed to switch (auto mode)
  explicit AnemometerDecoder(AnemometerProtocol protocol = AnemometerProtocol::kAuto, int lock_after = 3,
                             int unlock_after = 10);

  // Decodes one record.
  // Inputs:
  //   record  one record without terminator
  // Outputs:
  //   used  protocol the record was parsed with (kAuto when unrecognised); may be null
  // Returns the parse result (kMalformed with an explanation for a rejected record).
  ParseResult Decode(const std::string& record, AnemometerProtocol* used = nullptr);

  // The configured protocol, or in auto mode the locked one (kAuto until locked).
  AnemometerProtocol protocol() const;
  bool auto_mode() const { return configured_ == AnemometerProtocol::kAuto; }
  const DecoderCounters& counters() const { return counters_; }
  const std::string& last_error() const { return last_error_; }

 private:
  AnemometerProtocol configured_;
  AnemometerProtocol locked_ = AnemometerProtocol::kAuto;
  AnemometerProtocol candidate_ = AnemometerProtocol::kAuto;
  int candidate_count_ = 0;
  int lock_after_;
  int unlock_after_;
  struct NmeaChecksumHabit {
    int checksummed = 0;    // good sentences with a checksum since the last without was accepted
    int unchecked_run = 0;  // good-looking sentences without one in a row, refused
  };
  static constexpr size_t kMaxNmeaTalkers = 16;  // more (line noise's talkers) start the habits afresh
  std::map<std::string, NmeaChecksumHabit> nmea_habits_;  // by talker ("II", "WI", "GP", "PG")
  DecoderCounters counters_;
  std::string last_error_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_ANEMOMETER_PROTOCOL_H_
