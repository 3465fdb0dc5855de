// Table 1's metrics and their split by true wind speed, checked against figures worked out by
// hand and against the whole-split metrics they must recombine into.
#include "learn/evaluate.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::learn {
namespace {

TEST(EvaluateTest, MetricsOfAHandWorkedExample) {
  // Errors +0.2, -0.5, +0.6, -0.9, 0: |e| <= 0.5 for three of five (the bound is inclusive).
  const Metrics m = ComputeMetrics({0.5, 1.5, 3.0, 9.9, 10.0}, {0.7, 1.0, 3.6, 9.0, 10.0});
  EXPECT_EQ(m.count, 5);
  EXPECT_NEAR(m.rmse, std::sqrt((0.04 + 0.25 + 0.36 + 0.81) / 5), 1e-12);
  EXPECT_DOUBLE_EQ(m.acc05, 0.6);
  EXPECT_TRUE(std::isnan(ComputeMetrics({}, {}).rmse));
  EXPECT_THROW(ComputeMetrics({1.0}, {}), std::invalid_argument);
}

TEST(EvaluateTest, CalibrationScaleMakesErrorsUnitInTheirStd) {
  // Errors +1, -2, +2 against stds 1, 1, 2: z = 1, -2, 1, so k = sqrt((1 + 4 + 1) / 3).
  EvalResult r;
  r.truth = {1.0, 5.0, 3.0};
  r.predicted = {2.0, 3.0, 5.0};
  r.predicted_std = {1.0, 1.0, 2.0};
  const double k = CalibrationScale(r);
  EXPECT_NEAR(k, std::sqrt(2.0), 1e-12);
  // Multiplying every std by k calibrates: the factor of the result is 1.
  for (double& s : r.predicted_std) s *= k;
  EXPECT_NEAR(CalibrationScale(r), 1.0, 1e-12);
  // |e| / std = 1, 2, 1 before calibration: two within 1 std (inclusive), all within 2.
  for (double& s : r.predicted_std) s /= k;
  EXPECT_DOUBLE_EQ(StdCoverage(r, 1), 2.0 / 3);
  EXPECT_DOUBLE_EQ(StdCoverage(r, 2), 1.0);
  EXPECT_TRUE(std::isnan(StdCoverage(EvalResult{}, 1)));
  r.predicted_std[1] = 0;
  EXPECT_THROW(CalibrationScale(r), std::invalid_argument);
  EXPECT_THROW(CalibrationScale(EvalResult{}), std::invalid_argument);
}

TEST(EvaluateTest, BandsSplitByTrueSpeedAndKeepEmptyBands) {
  const std::vector<BandMetrics> b =
      ComputeBandMetrics({0.5, 1.5, 3.0, 9.9, 10.0}, {0.7, 1.0, 3.6, 9.0, 10.0}, 2.0);
  ASSERT_EQ(b.size(), 5u);  // 0-2, 2-4, 4-6, 6-8, 8-10 (10.0 itself goes into the last band)
  EXPECT_DOUBLE_EQ(b[0].lo, 0.0);
  EXPECT_DOUBLE_EQ(b[4].hi, 10.0);
  EXPECT_EQ(b[0].metrics.count, 2);
  EXPECT_NEAR(b[0].metrics.rmse, std::sqrt((0.04 + 0.25) / 2), 1e-12);
  EXPECT_DOUBLE_EQ(b[0].metrics.acc05, 1.0);
  EXPECT_NEAR(b[0].metrics.bias, -0.15, 1e-12);
  EXPECT_EQ(b[1].metrics.count, 1);
  EXPECT_NEAR(b[1].metrics.bias, 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(b[1].metrics.acc05, 0.0);
  for (int i : {2, 3}) {
    EXPECT_EQ(b[i].metrics.count, 0);
    EXPECT_TRUE(std::isnan(b[i].metrics.rmse));
    EXPECT_TRUE(std::isnan(b[i].metrics.bias));
  }
  EXPECT_EQ(b[4].metrics.count, 2);
  EXPECT_NEAR(b[4].metrics.rmse, std::sqrt(0.81 / 2), 1e-12);
  EXPECT_NEAR(b[4].metrics.bias, -0.45, 1e-12);
  EXPECT_DOUBLE_EQ(b[4].metrics.acc05, 0.5);
}

TEST(EvaluateTest, BandsRecombineIntoTheWholeSplit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> speed(0.0, 10.0);
  std::normal_distribution<double> error(-0.1, 0.6);
  std::vector<double> truth, predicted;
  for (int i = 0; i < 997; ++i) {
    truth.push_back(speed(rng));
    predicted.push_back(truth.back() + error(rng));
  }
  const Metrics all = ComputeMetrics(truth, predicted);
  int count = 0;
  double se = 0, within = 0, bias = 0;
  for (const BandMetrics& b : ComputeBandMetrics(truth, predicted, 1.5)) {
    if (b.metrics.count == 0) continue;
    EXPECT_LT(b.lo, b.hi);
    count += b.metrics.count;
    se += b.metrics.count * b.metrics.rmse * b.metrics.rmse;
    within += b.metrics.count * b.metrics.acc05;
    bias += b.metrics.count * b.metrics.bias;
  }
  EXPECT_EQ(count, all.count);
  EXPECT_NEAR(std::sqrt(se / count), all.rmse, 1e-9);
  EXPECT_NEAR(within / count, all.acc05, 1e-9);
  double mean_error = 0;
  for (size_t i = 0; i < truth.size(); ++i) mean_error += (predicted[i] - truth[i]) / truth.size();
  EXPECT_NEAR(bias / count, mean_error, 1e-9);
}

TEST(EvaluateTest, BandsRefuseBadInput) {
  EXPECT_THROW(ComputeBandMetrics({1.0}, {1.0, 2.0}, 2.0), std::invalid_argument);
  EXPECT_THROW(ComputeBandMetrics({1.0}, {1.0}, 0.0), std::invalid_argument);
  // A split of calm clips only still gets one band.
  const std::vector<BandMetrics> calm = ComputeBandMetrics({0.0, 0.0}, {0.1, -0.1}, 2.0);
  ASSERT_EQ(calm.size(), 1u);
  EXPECT_EQ(calm[0].metrics.count, 2);
}

TEST(EvaluateTest, JsonAndTableCarryTheBands) {
  EvalResult r;
  r.split = "test";
  r.truth = {0.5, 1.5, 9.0};
  r.predicted = {0.7, 1.0, 8.0};
  r.metrics = ComputeMetrics(r.truth, r.predicted);
  r.bands = ComputeBandMetrics(r.truth, r.predicted, kEvalBandWidth);
  const nlohmann::json j = EvalJson(r);
  ASSERT_EQ(j["bands"].size(), 5u);
  EXPECT_EQ(j["bands"][0]["count"].get<int>(), 2);
  EXPECT_TRUE(j["bands"][1]["rmse"].is_null());  // an empty band's NaN
  EXPECT_NEAR(j["bands"][4]["bias"].get<double>(), -1.0, 1e-12);
  const std::string table = EvalTable(r);
  EXPECT_NE(table.find("true  0-2  m/s: RMSE 0.381"), std::string::npos) << table;
  EXPECT_NE(table.find("bias -1.000  (1)"), std::string::npos) << table;
  EXPECT_EQ(table.find(" 2-4 "), std::string::npos) << table;  // empty bands are not printed
}

}  // namespace
}  // namespace clothwind::learn
