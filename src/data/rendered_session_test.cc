#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "data/anemometer_model.h"
#include "data/rendered_flag_generator.h"
#include "data/session_wind.h"

namespace clothwind::data {
namespace {

sensors::SyntheticSessionOptions SmallSession() {
  sensors::SyntheticSessionOptions o;
  o.duration = 3.0;
  o.width = 96;
  o.height = 72;
  o.seed = 4;
  return o;
}

RenderedSessionOptions Coarse() {
  RenderedSessionOptions r;
  r.max_edge = 1.0;
  r.warmup = 0.5;
  r.samples = 1;
  r.threads = 1;
  return r;
}

// A wind that is `a` m/s until t_step, then `b` m/s, along +x.
class StepWind final : public sim::WindField {
 public:
  StepWind(double a, double b, double t_step) : a_(a), b_(b), t_(t_step) {}
  Eigen::Vector3d Velocity(const Eigen::Vector3d&, double t) const override {
    return Eigen::Vector3d(t < t_ ? a_ : b_, 0, 0);
  }

 private:
  double a_, b_, t_;
};

TEST(AnemometerModelTest, SteadyWindReadsItsSpeedAndDirectionAtOneHertz) {
  const sim::SteadyWind wind(Eigen::Vector3d(5.0, 0, 0));
  AnemometerModelParams p;
  const auto r = SimulateAnemometer(wind, p, 100.0, 30.0);
  ASSERT_EQ(r.size(), 29u);  // the 30th would arrive after the end
  double mean = 0;
  for (size_t k = 0; k < r.size(); ++k) {
    EXPECT_DOUBLE_EQ(r[k].measured_at, 100.0 + (k + 1));
    EXPECT_DOUBLE_EQ(r[k].stamp, 100.0 + (k + 1) + 0.05);
    EXPECT_NEAR(r[k].speed, 5.0, 0.5);
    EXPECT_NEAR(r[k].angle, 270.0, 1e-9);  // +x is the session's mean direction
    EXPECT_EQ(r[k].sentence, sensors::FormatMwvSentence(r[k].angle, r[k].speed));
    mean += r[k].speed / r.size();
  }
  EXPECT_NEAR(mean, 5.0, 0.05);
  // The noise is there (readings differ) and follows the seed.
  EXPECT_NE(r[0].speed, r[1].speed);
  EXPECT_EQ(SimulateAnemometer(wind, p, 100.0, 30.0)[7].sentence, r[7].sentence);
  p.seed = 2;
  EXPECT_NE(SimulateAnemometer(wind, p, 100.0, 30.0)[7].sentence, r[7].sentence);
}

TEST(AnemometerModelTest, CupsFollowAStepWithTheirDistanceConstant) {
  const StepWind wind(2.0, 8.0, 10.01);  // between two 20 Hz samples
  AnemometerModelParams p;
  p.noise_std = 0;
  p.noise_relative = 0;
  p.distance_constant = 8.0;  // tau = 1 s at 8 m/s: visibly slow
  const auto r = SimulateAnemometer(wind, p, 0.0, 20.0);
  EXPECT_NEAR(r[9].speed, 2.0, 0.01);    // interval (9, 10]: before the step
  // Interval (10, 11]: samples s_i = 8 - 6 exp(-0.05 i / tau), i = 1..20, tau = 1 s, averaged
  // (the continuous mean would be 8 - 6 (1 - 1/e) = 4.21).
  double expected = 0;
  for (int i = 1; i <= 20; ++i) expected += (8.0 - 6.0 * std::exp(-0.05 * i)) / 20;
  EXPECT_NEAR(r[10].speed, expected, 0.011);
  EXPECT_GT(r[11].speed, r[10].speed);
  EXPECT_NEAR(r[15].speed, 8.0, 0.05);
  // Below the starting threshold the cups stand still.
  const sim::SteadyWind calm(Eigen::Vector3d(0.2, 0, 0));
  EXPECT_EQ(SimulateAnemometer(calm, p, 0.0, 5.0)[2].speed, 0.0);
}

TEST(AnemometerModelTest, ACalmAfterWindReadsZeroWithTheInstrumentsNoise) {
  // 6 m/s, then air below the starting speed from t = 10 s: the cups run down and stop, and a
  // stopped instrument reads 0 whatever its noise (the decay alone only approached 0, so noise
  // clamped at 0 read calm air ~+0.02 m/s for the rest of the session).
  const StepWind wind(6.0, 0.1, 10.0);
  AnemometerModelParams p;  // the default noise
  const auto r = SimulateAnemometer(wind, p, 0.0, 60.0);
  ASSERT_GE(r.size(), 50u);
  EXPECT_GT(r[5].speed, 5.5);
  for (size_t k = 30; k < r.size(); ++k) EXPECT_EQ(r[k].speed, 0.0) << "interval " << k;
}

TEST(AnemometerModelTest, VaneReportsTheDirectionTheWindComesFrom) {
  AnemometerModelParams p;
  // Blowing towards +y (counter-clockwise 90 deg from the mean direction +x): MWV 270 - 90.
  const sim::SteadyWind wind(Eigen::Vector3d(0, 4.0, 0));
  EXPECT_NEAR(SimulateAnemometer(wind, p, 0.0, 10.0)[5].angle, 180.0, 0.1);
  EXPECT_THROW(SimulateAnemometer(wind, AnemometerModelParams{Eigen::Vector3d::Zero(), 0.0}, 0.0, 10.0),
               std::invalid_argument);
}

TEST(SessionWindFieldTest, FollowsTheSessionsSpeedAndDirection) {
  const sensors::SyntheticSessionOptions o = SmallSession();
  auto wind = std::make_shared<sensors::SyntheticWind>(o);
  const SessionWindField calm_field(wind, o.direction_from, sim::TurbulenceParams{}, o.wind_base);
  for (double t : {0.0, 1.3, 2.9}) {
    const Eigen::Vector3d v = calm_field.Velocity(Eigen::Vector3d(1, 2, 3), t);
    EXPECT_NEAR(v.norm(), wind->Speed(t), 1e-9);
    EXPECT_NEAR(v.z(), 0.0, 1e-12);
    // MWV angle back from the direction.
    const double phi = std::atan2(v.y(), v.x()) * 180 / M_PI;
    EXPECT_NEAR(std::remainder(o.direction_from - phi - wind->FromAngle(t), 360.0), 0.0, 1e-6);
  }
  sim::TurbulenceParams turb;
  turb.intensity = 0.1;
  turb.seed = 3;
  const SessionWindField gusty(wind, o.direction_from, turb, o.wind_base);
  const Eigen::Vector3d a = gusty.Velocity(Eigen::Vector3d(0, 0, 1), 1.0);
  const Eigen::Vector3d b = gusty.Velocity(Eigen::Vector3d(0, 10, 1), 1.0);
  EXPECT_GT((a - b).norm(), 1e-3);  // points in space see their own gusts
  const TimeShiftedWind shifted(std::make_shared<SessionWindField>(wind, o.direction_from, turb, o.wind_base), -0.5);
  EXPECT_EQ(shifted.Velocity(Eigen::Vector3d(0, 0, 1), 1.5), a);
}

// make-session's options, named as the user gave them: the render parameters' own field names
// ("field 'camera_radius' is 0.05") named no option of make-session.
TEST(RenderedFlagGeneratorTest, BadCameraOrSamplesAreRefusedNamingTheOption) {
  RenderedSessionOptions near = Coarse();
  near.camera_radius = 0.05;
  RenderedSessionOptions no_samples = Coarse();
  no_samples.samples = 0;
  for (const auto& [options, option] : {std::pair<RenderedSessionOptions, std::string>{near, "--camera-distance"},
                                        {no_samples, "--render-samples"}}) {
    try {
      RenderedFlagGenerator(SmallSession(), options);
      ADD_FAILURE() << option << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("rendered session: " + option + ": ", 0), 0u) << e.what();
    }
  }
}

TEST(RenderedFlagGeneratorTest, RendersTheSimulatedFlagInTimeOrder) {
  const sensors::SyntheticSessionOptions o = SmallSession();
  const auto gen = std::make_shared<RenderedFlagGenerator>(o, Coarse());
  const sensors::SyntheticSession session(o, gen);
  EXPECT_EQ(gen->zeta().width, 96);
  EXPECT_EQ(gen->zeta().camera_fov_deg, 60.0);
  const cv::Mat f0 = session.RenderFrame(0);
  ASSERT_EQ(f0.type(), CV_8UC3);
  EXPECT_EQ(f0.cols, 96);
  EXPECT_EQ(f0.rows, 72);
  const cv::Mat f30 = session.RenderFrame(30);
  EXPECT_GT(cv::norm(f0, f30, cv::NORM_L1), 0.0);  // the flag moved in one second
  EXPECT_THROW(session.RenderFrame(10), std::logic_error);  // back in time
  // Same options, same frames.
  const auto again = std::make_shared<RenderedFlagGenerator>(o, Coarse());
  const sensors::SyntheticSession session2(o, again);
  session2.RenderFrame(0);
  EXPECT_EQ(cv::norm(session2.RenderFrame(30), f30, cv::NORM_INF), 0.0);
  // Its anemometer samples the session's wind: readings near the session's mean speed.
  const auto readings = gen->AnemometerReadings();
  ASSERT_EQ(readings.size(), 2u);  // 3 s at 1 Hz, the third arrives after the end
  for (const auto& r : readings) {
    EXPECT_NEAR(r.speed, session.wind().MeanSpeed(r.measured_at - o.start_time - 1, r.measured_at - o.start_time),
                1.5);
  }
  // That check alone admits an anemometer reading some other wind (a steady 3 m/s passed it).
  // A session of a steady 9 m/s from MWV 200 deg (no drift, gusts or direction wander; only the
  // spatial turbulence of 10 % and the instrument's noise remain): its anemometer must read
  // ~9 m/s from ~200 deg, and 5 m/s more than the same session at 4 m/s. No frame is rendered
  // (the readings do not need the flag), so this costs two scene builds.
  auto steady = [&](double speed) {
    sensors::SyntheticSessionOptions s = o;
    s.wind_base = speed;
    s.wind_drift_std = 0.0;
    s.turbulence_intensity = 0.0;
    s.direction_from = 200.0;
    s.direction_std = 0.0;
    return RenderedFlagGenerator(s, Coarse()).AnemometerReadings();
  };
  // (Read today: 8.49, 9.17 and 3.67, 3.80 m/s; 186..196 deg. The tolerances leave room for the
  // gusts' and the noise's draws, not for another wind: the default 270 deg is 70 deg off.)
  const auto fast = steady(9.0), slow = steady(4.0);
  ASSERT_EQ(fast.size(), 2u);
  ASSERT_EQ(slow.size(), 2u);
  for (size_t k = 0; k < fast.size(); ++k) {
    EXPECT_NEAR(fast[k].speed, 9.0, 1.2) << k;
    EXPECT_NEAR(slow[k].speed, 4.0, 0.8) << k;
    EXPECT_NEAR(fast[k].speed - slow[k].speed, 5.0, 1.0) << k;
    EXPECT_NEAR(std::remainder(fast[k].angle - 200.0, 360.0), 0.0, 25.0) << k;
    EXPECT_NEAR(std::remainder(slow[k].angle - 200.0, 360.0), 0.0, 25.0) << k;
  }
}

}  // namespace
}  // namespace clothwind::data
