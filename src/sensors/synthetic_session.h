#ifndef CLOTHWIND_SENSORS_SYNTHETIC_SESSION_H_
#define CLOTHWIND_SENSORS_SYNTHETIC_SESSION_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace clothwind::sensors {

// Settings of a synthetic field session (`clothwind make-session`): a camera watching a flag and
// a 1 Hz NMEA anemometer next to it, both driven by one seeded wind.
struct SyntheticSessionOptions {
  double duration = 90.0;             // [s]
  double fps = 30.0;                  // camera's native rate [Hz]
  int width = 320;                    // image size [px]
  int height = 240;
  uint64_t seed = 1;
  double start_time = 1700000000.0;   // stamp of the session start [s since the epoch]
  double wind_base = 4.0;             // long-term mean wind speed [m/s]
  double wind_drift_std = 1.0;        // std of the slowly drifting mean [m/s]
  double wind_drift_tau = 40.0;       // correlation time of the drift [s]
  double turbulence_intensity = 0.15; // std of the fast fluctuation / current mean
  double turbulence_tau = 2.0;        // correlation time of the fluctuation [s]
  double direction_from = 270.0;      // mean MWV angle the wind comes from [deg, clockwise from bow]
  double direction_std = 15.0;        // its wander [deg]
  double anemometer_rate = 1.0;       // sentences per second [Hz]
  double anemometer_latency = 0.05;   // from measurement to the sentence's arrival [s]
  double frame_jitter = 0.002;        // std of capture-stamp jitter [s]
  double drop_probability = 0.0;      // chance a camera frame is lost
};

// The wind of a session: speed(t) = max(0.2, drift(t) + turbulence(t)), both Ornstein-Uhlenbeck
// processes (exact discretisation on a 20 ms grid, linear interpolation between), plus a slowly
// wandering direction. t is seconds since the session start.
class SyntheticWind {
 public:
  explicit SyntheticWind(const SyntheticSessionOptions& options);

  double Speed(double t) const;           // [m/s]
  double FromAngle(double t) const;       // MWV angle the wind comes from [deg, 0..360)
  // Mean speed over [t0, t1] [m/s] (what a cup anemometer reports for that interval).
  double MeanSpeed(double t0, double t1) const;
  // Phase of the flag's flutter [rad]: the integral of 2 pi FlutterFrequency(speed) dt from 0 to t.
  double FlutterPhase(double t) const;
  // How fast a flag flutters in a wind of `speed` [m/s]: f = 0.5 + 0.35 speed [Hz] (flags flap
  // roughly in proportion to the wind; the exact law matters only in that it grows).
  static double FlutterFrequency(double speed);

 private:
  double Interp(const std::vector<double>& v, double t) const;
  double dt_;
  std::vector<double> speed_, angle_, phase_;
};

// Draws one camera frame of the session. Pluggable, so a rendered flag (render/) can replace the
// procedural one without touching the session or the bag writer.
class FlagFrameGenerator {
 public:
  virtual ~FlagFrameGenerator() = default;
  // Inputs:
  //   t       capture time since the session start [s]
  //   wind    the session's wind
  //   width, height  image size [px]
  // Returns a height x width CV_8UC3 image, BGR.
  virtual cv::Mat Render(double t, const SyntheticWind& wind, int width, int height) const = 0;
};

// A flag on a pole against a sky: a striped cloth whose travelling wave moves with the wind's
// flutter phase (so its motion frequency grows with speed), with amplitude growing from the pole
// to the free end, droop in light wind, and shading from the wave's slope. Drawn with OpenCV.
class ProceduralFlagGenerator : public FlagFrameGenerator {
 public:
  cv::Mat Render(double t, const SyntheticWind& wind, int width, int height) const override;
};

// One anemometer sentence of the session.
struct SyntheticReading {
  double measured_at = 0.0;  // end of the 1/rate interval it averages [s since the epoch]
  double stamp = 0.0;        // arrival time = measured_at + latency [s since the epoch]
  double speed = 0.0;        // speed as written in the sentence (rounded to 0.01) [m/s]
  double angle = 0.0;        // angle as written (rounded to 0.1) [deg]
  std::string sentence;      // "$WIMWV,<angle>,R,<speed>,M,A*hh"
};

// NMEA 0183 MWV sentence with checksum for a wind from `angle_deg` (clockwise from the bow,
// relative) at `speed_mps` [m/s]: "$WIMWV,270.0,R,4.25,M,A*hh".
std::string FormatMwvSentence(double angle_deg, double speed_mps);

// A seeded, deterministic synthetic session: camera frame stamps (30 fps with jitter and optional
// drops) and anemometer sentences. Frames are drawn on demand (a session is too big to hold).
class SyntheticSession {
 public:
  // generator: null means ProceduralFlagGenerator.
  explicit SyntheticSession(const SyntheticSessionOptions& options,
                            std::shared_ptr<const FlagFrameGenerator> generator = nullptr);

  const SyntheticSessionOptions& options() const { return options_; }
  const SyntheticWind& wind() const { return wind_; }
  // Capture stamps of the frames [s since the epoch], strictly increasing.
  const std::vector<double>& frame_stamps() const { return frame_stamps_; }
  // Frame i (a height x width CV_8UC3 BGR image), drawn at its capture stamp.
  cv::Mat RenderFrame(size_t i) const;
  const std::vector<SyntheticReading>& readings() const { return readings_; }

 private:
  SyntheticSessionOptions options_;
  SyntheticWind wind_;
  std::shared_ptr<const FlagFrameGenerator> generator_;
  std::vector<double> frame_stamps_;
  std::vector<SyntheticReading> readings_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_SYNTHETIC_SESSION_H_
