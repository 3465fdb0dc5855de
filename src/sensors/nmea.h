// NMEA 0183 wind sentences: MWV (wind speed and angle), MWD (wind direction and speed) and XDR
// (transducer measurements, where a quadruplet names a wind quantity). Sentences are taken as
// one record without its line terminator, e.g. "$IIMWV,229.0,R,5.8,N,A*39".
#ifndef CLOTHWIND_SENSORS_NMEA_H_
#define CLOTHWIND_SENSORS_NMEA_H_

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

// A framed NMEA sentence: "$<talker><type>,<fields...>[*hh]".
struct NmeaSentence {
  std::string talker;               // e.g. "II", "WI" (2 characters; "P" for proprietary)
  std::string type;                 // e.g. "MWV"
  std::vector<std::string> fields;  // the comma separated fields after the address
  bool has_checksum = false;
};

// XOR of the characters between '$' (or '!') and '*' (exclusive), as NMEA 0183 defines it.
// Inputs:
//   body  the characters between the start delimiter and '*'
// Returns the checksum byte.
uint8_t NmeaChecksum(const std::string& body);

// Frames and checks one sentence. A sentence without "*hh" is accepted (many small sensors omit
// it); one with "*hh" must match.
// Inputs:
//   record  one line without terminator
// Outputs:
//   out    the sentence on success
//   error  on failure: kChecksumError or kMalformed with a message
// Returns true on success.
bool SplitNmeaSentence(const std::string& record, NmeaSentence* out, ParseResult* error);

// Parses one NMEA record into a wind reading: MWV, MWD and wind quadruplets of XDR give kOk;
// any other well-formed sentence gives kNotWind.
// Inputs:
//   record  one line without terminator
// Returns the parse result (speeds in m/s, angles as reported, see WindReading).
ParseResult ParseNmea(const std::string& record);

// Appends "*hh" to "$<body>", a helper for tests and simulators.
// Inputs:
//   body  the sentence without '$' and checksum, e.g. "IIMWV,229.0,R,5.8,N,A"
// Returns "$<body>*hh".
std::string WithNmeaChecksum(const std::string& body);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_NMEA_H_
