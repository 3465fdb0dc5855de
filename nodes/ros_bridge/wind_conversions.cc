#include "ros_bridge/wind_conversions.h"

#include <cctype>
#include <cstdio>

namespace clothwind::ros_bridge {

clothwind::WindMeasurement ToWindMeasurement(const sensors::WindReading& r, const ros::Time& stamp,
                                             const std::string& frame_id, double magnetic_declination) {
  clothwind::WindMeasurement m;
  m.header.stamp = stamp;
  m.header.frame_id = frame_id;
  m.speed = r.speed;
  m.gust = r.gust;
  m.direction = sensors::WindDirection(r, magnetic_declination);
  const auto v = sensors::WindVelocity(r, magnetic_declination);
  m.velocity.x = v[0];
  m.velocity.y = v[1];
  m.velocity.z = v[2];
  m.valid = r.valid;
  m.relative = r.relative;
  m.source = r.source;
  return m;
}

clothwind::RawSentence ToRawSentence(const std::string& data, const std::string& protocol, const ros::Time& stamp,
                                     const std::string& frame_id) {
  clothwind::RawSentence m;
  m.header.stamp = stamp;
  m.header.frame_id = frame_id;
  m.protocol = protocol;
  m.data.reserve(data.size());
  for (unsigned char c : data) {
    if (c == 0 || c >= 0x80 || c == '\\') {
      char esc[8];
      std::snprintf(esc, sizeof(esc), "\\x%02X", c);
      m.data += esc;
    } else {
      m.data.push_back(static_cast<char>(c));
    }
  }
  return m;
}

std::string RawSentenceBytes(const clothwind::RawSentence& msg) {
  const std::string& s = msg.data;
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 3 < s.size() && s[i + 1] == 'x' && std::isxdigit(static_cast<unsigned char>(s[i + 2])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 3]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(i + 2, 2), nullptr, 16)));
      i += 3;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

}  // namespace clothwind::ros_bridge
