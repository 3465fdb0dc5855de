// One anemometer reading in SI units, independent of the protocol that produced it, plus the unit
// and direction conversions every protocol shares. The direction convention is the one written
// in msg/WindMeasurement.msg: direction = angle of the air's motion (where it blows TO), counter-
// clockwise about +z from +x of the instrument frame, in (-pi, pi].
#ifndef CLOTHWIND_SENSORS_WIND_READING_H_
#define CLOTHWIND_SENSORS_WIND_READING_H_

#include <array>
#include <limits>
#include <string>

namespace clothwind::sensors {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Speed units anemometers report. Each protocol maps its own letters onto these (NMEA uses
// 'S' for statute mph, Gill uses 'P'), so the letter tables stay in the protocol files.
enum class SpeedUnit { kMetresPerSecond, kKnots, kKilometresPerHour, kMilesPerHour, kFeetPerMinute };

// What a reported "from" angle is measured against.
enum class AngleReference {
  kNone,        // no direction reported
  kInstrument,  // clockwise from the instrument's north mark / the bow (NMEA MWV, Gill, CSV)
  kEarth,       // compass bearing clockwise from true north (NMEA MWD, a north-aligned station)
  kMagnetic,    // compass bearing clockwise from magnetic north (NMEA MWD without a true bearing);
                // needs the local magnetic declination to become a direction
};

// Fastest wind any instrument read here can report (Gill WindSonic 60 m/s, Fine Offset ~50):
// a reading beyond it is a misread unit or a corrupt record, not wind. [m/s]
inline constexpr double kMaxPlausibleWindSpeed = 90.0;

// A parsed reading. Angles are kept as reported (degrees, "from", clockwise) so that the raw
// meaning survives; WindDirection()/WindVelocity() apply the REP 103 convention.
struct WindReading {
  double speed = kNaN;           // horizontal speed [m/s]; NaN when not reported/invalid
  double gust = kNaN;            // gust speed [m/s]; NaN when the instrument reports none
  double from_angle_deg = kNaN;  // where the wind comes FROM, clockwise from `reference` [deg]
  AngleReference reference = AngleReference::kNone;
  bool valid = true;             // false: the instrument flagged the reading void
  bool relative = false;         // true: apparent (relative) wind
  std::string source;            // nmea_mwv, nmea_mwd, nmea_xdr, gill, csv, fine_offset
  std::string status;            // instrument status text, e.g. "A", "00 ok", "lost contact"
};

// Outcome of parsing one record.
enum class ParseStatus {
  kOk,             // a wind reading (possibly flagged invalid by the instrument: see valid)
  kNotWind,        // well-formed, checksum fine, but carries no wind (e.g. NMEA GGA, a CSV header)
  kChecksumError,  // framing fine, checksum wrong
  kMalformed,      // truncated, wrong field count, bad number, unknown unit, garbage
};

// One record's parse: status, reading (meaningful when kOk) and, otherwise, why it failed
// (naming the field and what was expected).
struct ParseResult {
  ParseStatus status = ParseStatus::kMalformed;
  WindReading reading;
  std::string error;
};

// Name of a status for logs and diagnostics ("ok", "not_wind", "checksum", "malformed").
const char* ParseStatusName(ParseStatus s);

// Converts a speed to m/s.
// Inputs:
//   value  speed in `unit`
//   unit   unit of value
// Returns value [m/s].
double SpeedToMetresPerSecond(double value, SpeedUnit unit);

// Wraps an angle to (-pi, pi].
// Inputs:
//   angle  [rad], any finite value
// Returns the equivalent angle in (-pi, pi] [rad]; NaN stays NaN.
double WrapAngle(double angle);

// Direction (REP 103, "to", CCW from +x) of a wind reported as coming FROM `from_deg` degrees
// clockwise from the instrument's north mark (x forward): pi - from.
// Inputs:
//   from_deg  [deg]
// Returns direction in (-pi, pi] [rad].
double DirectionFromInstrumentAngle(double from_deg);

// Direction (REP 103, "to", CCW from east in an ENU frame) of a wind coming FROM compass bearing
// `bearing_deg` (clockwise from north): 3*pi/2 - bearing.
// Inputs:
//   bearing_deg  [deg]
// Returns direction in (-pi, pi] [rad].
double DirectionFromBearing(double bearing_deg);

// The reading's direction in the WindMeasurement convention, NaN when it has none.
// Inputs:
//   r                     reading
//   magnetic_declination  [deg] east of true north, for kMagnetic bearings (true = magnetic +
//                         declination); NaN (unknown) gives a magnetic bearing no direction
// Returns direction [rad] in (-pi, pi] or NaN.
double WindDirection(const WindReading& r, double magnetic_declination = kNaN);

// The reading's air velocity speed * (cos d, sin d, 0) in the instrument (or ENU) frame.
// A calm reading without direction (speed 0) gives the zero vector; a non-zero speed without
// direction gives NaNs, since the vector is unknown.
// Inputs:
//   r                     reading
//   magnetic_declination  as WindDirection's
// Returns velocity [m/s], 3 components.
std::array<double, 3> WindVelocity(const WindReading& r, double magnetic_declination = kNaN);

// Why a reading the instrument calls valid cannot be wind, or "" when it can: speed or gust not
// in [0, kMaxPlausibleWindSpeed], a reported angle not in [0, 360] deg.
// Inputs:
//   r  reading
// Returns the reason, naming the field and the value.
std::string ImplausibleWindReason(const WindReading& r);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_WIND_READING_H_
