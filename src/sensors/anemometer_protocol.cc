#include "sensors/anemometer_protocol.h"

#include <cctype>

#include "sensors/csv_wind.h"
#include "sensors/fine_offset_record.h"
#include "sensors/gill_windsonic.h"
#include "sensors/nmea.h"

namespace clothwind::sensors {

const char* AnemometerProtocolName(AnemometerProtocol p) {
  switch (p) {
    case AnemometerProtocol::kAuto: return "auto";
    case AnemometerProtocol::kNmea: return "nmea";
    case AnemometerProtocol::kGill: return "gill";
    case AnemometerProtocol::kCsv: return "csv";
    case AnemometerProtocol::kFineOffset: return "fine_offset";
  }
  return "?";
}

bool ParseAnemometerProtocol(const std::string& name, AnemometerProtocol* p) {
  if (name.empty() || name == "auto") *p = AnemometerProtocol::kAuto;
  else if (name == "nmea") *p = AnemometerProtocol::kNmea;
  else if (name == "gill") *p = AnemometerProtocol::kGill;
  else if (name == "csv") *p = AnemometerProtocol::kCsv;
  else if (name == "fine_offset") *p = AnemometerProtocol::kFineOffset;
  else return false;
  return true;
}

AnemometerProtocol ClassifyAnemometerRecord(const std::string& record) {
  if (record.empty()) return AnemometerProtocol::kAuto;
  if (record[0] == '$' || record[0] == '!') return AnemometerProtocol::kNmea;
  if (record[0] == kGillStx) return AnemometerProtocol::kGill;
  if (record.size() == 2 * kFineOffsetRecordSize || record.size() == 40) {
    bool hex = true;
    for (char c : record) hex = hex && std::isxdigit(static_cast<unsigned char>(c));
    if (hex) return AnemometerProtocol::kFineOffset;
  }
  if (LooksLikeCsvWind(record)) return AnemometerProtocol::kCsv;
  return AnemometerProtocol::kAuto;
}

ParseResult ParseAnemometerRecord(const std::string& record, AnemometerProtocol protocol) {
  if (protocol == AnemometerProtocol::kAuto) protocol = ClassifyAnemometerRecord(record);
  switch (protocol) {
    case AnemometerProtocol::kNmea: return ParseNmea(record);
    case AnemometerProtocol::kGill: return ParseGillWindSonic(record);
    case AnemometerProtocol::kCsv: return ParseCsvWind(record);
    case AnemometerProtocol::kFineOffset: return ParseFineOffsetHex(record);
    case AnemometerProtocol::kAuto: break;
  }
  ParseResult r;
  r.error = "unrecognised record (not NMEA, Gill, CSV or Fine Offset hex)";
  return r;
}

AnemometerDecoder::AnemometerDecoder(AnemometerProtocol protocol, int lock_after, int unlock_after)
    : configured_(protocol), lock_after_(lock_after), unlock_after_(unlock_after) {}

AnemometerProtocol AnemometerDecoder::protocol() const {
  return configured_ != AnemometerProtocol::kAuto ? configured_ : locked_;
}

ParseResult AnemometerDecoder::Decode(const std::string& record, AnemometerProtocol* used) {
  ++counters_.records;
  AnemometerProtocol p = configured_;
  if (p == AnemometerProtocol::kAuto) p = ClassifyAnemometerRecord(record);
  if (used) *used = p;
  ParseResult r = ParseAnemometerRecord(record, p);
  if (p == AnemometerProtocol::kNmea && (r.status == ParseStatus::kOk || r.status == ParseStatus::kNotWind)) {
    // Per talker: a multiplexer merging a GPS that sends checksums with a wind sensor that sends
    // none ($GPGGA...*47 between $WIMWV... without) had every wind sentence refused, as one
    // instrument whose '*' was lost.
    const std::string talker = record.substr(1, 2);
    if (nmea_habits_.size() >= kMaxNmeaTalkers && nmea_habits_.count(talker) == 0) nmea_habits_.clear();
    NmeaChecksumHabit& habit = nmea_habits_[talker];
    if (record.find('*') != std::string::npos) {
      ++habit.checksummed;
      habit.unchecked_run = 0;
    } else if (habit.checksummed >= lock_after_) {
      if (++habit.unchecked_run >= unlock_after_) {
        habit = NmeaChecksumHabit();  // reconfigured: sentences without are the norm now
      } else {
        r = ParseResult();
        r.status = ParseStatus::kChecksumError;
        r.error = "NMEA: no checksum, where talker " + talker +
                  "'s sentences carry one (its '*' lost to line noise?)";
      }
    }
  }
  const bool good = r.status == ParseStatus::kOk || r.status == ParseStatus::kNotWind;
  // Good records of one protocol with none of another between them: line noise and checksum
  // failures between them count neither way (a noisy line still locks), but a good record of
  // another protocol starts the count again.
  if (auto_mode() && p != AnemometerProtocol::kAuto && good) {
    if (p == candidate_) ++candidate_count_;
    else candidate_ = p, candidate_count_ = 1;
    if (locked_ == AnemometerProtocol::kAuto && candidate_count_ >= lock_after_) locked_ = p;
    if (locked_ != AnemometerProtocol::kAuto && locked_ != p && candidate_count_ >= unlock_after_) locked_ = p;
  }
  if (auto_mode() && locked_ != AnemometerProtocol::kAuto && p != locked_ && good) {
    // Locked onto another protocol: this record is noise until enough of it prove otherwise.
    r = ParseResult();
    r.error = std::string("record looks like ") + AnemometerProtocolName(p) + " but the instrument speaks " +
              AnemometerProtocolName(locked_);
  }
  if (r.status == ParseStatus::kOk && r.reading.valid) {
    const std::string why = ImplausibleWindReason(r.reading);
    if (!why.empty()) {
      r.status = ParseStatus::kMalformed;
      r.error = r.reading.source + ": " + why;
    }
  }
  switch (r.status) {
    case ParseStatus::kOk:
      ++counters_.readings;
      if (!r.reading.valid) ++counters_.invalid_readings;
      break;
    case ParseStatus::kNotWind: ++counters_.not_wind; break;
    case ParseStatus::kChecksumError:
      ++counters_.checksum_failures;
      last_error_ = r.error;
      break;
    case ParseStatus::kMalformed:
      ++counters_.parse_errors;
      last_error_ = r.error;
      break;
  }
  return r;
}

}  // namespace clothwind::sensors
