#include "sensors/wind_reading.h"

#include <cmath>
#include <cstdio>

namespace clothwind::sensors {

const char* ParseStatusName(ParseStatus s) {
  switch (s) {
    case ParseStatus::kOk: return "ok";
    case ParseStatus::kNotWind: return "not_wind";
    case ParseStatus::kChecksumError: return "checksum";
    case ParseStatus::kMalformed: return "malformed";
  }
  return "?";
}

double SpeedToMetresPerSecond(double value, SpeedUnit unit) {
  switch (unit) {
    case SpeedUnit::kMetresPerSecond: return value;
    case SpeedUnit::kKnots: return value * (1852.0 / 3600.0);          // 1 kn = 1852 m/h exactly
    case SpeedUnit::kKilometresPerHour: return value / 3.6;
    case SpeedUnit::kMilesPerHour: return value * (1609.344 / 3600.0); // international mile
    case SpeedUnit::kFeetPerMinute: return value * (0.3048 / 60.0);
  }
  return kNaN;
}

double WrapAngle(double angle) {
  if (!std::isfinite(angle)) return kNaN;
  double a = std::fmod(angle + M_PI, 2.0 * M_PI);  // (-2pi, 2pi)
  if (a <= 0.0) a += 2.0 * M_PI;                   // (0, 2pi]
  return a - M_PI;                                 // (-pi, pi]
}

double DirectionFromInstrumentAngle(double from_deg) {
  return WrapAngle(M_PI - from_deg * M_PI / 180.0);
}

double DirectionFromBearing(double bearing_deg) {
  return WrapAngle(1.5 * M_PI - bearing_deg * M_PI / 180.0);
}

double WindDirection(const WindReading& r, double magnetic_declination) {
  if (!std::isfinite(r.from_angle_deg)) return kNaN;
  switch (r.reference) {
    case AngleReference::kInstrument: return DirectionFromInstrumentAngle(r.from_angle_deg);
    case AngleReference::kEarth: return DirectionFromBearing(r.from_angle_deg);
    case AngleReference::kMagnetic:
      // Without the declination a magnetic bearing would be taken as true and be off by up to
      // tens of degrees (or more near the poles): no direction rather than a wrong one.
      if (!std::isfinite(magnetic_declination)) return kNaN;
      return DirectionFromBearing(r.from_angle_deg + magnetic_declination);
    case AngleReference::kNone: break;
  }
  return kNaN;
}

std::string ImplausibleWindReason(const WindReading& r) {
  auto outside = [](const char* field, double v, double lo, double hi, const char* unit) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s %g %s outside the plausible %g..%g %s", field, v, unit, lo, hi, unit);
    return std::string(buf);
  };
  if (!std::isnan(r.speed) && !(r.speed >= 0.0 && r.speed <= kMaxPlausibleWindSpeed))
    return outside("speed", r.speed, 0.0, kMaxPlausibleWindSpeed, "m/s");
  if (!std::isnan(r.gust) && !(r.gust >= 0.0 && r.gust <= kMaxPlausibleWindSpeed))
    return outside("gust", r.gust, 0.0, kMaxPlausibleWindSpeed, "m/s");
  if (!std::isnan(r.from_angle_deg) && !(r.from_angle_deg >= 0.0 && r.from_angle_deg <= 360.0))
    return outside("direction", r.from_angle_deg, 0.0, 360.0, "deg");
  return "";
}

std::array<double, 3> WindVelocity(const WindReading& r, double magnetic_declination) {
  const double d = WindDirection(r, magnetic_declination);
  if (!std::isfinite(r.speed)) return {kNaN, kNaN, kNaN};
  if (!std::isfinite(d)) {
    if (r.speed == 0.0) return {0.0, 0.0, 0.0};
    return {kNaN, kNaN, kNaN};
  }
  return {r.speed * std::cos(d), r.speed * std::sin(d), 0.0};
}

}  // namespace clothwind::sensors
