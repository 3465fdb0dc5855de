// Table 1's metrics and their split by true wind speed and by simulation, checked against figures
// worked out by hand and against the whole-split metrics they must recombine into; Evaluate end
// to end with an untrained network (windows, unlabelled clips, device).
#include "learn/evaluate.h"

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "learn/dataset.h"
#include "learn/networks.h"
#include "learn/predictor.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

// A gnuplot on PATH that ends as `ending` says (a shell line), for RunGnuplot's tests.
std::filesystem::path FakeGnuplotFolder(const std::string& name, const std::string& ending) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("clothwind_fake_gnuplot_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "gnuplot") << "#!/bin/sh\n" << ending << "\n";
  std::filesystem::permissions(dir / "gnuplot", std::filesystem::perms::owner_all);
  return dir;
}

// A Ctrl-C while gnuplot draws reaches gnuplot and its caller (the terminal's process group).
// gnuplot catches it and exits 1; std::system, which started it, ignored it in the caller
// meanwhile, so it was lost: train ran on to its last epoch and exited 0. The fake gnuplot here
// does as a Ctrl-C would: SIGINT to its parent and itself, which it catches, exiting 1. The caller
// now ends by the signal. A gnuplot that merely fails only fails the plot, its status said as an
// exit status (a signal's "exit 2" had read as gnuplot's own), and one not found says so.
TEST(GnuplotDeathTest, AnInterruptedPlotInterruptsTheCaller) {
  const std::string old_style = GTEST_FLAG_GET(death_test_style);
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string old_path = std::getenv("PATH") ? std::getenv("PATH") : "/usr/bin:/bin";
  const std::filesystem::path interrupted = FakeGnuplotFolder("int", "trap 'exit 1' INT\nkill -INT $PPID $$\nexit 1");
  EXPECT_EXIT(
      {
        ::setenv("PATH", (interrupted.string() + ":" + old_path).c_str(), 1);
        std::string error;
        RunGnuplot("plot x\n", interrupted / "p.png", &error);
        std::fprintf(stderr, "carried on after the plot: %s\n", error.c_str());
        std::exit(0);
      },
      ::testing::KilledBySignal(SIGINT), "");
  GTEST_FLAG_SET(death_test_style, old_style);
  const std::filesystem::path failing = FakeGnuplotFolder("fail", "exit 3");
  ::setenv("PATH", (failing.string() + ":" + old_path).c_str(), 1);
  std::string error;
  const bool drawn = RunGnuplot("plot x\n", failing / "p.png", &error);
  EXPECT_FALSE(drawn);
  EXPECT_NE(error.find("gnuplot failed (exit 3), see " + (failing / "p.png.gp.err").string()), std::string::npos)
      << error;
  EXPECT_FALSE(std::filesystem::exists(failing / "p.png"));
  ::setenv("PATH", "/nonexistent", 1);
  EXPECT_FALSE(RunGnuplot("plot x\n", failing / "q.png", &error));
  EXPECT_NE(error.find("gnuplot failed (could not be started: No such file or directory"), std::string::npos) << error;
  ::setenv("PATH", old_path.c_str(), 1);
  std::filesystem::remove_all(interrupted);
  std::filesystem::remove_all(failing);
}

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

TEST(EvaluateTest, StdCoverageOfListsOfDifferentLengthsIsNaN) {
  // Sized by truth and std alone, a shorter `predicted` was read past its end (here within its
  // capacity, so the old code counted garbage rather than crash).
  EvalResult r;
  r.truth = {1.0, 5.0, 3.0};
  r.predicted_std = {1.0, 1.0, 2.0};
  r.predicted.reserve(3);
  r.predicted = {1.0};
  EXPECT_TRUE(std::isnan(StdCoverage(r, 1))) << StdCoverage(r, 1);
  r.predicted = {1.0, 5.0, 3.0};
  EXPECT_DOUBLE_EQ(StdCoverage(r, 1), 1.0);
  r.predicted_std.pop_back();  // a result without (all) stds
  EXPECT_TRUE(std::isnan(StdCoverage(r, 1)));
  EXPECT_TRUE(EvalJson(r)["std_within_1"].is_null());
  EXPECT_TRUE(EvalJson(r)["std_scale_fit"].is_null());
}

// eval --json carries the factor export-model --calibrate-std would fit on the same clips (its CLI
// test compares the two), and null where there is nothing to fit.
TEST(EvaluateTest, TheJsonCarriesTheStdScaleCalibrationWouldFit) {
  EvalResult r;
  r.truth = {1.0, 5.0, 3.0};
  r.predicted = {2.0, 5.5, 2.0};
  r.predicted_std = {0.5, 1.0, 2.0};  // errors of 2, 0.5 and 0.5 stds
  const nlohmann::json j = EvalJson(r);
  ASSERT_TRUE(j["std_scale_fit"].is_number()) << j.dump();
  EXPECT_NEAR(j["std_scale_fit"].get<double>(), std::sqrt((4 + 0.25 + 0.25) / 3), 1e-12);
  EXPECT_DOUBLE_EQ(j["std_scale_fit"].get<double>(), CalibrationScale(r));
  r.predicted_std[1] = 0;  // nothing to fit: CalibrationScale refuses it, the JSON says null
  EXPECT_TRUE(EvalJson(r)["std_scale_fit"].is_null());
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

TEST(EvaluateTest, PerSimulationSplitOfAHandWorkedExample) {
  // Simulation 0 (2 m/s): views read 2.5 and 1.5, mean 2.0: no shared error, each view 0.5 off it.
  // Simulation 1 (4 m/s): both views read 5: a shared error of 1, no scatter. The recorded clip
  // (-1) is left out.
  const SimulationMetrics m =
      ComputeSimulationMetrics({2.0, 2.0, 4.0, 4.0, 7.0}, {2.5, 1.5, 5.0, 5.0, 0.0}, {0, 0, 1, 1, -1});
  EXPECT_EQ(m.simulations, 2);
  EXPECT_EQ(m.clips, 4);
  EXPECT_NEAR(m.rmse, std::sqrt((0.0 + 1.0) / 2), 1e-12);
  EXPECT_NEAR(m.scatter, std::sqrt((0.25 + 0.25 + 0 + 0) / 4), 1e-12);
  // No simulation ids: nothing to split.
  const SimulationMetrics none = ComputeSimulationMetrics({1.0, 2.0}, {1.0, 2.0}, {-1, -1});
  EXPECT_EQ(none.simulations, 0);
  EXPECT_TRUE(std::isnan(none.rmse));
  EXPECT_TRUE(std::isnan(none.scatter));
}

TEST(EvaluateTest, PerSimulationAndScatterRecombineIntoTheClipsError) {
  // Four views a simulation: each clip's squared error is its simulation's shared error squared
  // plus its own deviation squared plus a cross term that sums to zero over the views, so
  // rmse^2 + scatter^2 is the clips' mean squared error.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> speed(0.0, 10.0);
  std::normal_distribution<double> shared(0.1, 0.4), view(0.0, 0.2);
  std::vector<double> truth, predicted;
  std::vector<int> simulation;
  for (int s = 0; s < 301; ++s) {
    const double wind = speed(rng), offset = shared(rng);
    for (int v = 0; v < 4; ++v) {
      truth.push_back(wind);
      predicted.push_back(wind + offset + view(rng));
      simulation.push_back(s);
    }
  }
  const SimulationMetrics m = ComputeSimulationMetrics(truth, predicted, simulation);
  EXPECT_EQ(m.simulations, 301);
  EXPECT_EQ(m.clips, 1204);
  const double clip_rmse = ComputeMetrics(truth, predicted).rmse;
  EXPECT_NEAR(m.rmse * m.rmse + m.scatter * m.scatter, clip_rmse * clip_rmse, 1e-9);
  // And each part is the one drawn: the shared error's rms sqrt(0.1^2 + 0.4^2 + 0.2^2/4) (the
  // views' mean keeps a quarter of their variance), the scatter 0.2 sqrt(3/4).
  EXPECT_NEAR(m.rmse, std::sqrt(0.01 + 0.16 + 0.01), 0.05);
  EXPECT_NEAR(m.scatter, 0.2 * std::sqrt(0.75), 0.012);
}

TEST(EvaluateTest, PerSimulationRefusesBadInput) {
  EXPECT_THROW(ComputeSimulationMetrics({1.0}, {1.0, 2.0}, {0, 0}), std::invalid_argument);
  EXPECT_THROW(ComputeSimulationMetrics({1.0, 2.0}, {1.0, 2.0}, {0}), std::invalid_argument);
  try {
    ComputeSimulationMetrics({3.0, 3.5}, {3.0, 3.0}, {7, 7});
    ADD_FAILURE() << "two winds in one simulation";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("simulation 7 has clips of two winds"), std::string::npos) << e.what();
  }
}

TEST(EvaluateTest, JsonAndTableCarryThePerSimulationSplit) {
  EvalResult r;
  r.split = "test";
  r.truth = {2.0, 2.0, 4.0, 4.0};
  r.predicted = {2.5, 1.5, 5.0, 5.0};
  r.simulations = {0, 0, 1, 1};
  r.metrics = ComputeMetrics(r.truth, r.predicted);
  r.bands = ComputeBandMetrics(r.truth, r.predicted, kEvalBandWidth);
  r.per_simulation = ComputeSimulationMetrics(r.truth, r.predicted, r.simulations);
  const nlohmann::json j = EvalJson(r);
  EXPECT_NEAR(j["per_simulation"]["rmse"].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(j["per_simulation"]["scatter"].get<double>(), std::sqrt(0.125), 1e-12);
  EXPECT_EQ(j["per_simulation"]["simulations"].get<int>(), 2);
  const std::string table = EvalTable(r);
  EXPECT_NE(table.find("per simulation (mean of its clips): RMSE 0.707; views scatter 0.354  (2 simulations, 4 clips)"),
            std::string::npos)
      << table;
  // A recorded dataset has no simulations: null, and no line.
  r.simulations = {-1, -1, -1, -1};
  r.per_simulation = ComputeSimulationMetrics(r.truth, r.predicted, r.simulations);
  EXPECT_TRUE(EvalJson(r)["per_simulation"].is_null());
  EXPECT_EQ(EvalTable(r).find("per simulation"), std::string::npos);
}

// A toy dataset of `clips` clips of `frames` frames (kind "real" when `real`) and an untrained
// TinySdn-like model beside it, in a fresh folder: Evaluate end to end, without training.
class EvaluateRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("clothwind_evaluate_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    ToyDatasetOptions o;
    o.clips = 10;
    o.frames = 32;
    o.size = 16;
    WriteToyDataset(root_ / "data", o);
    ModelConfig c;
    c.frames = 30;
    c.k = 2;
    c.width = 4;
    c.input_size = 16;
    c.label_mean = 5;  // raw speeds well above the clamp at 0, so that averaging them shows
    c.label_std = 3;
    at::manual_seed(3);
    WindNet net(c);
    net->eval();
    SaveWindNet(net, root_ / "model.pt");
  }
  void TearDown() override { fs::remove_all(root_); }

  // Edits `file` (JSON) in place.
  static void EditJson(const fs::path& file, const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
    edit(j);
    std::ofstream(file) << j.dump(2);
  }
  // Sets clip `name`'s label num_frames (its frames beyond stay on disk, unread).
  void SetFrames(const std::string& name, int frames) {
    EditJson(root_ / "data" / name / "label.json", [&](nlohmann::json& j) { j["num_frames"] = frames; });
  }
  fs::path root_;
};

TEST_F(EvaluateRunTest, AClipWithFewerDistinctWindowsThanAskedReadsEachOnce) {
  // 31 frames, 30-frame windows, --windows 3: the starts were {0, 1, 1}, window 1 weighted double
  // while the table said "mean of 3 frame windows".
  const std::vector<ClipInfo> test = SelectSplit(ReadDataset(root_ / "data"), "test");
  ASSERT_GE(test.size(), 2u);
  SetFrames(test[0].name, 31);
  const EvalResult r = Evaluate(root_ / "model.pt", root_ / "data", "test", 1, "cpu", 1, 3);
  ASSERT_EQ(r.names[0], test[0].name);
  Predictor predictor(root_ / "model.pt", 1, "cpu");
  SampleOptions o = predictor.config().Sampling();
  double raw[2], var[2];
  for (int start : {0, 1}) {
    o.first_frame = start;
    const Sample sample = LoadSample(test[0], o, 0);
    const Prediction p = predictor.Predict({&sample})[0];
    raw[start] = p.raw_speed;
    var[start] = p.speed_std * p.speed_std;
  }
  // The two windows differ enough that weighting one double shows.
  ASSERT_GT(std::abs(raw[1] - raw[0]), 1e-4) << raw[0] << " " << raw[1];
  EXPECT_NEAR(r.predicted[0], ClampSpeed((raw[0] + raw[1]) / 2), 1e-6);
  EXPECT_NEAR(r.predicted_std[0], std::sqrt((var[0] + var[1]) / 2), 1e-6);
  // Reported: the other clips (32 frames) hold 3 windows.
  EXPECT_EQ(r.windows, 3);
  EXPECT_EQ(r.windows_min, 2);
  EXPECT_EQ(r.windows_max, 3);
  EXPECT_EQ(r.windows_read, 2 + 3 * static_cast<int>(test.size() - 1));
  const nlohmann::json j = EvalJson(r);
  EXPECT_EQ(j["windows"].get<int>(), 3);
  EXPECT_EQ(j["windows_used"]["min"].get<int>(), 2);
  EXPECT_EQ(j["windows_used"]["max"].get<int>(), 3);
  const std::string table = EvalTable(r);
  EXPECT_NE(table.find("mean of 2 to 3 distinct frame windows per clip, not the 3 asked for: shorter clips hold fewer"),
            std::string::npos) << table;
  // Every clip short: one count, said as such.
  for (const ClipInfo& c : test) SetFrames(c.name, 31);
  const EvalResult all = Evaluate(root_ / "model.pt", root_ / "data", "test", 1, "cpu", 4, 3);
  EXPECT_EQ(all.windows_min, 2);
  EXPECT_EQ(all.windows_max, 2);
  EXPECT_NEAR(all.predicted[0], r.predicted[0], 1e-5);
  EXPECT_NE(EvalTable(all).find("mean of 2 distinct frame windows per clip, not the 3 asked for: the clips hold no more"),
            std::string::npos) << EvalTable(all);
  // Clips with room for them all: as before.
  for (const ClipInfo& c : test) SetFrames(c.name, 32);
  const EvalResult room = Evaluate(root_ / "model.pt", root_ / "data", "test", 1, "cpu", 4, 3);
  EXPECT_EQ(room.windows_min, 3);
  EXPECT_NE(EvalTable(room).find(", mean of 3 frame windows per clip)"), std::string::npos) << EvalTable(room);
}

TEST_F(EvaluateRunTest, UnlabelledClipsAreReportedForTheirOwnSplitOnly) {
  // A recorded dataset with unlabelled clips in the train split only: eval --split test said
  // "2 recorded clips without a wind label left out" of the test split.
  const Dataset before = ReadDataset(root_ / "data");
  const std::vector<ClipInfo> train = SelectSplit(before, "train");
  ASSERT_GE(train.size(), 2u);
  EditJson(root_ / "data" / "index.json", [](nlohmann::json& j) { j["kind"] = "real"; });
  for (size_t i = 0; i < 2; ++i)
    EditJson(root_ / "data" / train[i].name / "label.json", [](nlohmann::json& j) { j["wind_speed"] = nullptr; });
  const EvalResult test = Evaluate(root_ / "model.pt", root_ / "data", "test", 1, "cpu", 4);
  EXPECT_EQ(test.unlabelled, 0u);
  EXPECT_EQ(EvalTable(test).find("without a wind label"), std::string::npos) << EvalTable(test);
  const EvalResult on_train = Evaluate(root_ / "model.pt", root_ / "data", "train", 1, "cpu", 4);
  EXPECT_EQ(on_train.unlabelled, 2u);
  EXPECT_EQ(on_train.metrics.count, static_cast<int>(train.size()) - 2);
  EXPECT_NE(EvalTable(on_train).find("; 2 recorded clips without a wind label left out"), std::string::npos)
      << EvalTable(on_train);
}

TEST_F(EvaluateRunTest, TheDeviceIsRecordedAndTheCpuTableIsAsBefore) {
  const EvalResult r = Evaluate(root_ / "model.pt", root_ / "data", "test", 1, "cpu", 4);
  EXPECT_EQ(r.device, "cpu");
  EXPECT_EQ(EvalJson(r)["device"].get<std::string>(), "cpu");
  // Only a GPU's figures are said to be one's: the CPU's line reads as it did.
  const std::string table = EvalTable(r);
  EXPECT_NE(table.find("(" + std::to_string(r.metrics.count) + " examples, split test)\n"), std::string::npos)
      << table;
  EvalResult gpu = r;
  gpu.device = "cuda";
  EXPECT_NE(EvalTable(gpu).find("examples, split test, on cuda)"), std::string::npos) << EvalTable(gpu);
  EXPECT_TRUE(EvalJson(EvalResult{})["device"].is_null());
}

}  // namespace
}  // namespace clothwind::learn
