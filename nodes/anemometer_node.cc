// anemometer_node: reads a wind instrument and publishes clothwind/WindMeasurement.
//   ~input = serial (default): termios serial port, NMEA 0183 / Gill WindSonic / CSV (auto-detected)
//            usb:              Fine Offset WH1080/WH3080-class station over libusb
//            topic:            parses anemometer/raw (RawSentence) from a rosbag replay
// In serial/usb modes every record is published as anemometer/raw (stamp = arrival of its first
// byte) and every reading as anemometer/wind with the same stamp. In topic mode the wind is
// stamped with the raw message's stamp, so a replay with use_sim_time keeps the recorded timing.
// The device is opened with back-off retries (a port that does not exist yet is not an error),
// and a vanished device is re-opened the same way (a USB station also after 3 failed reads in a
// row while open). See docs/anemometer.md.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <clothwind/RawSentence.h>
#include <clothwind/WindMeasurement.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wind_conversions.h"
#include "ros_bridge/wall_throttle.h"
#include "sensors/anemometer_protocol.h"
#include "sensors/anemometer_stream.h"
#include "sensors/backoff.h"
#include "sensors/clock_course.h"
#include "sensors/fine_offset_memory.h"
#include "sensors/fine_offset_record.h"
#include "sensors/fine_offset_usb.h"
#include "sensors/reading_frames.h"
#include "sensors/reading_rate.h"
#include "sensors/serial_port.h"
#include "sensors/usb_read_health.h"

namespace {

using clothwind::sensors::AnemometerDecoder;
using clothwind::sensors::AnemometerProtocol;
using clothwind::sensors::AnemometerProtocolName;
using clothwind::sensors::ParseResult;
using clothwind::sensors::ParseStatus;

// ~frame_id's default: the instrument's own frame (x towards its north mark).
constexpr const char* kDefaultFrameId = "anemometer";

class AnemometerNode {
 public:
  AnemometerNode(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh), pnh_(pnh), backoff_(0.1, 2.0) {}

  bool Init() {
    // Every parameter is read whatever ~input says (config/anemometer.yaml sets the serial port's
    // for a replay's topic input too): each is type-checked, and none is named unread for
    // belonging to another input.
    clothwind::ros_bridge::StrictParams params(pnh_);
    std::string protocol_name, parity;
    double initial = 0.1, maximum = 2.0;
    try {
      input_ = params.Get("input", "serial");
      frame_id_ = params.Get("frame_id", std::string(kDefaultFrameId));
      earth_frame_id_ = params.Get("earth_frame_id", "");
      if (params.Has("magnetic_declination")) {
        const double d = params.Get("magnetic_declination", 0.0);
        if (!std::isfinite(d) || d < -180.0 || d > 180.0)
          throw std::invalid_argument("~magnetic_declination: expected degrees east of true north in -180..180 "
                                      "(west negative)");
        magnetic_declination_ = d;
      }
      protocol_name = params.Get("protocol", "auto");
      initial = params.Get("reconnect_initial_delay", initial);
      maximum = params.Get("reconnect_max_delay", maximum);
      serial_.port = params.Get("port", "/dev/ttyUSB0");
      serial_.baud = params.Get("baud", 4800);
      serial_.data_bits = params.Get("data_bits", 8);
      parity = params.Get("parity", "none");
      serial_.stop_bits = params.Get("stop_bits", 1);
      usb_poll_period_ = params.Get("usb_poll_period", 10.0);
      stale_timeout_given_ = params.Has("stale_timeout");
      stale_timeout_ = params.Get("stale_timeout", 5.0);
    } catch (const std::exception& e) {
      ROS_FATAL("anemometer_node: %s", e.what());
      return false;
    }
    frames_ = clothwind::sensors::ReadingFrames(earth_frame_id_, kDefaultFrameId);
    params.Known("diagnostic_period");  // checked in main, read by diagnostic_updater (ros_bridge/wall_diagnostics.h)
    params.WarnUnread("anemometer_node");

    AnemometerProtocol protocol;
    if (!clothwind::sensors::ParseAnemometerProtocol(protocol_name, &protocol)) {
      ROS_FATAL("~protocol: '%s' unknown (expected auto, nmea, gill, csv or fine_offset)", protocol_name.c_str());
      return false;
    }
    if (input_ == "usb" && protocol == AnemometerProtocol::kAuto) protocol = AnemometerProtocol::kFineOffset;
    // A station's records are Fine Offset's: any other decoder refused every one, and no wind came.
    if (input_ == "usb" && protocol != AnemometerProtocol::kFineOffset) {
      ROS_FATAL("~protocol: '%s' cannot read ~input: usb, which reads a Fine Offset station (expected auto or "
                "fine_offset)", protocol_name.c_str());
      return false;
    }
    decoder_ = AnemometerDecoder(protocol);
    if (!PositiveSeconds("reconnect_initial_delay", initial) || !PositiveSeconds("reconnect_max_delay", maximum)) {
      return false;
    }
    const double first_delay = std::max(0.01, initial);
    backoff_ = clothwind::sensors::Backoff(first_delay, std::max(first_delay, maximum));

    updater_.add("anemometer", this, &AnemometerNode::Diagnose);
    // The serial settings end serial input when bad; usb and topic input do not use them, but a
    // replay of the field's YAML is where a bad one is best found: a WARN naming it there.
    std::string serial_error;
    if (!clothwind::sensors::ParseParity(parity, &serial_.parity)) {
      serial_error = "parity: '" + parity + "' unknown (expected none, even or odd)";
    } else {
      clothwind::sensors::ValidateSerialConfig(serial_, &serial_error);
    }
    if (!serial_error.empty() && input_ != "serial")
      ROS_WARN("anemometer_node: ~%s; unused with ~input %s, but a serial input would end on it",
               serial_error.c_str(), input_.c_str());
    if (input_ == "serial") {
      if (!serial_error.empty()) {
        ROS_FATAL("~%s", serial_error.c_str());
        return false;
      }
      updater_.setHardwareID(serial_.port);
      state_ = "waiting for " + serial_.port;
    } else if (input_ == "usb") {
      // The outdoor unit transmits every 48 s; allow two missed transmissions before warning.
      if (!stale_timeout_given_) stale_timeout_ = 3.0 * clothwind::sensors::kFineOffsetSensorPeriod;
      updater_.setHardwareID("usb:1941:8021");
      state_ = "waiting for USB station 1941:8021";
    } else if (input_ == "topic") {
      updater_.setHardwareID("topic:" + nh_.resolveName("anemometer/raw"));
      raw_sub_ = nh_.subscribe("anemometer/raw", 100, &AnemometerNode::OnRaw, this);
      state_ = "subscribed to " + raw_sub_.getTopic();
    } else {
      ROS_FATAL("~input: '%s' unknown (expected serial, usb or topic)", input_.c_str());
      return false;
    }
    if (!PositiveSeconds("stale_timeout", stale_timeout_) ||
        (input_ == "usb" && !PositiveSeconds("usb_poll_period", usb_poll_period_))) {
      return false;
    }
    if (input_ != "topic") raw_pub_ = nh_.advertise<clothwind::RawSentence>("anemometer/raw", 100);
    wind_pub_ = nh_.advertise<clothwind::WindMeasurement>("anemometer/wind", 100);
    ROS_INFO("anemometer_node: input %s, protocol %s, frame %s", input_.c_str(),
             AnemometerProtocolName(decoder_.protocol()), frame_id_.c_str());
    return true;
  }

  // A period parameter: finite, > 0 and at most a day (ros::WallDuration throws beyond its range,
  // and a zero poll period would poll the station without pause).
  static bool PositiveSeconds(const char* name, double value) {
    if (std::isfinite(value) && value > 0 && value <= 86400) return true;
    ROS_FATAL("~%s must be a time in seconds > 0 and <= 86400, got %g", name, value);
    return false;
  }

  void Run() {
    while (ros::ok()) {
      if (input_ == "serial") StepSerial();
      else if (input_ == "usb") StepUsb();
      else ros::WallDuration(0.02).sleep();
      ros::spinOnce();
      wall_diagnostics_.Update();
    }
    // Release the device on SIGINT (roscpp's handler ends ros::ok()).
    if (port_.is_open()) ROS_INFO("anemometer_node: closing %s", serial_.port.c_str());
    port_.Close();
    usb_.Close();
  }

 private:
  void StepSerial() {
    const ros::SteadyTime now = ros::SteadyTime::now();
    if (!port_.is_open()) {
      if (now < next_attempt_) {
        ros::WallDuration(std::min(0.05, (next_attempt_ - now).toSec())).sleep();
        return;
      }
      std::string error;
      if (port_.Open(serial_, &error)) {
        ROS_INFO("anemometer_node: opened %s at %d baud", serial_.port.c_str(), serial_.baud);
        framer_.Reset();
        // The back-off restarts when the instrument's bytes arrive, not when the port opens (as
        // for USB below): a port that opens and fails every read was reopened every 0.1 s, with
        // two log lines each time, for as long as it stayed so.
        state_ = "connected";
        ++connects_;
      } else {
        const double delay = backoff_.Next();
        WALL_WARN_THROTTLE(10.0, "anemometer_node: %s; retrying (every <= %.1f s)", error.c_str(), delay);
        state_ = "waiting: " + error;
        next_attempt_ = now + ros::WallDuration(delay);
      }
      return;
    }
    uint8_t buffer[512];
    size_t n = 0;
    std::string error;
    const auto status = port_.Read(buffer, sizeof(buffer), 50, &n, &error);
    if (status == clothwind::sensors::SerialPort::ReadStatus::kData) {
      backoff_.Reset();
      // All bytes of one read share its arrival time; a record is stamped with its first byte's.
      const ros::Time arrival = ros::Time::now();
      std::vector<clothwind::sensors::RawRecord> records;
      framer_.Feed(buffer, n, arrival.toSec(), &records);
      for (const auto& r : records) HandleRecord(r.data, ros::Time().fromSec(r.stamp), frame_id_, true);
    } else if (status == clothwind::sensors::SerialPort::ReadStatus::kFailed) {
      ROS_WARN("anemometer_node: %s; reconnecting", error.c_str());
      state_ = "disconnected: " + error;
      ++disconnects_;
      next_attempt_ = now + ros::WallDuration(backoff_.Next());
    }
  }

  void StepUsb() {
    const ros::SteadyTime now = ros::SteadyTime::now();
    if (!usb_.is_open()) {
      if (now < next_attempt_) {
        ros::WallDuration(std::min(0.05, (next_attempt_ - now).toSec())).sleep();
        return;
      }
      std::string error;
      if (usb_.Open(&error)) {
        ROS_INFO("anemometer_node: opened Fine Offset station");
        // The back-off restarts when the station answers a read, not when it opens: one that
        // opens and stays silent is reopened ever more slowly instead of every 0.1 s.
        usb_health_.Opened();
        state_ = "connected";
        ++connects_;
        next_poll_ = now;
      } else {
        // USB stations are unplugged for long stretches: back off to the poll period.
        const double delay = std::max(backoff_.Next(), 1.0);
        WALL_WARN_THROTTLE(30.0, "anemometer_node: %s; retrying", error.c_str());
        state_ = "waiting: " + error;
        next_attempt_ = now + ros::WallDuration(delay);
      }
      return;
    }
    if (now < next_poll_) {
      ros::WallDuration(std::min(0.05, (next_poll_ - now).toSec())).sleep();
      return;
    }
    next_poll_ = now + ros::WallDuration(usb_poll_period_);
    const ros::Time stamp = ros::Time::now();
    std::vector<uint8_t> record;
    uint16_t address = 0;
    std::string error;
    if (!usb_.ReadCurrentRecord(&record, &address, &error)) {
      ++usb_read_errors_;
      last_error_ = error;
      WALL_WARN_THROTTLE(30.0, "anemometer_node: %s", error.c_str());
      // A station that stays open but answers nothing (a wedged HID endpoint, a hub that lost
      // power) only recovers by being opened again.
      if (usb_health_.ReadFailed(error) && usb_.is_open()) {
        ROS_WARN("anemometer_node: %d USB reads in a row failed; reopening the station", usb_health_.errors_in_row());
        usb_.Close();
      }
      if (!usb_.is_open()) {
        state_ = "disconnected: " + error;
        ++disconnects_;
        next_attempt_ = now + ros::WallDuration(backoff_.Next());
      }
      return;
    }
    usb_health_.ReadSucceeded();
    backoff_.Reset();
    // The station rewrites the current record when its sensor transmits (every 48 s), but also
    // when its delay byte counts another minute, when indoor values or pressure change and when a
    // new history slot starts: publishing on those republished one 48 s wind value with later
    // stamps, counting it twice in a clip's label. Published when the wind or status bytes change,
    // or once a sensor period has passed without (steady wind is still a new measurement).
    if (!usb_gate_.ShouldPublish(record, now.toSec())) return;
    HandleRecord(clothwind::sensors::HexEncode(record), stamp, frame_id_, true);
  }

  void OnRaw(const clothwind::RawSentence::ConstPtr& msg) {
    // A record stamped 0, or further ahead of the clock than a replay's latency explains, would be
    // republished as a reading with that stamp, which the clip buffer then refuses (counted
    // there, far from its cause): dropped here and said in this node's diagnostics.
    // In double seconds: ros::Time's difference throws beyond 32 bits (a record stamped TIME_MAX
    // ended the node, uncaught in its callback).
    const ros::Time now = ros::Time::now();
    if (!now.isZero()) clock_.Note(now.toSec());
    const bool ahead = !now.isZero() && msg->header.stamp.toSec() - now.toSec() > kMaxFutureStamp;
    // Ahead of a clock that went back (a looped bag) but not past where it was: a record of the
    // previous pass still in flight, dropped without calling it a clock fault.
    if (ahead && clock_.IsPreviousPass(msg->header.stamp.toSec(), kMaxFutureStamp)) {
      ++previous_pass_;
      return;
    }
    const char* odd = msg->header.stamp.isZero() ? "stamped 0"
                      : ahead ? "stamped more than 5 s ahead of the clock"
                              : nullptr;
    if (odd) {
      ++odd_stamps_;
      last_odd_stamp_ = std::string(odd) + " (" + std::to_string(msg->header.stamp.toSec()) + " s, clock " +
                        std::to_string(now.toSec()) + " s)";
      return;
    }
    const std::string frame = msg->header.frame_id.empty() ? frame_id_ : msg->header.frame_id;
    HandleRecord(clothwind::ros_bridge::RawSentenceBytes(*msg), msg->header.stamp, frame, false);
  }

  void HandleRecord(const std::string& data, const ros::Time& stamp, const std::string& frame, bool publish_raw) {
    AnemometerProtocol used = AnemometerProtocol::kAuto;
    const ParseResult r = decoder_.Decode(data, &used);
    if (publish_raw) {
      const std::string protocol = used == AnemometerProtocol::kAuto ? "" : AnemometerProtocolName(used);
      raw_pub_.publish(clothwind::ros_bridge::ToRawSentence(data, protocol, stamp, frame));
    }
    // A replayed Fine Offset station (topic mode) reports every 48 s, as the live one: 5 s of
    // staleness read its every reading as stale. Its allowance, unless ~stale_timeout was given.
    if (used == AnemometerProtocol::kFineOffset && !stale_timeout_given_ &&
        stale_timeout_ < 3.0 * clothwind::sensors::kFineOffsetSensorPeriod)
      stale_timeout_ = 3.0 * clothwind::sensors::kFineOffsetSensorPeriod;
    if (r.status == ParseStatus::kOk) {
      wind_pub_.publish(clothwind::ros_bridge::ToWindMeasurement(r.reading, stamp, frames_.FrameFor(r.reading, frame),
                                                                 magnetic_declination_));
      last_status_ = r.reading.status;
      last_reading_void_ = !r.reading.valid;
      const double t = DiagnosticClock();
      if (r.reading.valid) {
        last_valid_ = r.reading;
        last_valid_time_ = t;
        have_valid_ = true;
      }
      reading_rate_.Add(t);
    } else if (r.status != ParseStatus::kNotWind) {
      last_error_ = r.error;
      ROS_DEBUG("anemometer_node: %s", r.error.c_str());
    }
  }

  // The clock of the readings' age and rate [s]: under simulated time (a replay) the replay's, as
  // on the wall clock a healthy 1 Hz instrument replayed at rate 0.15 turned "stale" every 6.5 s
  // and a paused replay read as a silent instrument; else the monotonic clock.
  static double DiagnosticClock() {
    return ros::Time::isSimTime() ? ros::Time::now().toSec() : ros::SteadyTime::now().toSec();
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    const auto& c = decoder_.counters();
    // Over the readings of the last 10 s, or of ~stale_timeout when longer (a Fine Offset station's
    // 144 s: one reading per 48 s read 0 Hz over 10 s); per report, a replay at -r 0.15 read 0 and
    // 6.6 Hz in turn.
    const double clock_now = DiagnosticClock();
    const double rate = reading_rate_.Rate(clock_now, std::max(10.0, stale_timeout_));
    const bool new_errors = c.checksum_failures + c.parse_errors > last_diag_errors_;
    last_diag_errors_ = c.checksum_failures + c.parse_errors;
    // (A clock that went back counts 0.)
    const double age = have_valid_ ? std::max(0.0, clock_now - last_valid_time_) : -1.0;

    const bool connected = input_ == "topic" || port_.is_open() || usb_.is_open();
    using diagnostic_msgs::DiagnosticStatus;
    if (!connected) stat.summary(DiagnosticStatus::ERROR, "not connected: " + state_);
    else if (!have_valid_) stat.summary(DiagnosticStatus::WARN, "connected, no valid reading yet");
    else if (age > stale_timeout_) stat.summary(DiagnosticStatus::WARN, "valid readings stale");
    else if (new_errors) stat.summary(DiagnosticStatus::WARN, "receiving, with bad records");
    else stat.summary(DiagnosticStatus::OK, "receiving");
    // The instrument's own word on its latest reading (Gill "04 axis 1 and 2 failed", a blocked path, NMEA status V, a
    // station that lost its outdoor sensor) says why readings are void; "stale" alone does not.
    // Open is not answering: failed USB reads warn, and a reopen that brought no answer is an error.
    if (input_ == "usb" && usb_health_.level() != clothwind::sensors::UsbReadHealth::Level::kOk)
      stat.mergeSummary(usb_health_.level() == clothwind::sensors::UsbReadHealth::Level::kError
                            ? DiagnosticStatus::ERROR
                            : DiagnosticStatus::WARN,
                        usb_health_.message());
    if (connected && last_reading_void_)
      stat.mergeSummary(DiagnosticStatus::WARN, "instrument flags its readings void: " + last_status_);
    for (const std::string& w : frames_.Warnings(std::isfinite(magnetic_declination_), frame_id_, input_ == "topic"))
      stat.mergeSummary(DiagnosticStatus::WARN, w);

    if (odd_stamps_ > last_diag_odd_stamps_)
      stat.mergeSummaryf(DiagnosticStatus::WARN, "%llu records dropped since last report: %s",
                         static_cast<unsigned long long>(odd_stamps_ - last_diag_odd_stamps_), last_odd_stamp_.c_str());
    last_diag_odd_stamps_ = odd_stamps_;

    stat.add("input", input_);
    stat.add("connection", state_);
    const AnemometerProtocol p = decoder_.protocol();
    stat.add("protocol", std::string(AnemometerProtocolName(p)) +
                             (decoder_.auto_mode() ? (p == AnemometerProtocol::kAuto ? " (detecting)" : " (detected)")
                                                   : " (configured)"));
    stat.add("records", c.records);
    if (input_ == "topic") stat.add("records dropped for their stamps", odd_stamps_);
    if (input_ == "topic") stat.add("records of the previous pass dropped (after the clock went back)", previous_pass_);
    stat.add("readings", c.readings);
    stat.add("invalid readings (instrument flagged)", c.invalid_readings);
    stat.addf("reading rate [Hz]", "%.3f", rate);
    stat.add("checksum failures", c.checksum_failures);
    stat.add("parse errors", c.parse_errors);
    stat.add("bytes dropped by framing", framer_.dropped_bytes());
    stat.add("last error", last_error_);
    stat.add("instrument status", last_status_.empty() ? "(none yet)" : last_status_);
    stat.add("magnetic declination [deg]",
             std::isfinite(magnetic_declination_) ? std::to_string(magnetic_declination_) : "(not set)");
    stat.add("earth frame", !earth_frame_id_.empty() ? earth_frame_id_
                            : input_ == "topic"  ? "each record's own (" + frame_id_ + ", ~frame_id, for records without one)"
                                                 : frame_id_ + " (~frame_id)");
    stat.add("connects", connects_);
    stat.add("disconnects", disconnects_);
    if (have_valid_) {
      stat.addf("last valid speed [m/s]", "%.3f", last_valid_.speed);
      stat.addf("last valid direction [rad]", "%.4f", clothwind::sensors::WindDirection(last_valid_, magnetic_declination_));
      stat.addf("last valid age [s]", "%.2f", age);
    } else {
      stat.add("last valid age [s]", "none yet");
    }
    if (input_ == "usb") {
      stat.add("usb read errors", usb_read_errors_);
      stat.addf("usb poll period [s]", "%.1f", usb_poll_period_);
      stat.add("update period", "the station's wind average is a ~48 s mean, refreshed every 48 s");
    }
  }

  ros::NodeHandle nh_, pnh_;
  ros::Publisher raw_pub_, wind_pub_;
  ros::Subscriber raw_sub_;
  diagnostic_updater::Updater updater_;
  clothwind::ros_bridge::WallDiagnostics wall_diagnostics_{&updater_};  // every wall second
  std::string input_, frame_id_, earth_frame_id_, state_, last_error_, last_status_;
  double magnetic_declination_ = std::numeric_limits<double>::quiet_NaN();  // [deg] east; NaN: unknown
  bool last_reading_void_ = false;
  clothwind::sensors::ReadingFrames frames_{"", kDefaultFrameId};  // set in Init
  clothwind::sensors::UsbReadHealth usb_health_{3};  // reopen after 3 failed reads in a row
  clothwind::sensors::SerialConfig serial_;
  clothwind::sensors::SerialPort port_;
  clothwind::sensors::FineOffsetUsb usb_;
  clothwind::sensors::RecordFramer framer_;
  AnemometerDecoder decoder_;
  clothwind::sensors::Backoff backoff_;
  // Steady (monotonic) time: the wall clock steps back under NTP, and a next-due instant then held
  // every poll and reconnect (and the USB gate's 48 s) until it caught up.
  ros::SteadyTime next_attempt_, next_poll_;
  // On DiagnosticClock [s]: the last valid reading's arrival, and the readings' for their rate over
  // 10 s or ~stale_timeout, whichever is longer.
  double last_valid_time_ = 0.0;
  clothwind::sensors::ReadingRate reading_rate_;
  double stale_timeout_ = 5.0;
  bool stale_timeout_given_ = false;  // ~stale_timeout set: kept whatever the instrument
  double usb_poll_period_ = 10.0;
  clothwind::sensors::FineOffsetPublishGate usb_gate_;  // which polled USB records are published
  uint64_t connects_ = 0, disconnects_ = 0, usb_read_errors_ = 0;
  // Topic mode: records dropped for their stamps (OnRaw), and the last one's reason.
  static constexpr double kMaxFutureStamp = 5.0;  // [s]
  uint64_t odd_stamps_ = 0, last_diag_odd_stamps_ = 0;
  uint64_t previous_pass_ = 0;              // topic mode: records of a looped bag's previous pass
  clothwind::sensors::ClockCourse clock_;  // topic mode: where the clock was before it went back
  std::string last_odd_stamp_;
  uint64_t last_diag_errors_ = 0;
  clothwind::sensors::WindReading last_valid_;
  bool have_valid_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "anemometer_node");
  ros::NodeHandle pnh("~");
  try {  // before the node's diagnostic_updater reads it
    clothwind::ros_bridge::StrictParams params(pnh);
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);
  } catch (const std::exception& e) {
    ROS_FATAL("anemometer_node: %s", e.what());
    return 1;
  }
  AnemometerNode node{ros::NodeHandle(), pnh};
  if (!node.Init()) return 1;
  node.Run();
  return 0;
}
