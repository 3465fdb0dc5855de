// Plain CSV wind lines from home-made or logger anemometers: "speed,direction[,gust]" with speed
// and gust in m/s and direction the "from" angle in degrees clockwise from the instrument's north
// mark (empty when unknown). A header line starting with "speed" is recognised and ignored.
#ifndef CLOTHWIND_SENSORS_CSV_WIND_H_
#define CLOTHWIND_SENSORS_CSV_WIND_H_

#include <string>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

// True when the record has the shape of a CSV wind line or header: 2 or 3 comma separated
// fields made of digits, sign, '.', 'e' and spaces (or the header words).
// Inputs:
//   record  one line without terminator
bool LooksLikeCsvWind(const std::string& record);

// Parses one CSV wind line.
// Inputs:
//   record  one line without terminator
// Returns kOk with speed/gust [m/s] and from-angle [deg], kNotWind for the header line,
// kMalformed (naming the field) otherwise.
ParseResult ParseCsvWind(const std::string& record);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CSV_WIND_H_
