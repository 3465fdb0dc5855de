#include "sensors/synthetic_session.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace clothwind::sensors {
namespace {

SyntheticSessionOptions Short(uint64_t seed) {
  SyntheticSessionOptions o;
  o.duration = 12.0;
  o.seed = seed;
  return o;
}

TEST(SyntheticSessionTest, MwvSentenceHasValidChecksum) {
  const std::string s = FormatMwvSentence(270.04, 4.256);
  ASSERT_EQ(s.rfind("$WIMWV,270.0,R,4.26,M,A*", 0), 0u) << s;
  // Checksum recomputed by hand: XOR of the bytes between '$' and '*'.
  uint8_t x = 0;
  for (size_t i = 1; i < s.find('*'); ++i) x ^= static_cast<uint8_t>(s[i]);
  unsigned written = 0;
  ASSERT_EQ(std::sscanf(s.c_str() + s.find('*') + 1, "%2X", &written), 1);
  EXPECT_EQ(written, x);
  EXPECT_EQ(s.size(), s.find('*') + 3);
}

TEST(SyntheticSessionTest, DeterministicForASeedAndDifferentAcrossSeeds) {
  const SyntheticSession a(Short(5)), b(Short(5)), c(Short(6));
  ASSERT_EQ(a.frame_stamps(), b.frame_stamps());
  ASSERT_EQ(a.readings().size(), b.readings().size());
  for (size_t i = 0; i < a.readings().size(); ++i) EXPECT_EQ(a.readings()[i].sentence, b.readings()[i].sentence);
  EXPECT_EQ(cv::norm(a.RenderFrame(100), b.RenderFrame(100), cv::NORM_INF), 0.0);
  bool differs = false;
  for (size_t i = 0; i < a.readings().size(); ++i) differs |= a.readings()[i].sentence != c.readings()[i].sentence;
  EXPECT_TRUE(differs);
}

TEST(SyntheticSessionTest, CameraAndAnemometerTiming) {
  const SyntheticSession s(Short(1));
  const auto& st = s.frame_stamps();
  ASSERT_EQ(st.size(), 360u);  // 12 s at 30 fps, no drops
  for (size_t i = 1; i < st.size(); ++i) {
    EXPECT_GT(st[i], st[i - 1]);
    EXPECT_NEAR(st[i] - st[i - 1], 1.0 / 30.0, 0.009);
  }
  const auto& r = s.readings();
  ASSERT_EQ(r.size(), 11u);  // 1 Hz; the 12th would arrive after the session ends
  for (size_t k = 0; k < r.size(); ++k) {
    EXPECT_NEAR(r[k].stamp, 1700000000.0 + (k + 1) + 0.05, 1e-6);
    EXPECT_GE(r[k].speed, 0.2);
    EXPECT_LT(r[k].speed, 20.0);
    // The sentence carries the recorded value.
    char speed[16];
    std::snprintf(speed, sizeof speed, ",%.2f,M,", r[k].speed);
    EXPECT_NE(r[k].sentence.find(speed), std::string::npos) << r[k].sentence;
  }
  const cv::Mat f = s.RenderFrame(0);
  EXPECT_EQ(f.type(), CV_8UC3);
  EXPECT_EQ(f.cols, 320);
  EXPECT_EQ(f.rows, 240);
}

TEST(SyntheticSessionTest, DroppedFramesLeaveHoles) {
  SyntheticSessionOptions o = Short(2);
  o.drop_probability = 0.2;
  const SyntheticSession s(o);
  EXPECT_LT(s.frame_stamps().size(), 330u);
  EXPECT_GT(s.frame_stamps().size(), 240u);
}

// Counts how often the flag region's mean brightness crosses its average over `seconds` of a
// steady wind: twice per flutter period.
double FlutterCrossingsPerSecond(double speed) {
  SyntheticSessionOptions o;
  o.duration = 6.0;
  o.wind_base = speed;
  o.wind_drift_std = 0.0;
  o.turbulence_intensity = 0.0;
  o.frame_jitter = 0.0;
  o.fps = 60.0;
  const SyntheticSession s(o);
  std::vector<double> v;
  for (size_t i = 0; i < s.frame_stamps().size(); ++i) {
    cv::Mat grey;
    cv::cvtColor(s.RenderFrame(i), grey, cv::COLOR_BGR2GRAY);
    v.push_back(cv::mean(grey(cv::Rect(200, 50, 40, 90)))[0]);  // near the free end
  }
  double avg = 0;
  for (double x : v) avg += x / v.size();
  int crossings = 0;
  for (size_t i = 1; i < v.size(); ++i) crossings += (v[i - 1] - avg) * (v[i] - avg) < 0;
  return crossings / o.duration;
}

TEST(SyntheticSessionTest, FlagFluttersFasterInStrongerWind) {
  const double slow = FlutterCrossingsPerSecond(2.0), fast = FlutterCrossingsPerSecond(8.0);
  // Expected flutter: 1.2 Hz at 2 m/s, 3.3 Hz at 8 m/s (0.5 + 0.35 v Hz, docs/clips.md) -> about
  // 2.4 and 6.6 crossings per second.
  EXPECT_NEAR(SyntheticWind::FlutterFrequency(2.0), 1.2, 1e-12);
  EXPECT_NEAR(SyntheticWind::FlutterFrequency(8.0), 3.3, 1e-12);
  EXPECT_NEAR(slow, 2.0 * SyntheticWind::FlutterFrequency(2.0), 1.0);
  EXPECT_NEAR(fast, 2.0 * SyntheticWind::FlutterFrequency(8.0), 1.5);
  EXPECT_GT(fast, 1.8 * slow);
}

TEST(SyntheticSessionTest, WindDriftsButStaysPlausible) {
  SyntheticSessionOptions o;
  o.duration = 300.0;
  const SyntheticWind w(o);
  double lo = 1e9, hi = 0;
  for (double t = 0; t < 300; t += 0.5) {
    lo = std::min(lo, w.Speed(t));
    hi = std::max(hi, w.Speed(t));
  }
  EXPECT_GE(lo, 0.2);
  EXPECT_LT(hi, 15.0);
  EXPECT_GT(hi - lo, 0.5);  // it does change
  EXPECT_NEAR(w.MeanSpeed(10.0, 10.0), w.Speed(10.0), 1e-12);
  // The window mean every anemometer reading carries, against a fine Riemann sum of the speed.
  double sum = 0;
  const int n = 30000;
  for (int k = 0; k < n; ++k) sum += w.Speed(10.0 + 3.0 * (k + 0.5) / n);
  EXPECT_NEAR(w.MeanSpeed(10.0, 13.0), sum / n, 1e-3);
  EXPECT_GT(w.FlutterPhase(10.0), w.FlutterPhase(5.0));
}

// Each of these used to be taken: a huge rate or image tried to allocate it, and a start
// before the epoch or after 2106 failed later inside rosbag ("Time is out of dual 32-bit range").
TEST(SyntheticSessionTest, RefusesRatesSizesAndStartTimesOutOfRange) {
  auto refused = [](auto change, const std::string& names) {
    SyntheticSessionOptions o;
    o.duration = 3.0;
    change(o);
    try {
      SyntheticSession session(o);
      return ::testing::AssertionFailure() << "accepted";
    } catch (const std::invalid_argument& e) {
      if (std::string(e.what()).find(names) == std::string::npos)
        return ::testing::AssertionFailure() << "message '" << e.what() << "' lacks '" << names << "'";
      return ::testing::AssertionSuccess();
    }
  };
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.fps = 1e12; }, "fps"));
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.fps = std::nan(""); }, "fps"));
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.width = 100000; }, "100000x"));
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.start_time = -5; }, "start time"));
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.start_time = 0; }, "start time"));
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.start_time = 0.001; }, "start time"));  // jitter < 0
  EXPECT_TRUE(refused([](SyntheticSessionOptions& o) { o.start_time = 4294967290.0; }, "start time"));
  SyntheticSessionOptions fine;
  fine.duration = 3.0;
  fine.fps = 1000.0;
  fine.frame_jitter = 0.0002;
  fine.width = fine.height = 16;
  EXPECT_NO_THROW(SyntheticSession{fine});
}

}  // namespace
}  // namespace clothwind::sensors
