// Gill WindSonic ASCII output ("Gill format"), polar and UV, as the WindSonic manual (doc 1405 PS
// 0019, section 9) documents it:
//   <STX>Q,229,002.74,M,00,<ETX>16          polar: node, direction [deg], speed, units, status
//   <STX>Q,+001.59,-002.74,M,00,<ETX>hh     UV: node, U, V, units, status
// The checksum is the XOR of the bytes between (not including) STX and ETX, sent as two hex
// digits after ETX. Units: M m/s, N knots, P mph, K km/h, F ft/min. Status: 00 ok, 01/02/04
// axis failed, 08 NVM error, 09 ROM error, 0A/10 system gain at maximum, 51 average building,
// 60 heating enabled and ok. Any status other than 00, 51 and 60 marks the reading invalid.
#ifndef CLOTHWIND_SENSORS_GILL_WINDSONIC_H_
#define CLOTHWIND_SENSORS_GILL_WINDSONIC_H_

#include <cstdint>
#include <string>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

constexpr char kGillStx = '\x02';
constexpr char kGillEtx = '\x03';

// XOR of the bytes between STX and ETX (exclusive).
// Inputs:
//   body  bytes between STX and ETX
// Returns the checksum byte.
uint8_t GillChecksum(const std::string& body);

// Builds a complete Gill record (STX body ETX hh), without CR LF; a helper for tests/simulators.
// Inputs:
//   body  e.g. "Q,229,002.74,M,00,"
// Returns the framed record.
std::string FrameGillRecord(const std::string& body);

// Meaning of a Gill status code ("00" -> "ok", "01" -> "axis 1 failed", ...).
// Inputs:
//   code  status field as sent
// Outputs:
//   valid  whether readings with this status are trustworthy
// Returns a short description.
std::string GillStatusText(const std::string& code, bool* valid);

// Parses one Gill ASCII record (starting with STX, without the line terminator).
// Polar direction is "from", in whole degrees clockwise from the instrument's north mark (none
// below 0.05 m/s, where the instrument leaves it empty or, in fixed-field mode, frozen). In UV mode +U is air moving towards the north mark and +V air moving
// towards the west side, i.e. (U, V) are the velocity's x and y in the REP 103 instrument frame
// (x to the north mark, y left); the from-angle is derived from them.
// Inputs:
//   record  the record bytes
// Returns the parse result; kChecksumError when the checksum does not match.
ParseResult ParseGillWindSonic(const std::string& record);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_GILL_WINDSONIC_H_
