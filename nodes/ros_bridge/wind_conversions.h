// Conversions between the ROS-free anemometer core (sensors::WindReading, raw records) and the
// clothwind/WindMeasurement and clothwind/RawSentence messages.
#ifndef CLOTHWIND_ROS_BRIDGE_WIND_CONVERSIONS_H_
#define CLOTHWIND_ROS_BRIDGE_WIND_CONVERSIONS_H_

#include <string>

#include <clothwind/RawSentence.h>
#include <clothwind/WindMeasurement.h>
#include <ros/time.h>

#include "sensors/wind_reading.h"

namespace clothwind::ros_bridge {

// Fills a WindMeasurement from a reading: speed, gust, direction and velocity in the REP 103
// convention of msg/WindMeasurement.msg (instrument angles -> pi - angle, compass bearings ->
// 3*pi/2 - bearing), valid, relative and source.
// Inputs:
//   reading   parsed reading (SI units)
//   stamp     arrival time of the record's first byte (or the raw message's stamp on replay)
//   frame_id  the frame the direction is in (the instrument's, or an ENU frame for bearings)
//   magnetic_declination  [deg] east of true north for magnetic bearings; NaN: unknown, such a
//             reading gets no direction (see sensors::WindDirection)
// Returns the message.
clothwind::WindMeasurement ToWindMeasurement(const sensors::WindReading& reading, const ros::Time& stamp,
                                             const std::string& frame_id,
                                             double magnetic_declination = sensors::kNaN);

// Makes a RawSentence. Bytes outside 0x01..0x7F are written as "\xHH" so the string is always
// valid UTF-8 (rospy decodes strings as UTF-8); the instruments' own records are plain ASCII
// (Gill's STX/ETX included), so real records pass unchanged.
// Inputs:
//   data      record bytes without line terminator
//   protocol  "nmea", "gill", "csv", "fine_offset" or ""
//   stamp     arrival time of the record's first byte
//   frame_id  the instrument's frame
// Returns the message.
clothwind::RawSentence ToRawSentence(const std::string& data, const std::string& protocol, const ros::Time& stamp,
                                     const std::string& frame_id);

// The record text of a RawSentence with "\xHH" escapes undone (inverse of ToRawSentence's escaping).
// Inputs:
//   msg  raw sentence
// Returns the record bytes.
std::string RawSentenceBytes(const clothwind::RawSentence& msg);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_ROS_BRIDGE_WIND_CONVERSIONS_H_
