// Learning checks on a tiny generated dataset whose stripes oscillate at a frequency set by the
// wind speed: training must actually learn (validation RMSE far below the label spread), the
// checkpoint must round-trip, resuming must continue the log, and evaluation must agree.
#include "learn/train.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <sstream>
#include <tuple>
#include <unistd.h>

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <torch/types.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/adam.h>
#include <torch/serialize.h>

#include "learn/aux_targets.h"
#include "learn/dataset.h"
#include "learn/evaluate.h"
#include "learn/fly_judge.h"
#include "learn/networks.h"
#include "learn/predictor.h"
#include "learn/track_head_eval.h"
#include "learn/track_targets.h"
#include "learn/view_breakdown.h"
#include "learn/weights_io.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

double LabelStd(const std::vector<ClipInfo>& clips) {
  double m = 0, v = 0;
  for (const auto& c : clips) m += c.wind_speed;
  m /= clips.size();
  for (const auto& c : clips) v += (c.wind_speed - m) * (c.wind_speed - m);
  return std::sqrt(v / clips.size());
}

// The smallest SDN the network tests build: k = 2 peaks, width 4, 16 px, 30 frames.
ModelConfig TinySdn() {
  ModelConfig c;
  c.arch = "sdn";
  c.frames = 30;
  c.k = 2;
  c.width = 4;
  c.input_size = 16;
  return c;
}

// Copies `from`'s parameters into `to`, which has the same parameter names and shapes.
void CopyParameters(torch::nn::Module& from, torch::nn::Module& to) {
  torch::OrderedDict<std::string, at::Tensor> source = from.named_parameters();
  for (auto& p : to.named_parameters()) p.value().copy_(source[p.key()]);
}

// Expects ModelConfigFromJson to refuse `j` read as "run/model.json", naming the file and `field`
// and then saying `saying` (e.g. " must be an integer"; "" for any reason).
void ExpectFieldRefused(const nlohmann::json& j, const std::string& field, const std::string& saying = "") {
  try {
    ModelConfigFromJson(j, "run/model.json");
    ADD_FAILURE() << "field \"" << field << "\" = " << j.at(field).dump() << " accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("run/model.json: field \"" + field + "\"" + saying), std::string::npos)
        << e.what();
  }
}

// Expects c's count field (member, JSON `field`) to survive the JSON round trip, to read as
// `absent` from a file written before the field existed, and to be refused by name when negative.
void ExpectCountFieldRoundTrips(const ModelConfig& c, int ModelConfig::*member, const std::string& field,
                                int absent) {
  EXPECT_EQ(ModelConfigFromJson(ToJson(c), "x.json").*member, c.*member);
  nlohmann::json old = ToJson(c);
  old.erase(field);
  EXPECT_EQ(ModelConfigFromJson(old, "x.json").*member, absent);
  nlohmann::json negative = ToJson(c);
  negative[field] = -1;
  ExpectFieldRefused(negative, field);
}

// Expects Train(o) to refuse, with a message holding every one of `words`; `accepted` says what
// was wrongly accepted.
void ExpectTrainRefused(const TrainOptions& o, const std::string& accepted, const std::vector<std::string>& words) {
  try {
    Train(o);
    ADD_FAILURE() << accepted;
  } catch (const std::exception& e) {  // invalid_argument for options (ValidateTrainOptions), else runtime_error
    const std::string what = e.what();
    for (const std::string& w : words) EXPECT_NE(what.find(w), std::string::npos) << what;
  }
}

// Trains `o` to its o.epochs in two goes into o.out: stopped after `first` epochs, then resumed
// (what a run stopped by a VM restart does).
TrainResult TrainStoppedAndResumed(TrainOptions o, int first) {
  const int epochs = o.epochs;
  o.epochs = first;
  Train(o);
  o.epochs = epochs;
  o.resume = true;
  return Train(o);
}

// A network built from `config` reads `clips` [1, C, N_t, H, W] into one (speed, log variance) pair.
void ExpectOneEstimatePerClip(const ModelConfig& config, const at::Tensor& clips) {
  WindNet net(config);
  net->eval();
  EXPECT_EQ(net->forward(clips).sizes(), (at::IntArrayRef{1, 2})) << config.Name();
}

class TrainTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("clothwind_learn_train_" + std::to_string(::getpid())));
    ToyDatasetOptions o;
    o.clips = 100;  // 60 frames of 32x32: enough examples for ~100 steps in a few seconds
    o.frames = 60;
    o.size = 32;
    WriteToyDataset(*root_ / "data", o);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static TrainOptions Options(const std::string& arch, const std::string& run) {
    TrainOptions t;
    t.model.arch = arch;
    t.model.frames = 30;
    t.model.k = 3;
    t.model.width = 8;
    t.model.input_size = 32;
    t.data = *root_ / "data";
    t.out = *root_ / run;
    t.epochs = 12;
    t.batch = 8;
    t.lr = 1e-2;
    t.threads = 2;
    t.device = "cpu";
    return t;
  }
  static fs::path* root_;
};
fs::path* TrainTest::root_ = nullptr;

TEST_F(TrainTest, SdnLearnsTheWindSpeedFromTheOscillationFrequency) {
  const Dataset dataset = ReadDataset(*root_ / "data");
  const std::vector<ClipInfo> val = SelectSplit(dataset, "val");
  ASSERT_GE(val.size(), 10u);
  const double label_std = LabelStd(dataset.clips);
  const TrainResult r = Train(Options("sdn", "sdn"));
  ASSERT_EQ(r.log.size(), 12u);
  EXPECT_EQ(r.device, "cpu");
  // Learning rate schedule: divided by 10 after half the epochs.
  EXPECT_DOUBLE_EQ(r.log[5].lr, 1e-2);
  EXPECT_DOUBLE_EQ(r.log[6].lr, 1e-3);
  // A real learning check: predicting the mean gives RMSE ≈ label std (≈ 2.9 m/s); after ~100
  // steps the SDN reads the speed off the oscillation frequency (≈ 0.7 m/s seen).
  EXPECT_LT(r.best_val_rmse, 0.4 * label_std) << "label std " << label_std;
  EXPECT_LT(r.best_val_rmse, 0.5 * LabelStd(val)) << "validation label std " << LabelStd(val);
  EXPECT_LT(r.log.back().train_loss, r.log.front().train_loss);
  for (const char* f : {"model.pt", "model.json", "state.json", "log.tsv"}) {
    EXPECT_TRUE(fs::exists(r.model.parent_path() / f)) << f;
  }
  // One checkpoint, the last epoch's, in the folder state.json names.
  const fs::path checkpoint = CheckpointDir(r.model.parent_path());
  EXPECT_EQ(checkpoint.filename(), "checkpoint-e0012");
  for (const char* f : {"last.pt", "last_optim.pt"}) EXPECT_TRUE(fs::exists(checkpoint / f)) << f;
  int checkpoints = 0;
  for (const auto& e : fs::directory_iterator(r.model.parent_path()))
    checkpoints += e.path().filename().string().rfind("checkpoint-e", 0) == 0 ? 1 : 0;
  EXPECT_EQ(checkpoints, 1);
  // The evaluation of the saved model reproduces the best validation RMSE seen in training.
  const EvalResult e = Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4);
  EXPECT_EQ(e.metrics.count, static_cast<int>(val.size()));
  EXPECT_NEAR(e.metrics.rmse, r.best_val_rmse, 1e-4);
  const Metrics again = ComputeMetrics(e.truth, e.predicted);
  const nlohmann::json j = EvalJson(e);
  EXPECT_DOUBLE_EQ(j["rmse"].get<double>(), again.rmse);
  EXPECT_DOUBLE_EQ(j["acc05"].get<double>(), again.acc05);
  EXPECT_EQ(j["count"].get<int>(), static_cast<int>(val.size()));
  for (double s : e.predicted_std) EXPECT_TRUE(std::isfinite(s) && s > 0);
  // Each example's folder comes with it, for the breakdown by view; the toy clips have no
  // rendering parameters, so that breakdown refuses them by their label file.
  ASSERT_EQ(e.dirs.size(), e.truth.size());
  for (const fs::path& d : e.dirs) EXPECT_TRUE(fs::exists(d / "label.json")) << d;
  try {
    BreakDownByView(e);
    ADD_FAILURE() << "toy clips were broken down by view";
  } catch (const std::runtime_error& err) {
    EXPECT_NE(std::string(err.what()).find("label.json: no zeta"), std::string::npos) << err.what();
  }
  // Several windows per clip: the mean of the predictions at the evenly spaced starts, and the
  // root mean of their variances, clip by clip.
  const EvalResult e3 = Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 3);
  ASSERT_EQ(e3.predicted.size(), val.size());
  EXPECT_EQ(EvalJson(e3)["windows"].get<int>(), 3);
  Predictor predictor(r.model, 1, "cpu");
  for (size_t i = 0; i < 3; ++i) {
    const std::vector<int> starts = EvenWindowStarts(val[i].num_frames, predictor.config().frames, 3);
    double sum = 0, sum_var = 0;
    for (int start : starts) {
      SampleOptions o;
      o.frames = predictor.config().frames;
      o.input_size = predictor.config().input_size;
      o.first_frame = start;
      const Sample sample = LoadSample(val[i], o, 0);
      ASSERT_EQ(sample.first_frame, start);
      const Prediction p = predictor.Predict({&sample}).front();
      sum += p.speed;
      sum_var += p.speed_std * p.speed_std;
    }
    EXPECT_EQ(e3.names[i], val[i].name);
    EXPECT_NEAR(e3.predicted[i], sum / 3, 1e-4);
    EXPECT_NEAR(e3.predicted_std[i], std::sqrt(sum_var / 3), 1e-4);
  }
  // Mirror averaging: each clip's prediction is the mean of the centred window's and of its mirror
  // image's; the network is not mirror-symmetric, so the two differ somewhere. (Batches of 4 on 2
  // threads against single clips on 1: float sums in another order, ~1e-4 relative.)
  const EvalResult em = Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, true);
  ASSERT_EQ(em.predicted.size(), val.size());
  EXPECT_TRUE(EvalJson(em)["mirror"].get<bool>());
  EXPECT_NE(EvalTable(em).find("mirror image"), std::string::npos);
  double largest_difference = 0;
  for (size_t i = 0; i < val.size(); ++i) {
    SampleOptions o;
    o.frames = predictor.config().frames;
    o.input_size = predictor.config().input_size;
    const Sample plain = LoadSample(val[i], o, 0);
    o.mirror = true;
    const Sample mirrored = LoadSample(val[i], o, 0);
    ASSERT_TRUE(mirrored.flipped);
    const Prediction a = predictor.Predict({&plain}).front(), b = predictor.Predict({&mirrored}).front();
    EXPECT_NEAR(e.predicted[i], a.speed, 2e-3);
    // The two readings' outputs averaged before the clamp at 0, not the clamped ones.
    EXPECT_NEAR(em.predicted[i], ClampSpeed((a.raw_speed + b.raw_speed) / 2), 2e-3);
    EXPECT_NEAR(em.predicted_std[i], std::sqrt((a.speed_std * a.speed_std + b.speed_std * b.speed_std) / 2), 2e-3);
    largest_difference = std::max(largest_difference, std::abs(a.speed - b.speed));
  }
  EXPECT_GT(largest_difference, 0.1);
  // Clips mirrored first (--mirror-clips: flags flying left) are what mirror averaging's second
  // pass reads; turned round again (--flag-flies left) they are the plain clips.
  const EvalResult left = Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, false, true);
  const EvalResult back = Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, false, true, FlagFlies::kLeft);
  EXPECT_EQ(left.turned, 0);
  EXPECT_EQ(back.turned, static_cast<int>(val.size()));
  for (size_t i = 0; i < val.size(); ++i) {
    EXPECT_NEAR(left.predicted[i], 2 * em.predicted[i] - e.predicted[i], 4e-3);
    EXPECT_NEAR(back.predicted[i], e.predicted[i], 1e-6);
  }
  EXPECT_TRUE(EvalJson(back)["mirror_clips"].get<bool>());
  EXPECT_EQ(EvalJson(back)["flag_flies"].get<std::string>(), "left");
  EXPECT_EQ(EvalJson(back)["turned"].get<int>(), static_cast<int>(val.size()));
  EXPECT_NE(EvalTable(back).find("clips mirrored (flags flying left), every clip turned round"), std::string::npos)
      << EvalTable(back);
  EXPECT_TRUE(EvalJson(back)["fly_judge"].is_null());
  // With auto a judge file decides: each clip is turned exactly when its mirror image is not (the
  // judge's score is antisymmetric and no toy clip is still), and the result names the judge.
  std::mt19937_64 rng(11);
  std::normal_distribution<float> n(0.0f, 0.3f);
  Eigen::MatrixXf w1(8, kMotionMapGrid * kMotionMapGrid);
  Eigen::VectorXf b1(8), w2(8);
  for (int i = 0; i < w1.size(); ++i) w1.data()[i] = n(rng);
  for (int i = 0; i < 8; ++i) b1[i] = n(rng), w2[i] = n(rng);
  const fs::path judge_file = r.model.parent_path() / "judge" / "fly_judge.pt";
  fs::create_directories(judge_file.parent_path());
  FlyJudge(w1, b1, w2, 0.1f).Save(judge_file);
  const EvalResult judged =
      Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, false, false, FlagFlies::kAuto, {}, judge_file);
  const EvalResult judged_left =
      Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, false, true, FlagFlies::kAuto, {}, judge_file);
  EXPECT_EQ(judged.turned + judged_left.turned, static_cast<int>(val.size()));
  EXPECT_EQ(judged.fly_judge, judge_file.string());
  EXPECT_EQ(EvalJson(judged)["fly_judge"].get<std::string>(), judge_file.string());
  EXPECT_NE(EvalTable(judged).find("turned round by the judge"), std::string::npos) << EvalTable(judged);
  for (size_t i = 0; i < val.size(); ++i) {
    // Whichever way each reads a clip, the two read it the same way round.
    EXPECT_NEAR(judged.predicted[i], judged_left.predicted[i], 1e-6);
  }
  EXPECT_EQ(Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4, 1, false, false, FlagFlies::kAuto).fly_judge,
            "motion cues");
  // A judge beside the model that cannot be read is said, not passed over in silence.
  const fs::path judged_copy = *root_ / "sdn_bad_judge";
  fs::create_directories(judged_copy);
  for (const char* f : {"model.pt", "model.json"}) fs::copy_file(r.model.parent_path() / f, judged_copy / f);
  std::ofstream(judged_copy / "fly_judge.pt") << "junk";
  const std::string said =
      Evaluate(judged_copy / "model.pt", *root_ / "data", "val", 2, "cpu", 4, 1, false, false, FlagFlies::kAuto)
          .fly_judge;
  EXPECT_NE(said.find("motion cues (the judge beside the model was not used: "), std::string::npos) << said;
  // The plots are PNGs made by gnuplot (installed with the project's dependencies).
  EXPECT_EQ(r.plot_error, "");
  std::string error;
  const fs::path png = r.model.parent_path() / "eval_val.png";
  ASSERT_TRUE(PlotPredictions(e, png, &error)) << error;
  // The data file says how the clips were read, so a three-window run is not mistaken for (nor
  // paired with) Table 1's one window.
  auto first_line = [](const fs::path& p) {
    std::ifstream in(p);
    std::string line;
    std::getline(in, line);
    return line;
  };
  EXPECT_EQ(first_line(png.string() + ".dat"), "# protocol windows 1 mirror 0 mirror_clips 0 flag_flies right");
  EvalResult three = e;
  three.windows = 3;
  three.flag_flies = FlagFlies::kAuto;
  ASSERT_TRUE(PlotPredictions(three, r.model.parent_path() / "eval_w3.png", &error)) << error;
  EXPECT_EQ(first_line(r.model.parent_path() / "eval_w3.png.dat"),
            "# protocol windows 3 mirror 0 mirror_clips 0 flag_flies auto");
  EXPECT_EQ(EvalProtocolSuffix(1, false, false, "right"), "");
  EXPECT_EQ(EvalProtocolSuffix(3, true, true, "auto"), "_w3_mirror_mirrored_flies-auto");
  // A plot that cannot be written is reported, not thrown (eval keeps its JSON); a path with a
  // quote in it is quoted for the shell and for gnuplot.
  EXPECT_FALSE(PlotPredictions(e, r.model.parent_path() / "missing" / "p.png", &error));
  EXPECT_NE(error.find("missing/p.png"), std::string::npos) << error;
  // A folder where the PNG should go: reported, and gnuplot's finished temporary not left behind.
  const fs::path folder = r.model.parent_path() / "plot_folder.png";
  fs::create_directories(folder);
  EXPECT_FALSE(PlotPredictions(e, folder, &error));
  EXPECT_NE(error.find("plot_folder.png"), std::string::npos) << error;
  for (const auto& entry : fs::directory_iterator(r.model.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("plot_folder.png.tmp"), std::string::npos) << entry.path();
  // A stopped run's temporary (killed while gnuplot drew) goes at the next plot of that name; a
  // live process's stays. It stayed beside every later curve, resumes included.
  const fs::path stale = r.model.parent_path() / "eval_val.png.tmp-999999999-0";
  const fs::path live = r.model.parent_path() / ("eval_val.png.tmp-" + std::to_string(::getpid()) + "-0");
  std::ofstream(stale) << "a half-drawn plot";
  std::ofstream(live) << "being drawn";
  ASSERT_TRUE(PlotPredictions(e, png, &error)) << error;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  fs::remove(live);
  const fs::path quoted = r.model.parent_path() / "it's here.png";
  ASSERT_TRUE(PlotPredictions(e, quoted, &error)) << error;
  EXPECT_GT(fs::file_size(quoted), 1000u);
  for (const fs::path& p : {png, r.model.parent_path() / "learning_curve.png"}) {
    std::ifstream in(p, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG") << p;
  }
  // log.tsv: a header and one line per epoch.
  std::ifstream log(r.model.parent_path() / "log.tsv");
  int lines = 0;
  for (std::string line; std::getline(log, line);) ++lines;
  EXPECT_EQ(lines, 13);
}

TEST_F(TrainTest, CheckpointRoundTripGivesIdenticalPredictions) {
  TrainOptions t = Options("resnet18", "roundtrip");
  t.epochs = 1;
  const TrainResult r = Train(t);
  WindNet loaded = LoadWindNet(r.model);
  WindNet again = LoadWindNet(r.model);
  EXPECT_EQ(loaded->config().arch, "resnet18");
  EXPECT_EQ(loaded->config().TrunkInputChannels(), 30);
  at::manual_seed(3);
  const at::Tensor x = at::randn({3, 1, 30, 32, 32});
  at::NoGradGuard no_grad;
  const at::Tensor a = loaded->forward(x), b = again->forward(x);
  EXPECT_TRUE(at::equal(a, b));
  // Saving the loaded network again and reloading changes nothing either.
  SaveWindNet(loaded, *root_ / "roundtrip" / "copy.pt");
  WindNet copy = LoadWindNet(*root_ / "roundtrip" / "copy.pt");
  EXPECT_TRUE(at::equal(copy->forward(x), a));
  // The Predictor (node, eval) gives the same numbers as the network.
  Predictor predictor(r.model, 2, "cpu");
  Sample s;
  s.pixels.assign(x[1].data_ptr<float>(), x[1].data_ptr<float>() + x[1].numel());
  const Prediction p = predictor.Predict({&s})[0];
  const ModelConfig& c = loaded->config();
  EXPECT_NEAR(p.raw_speed, c.label_mean + c.label_std * a[1][0].item<double>(), 1e-5);
  EXPECT_NEAR(p.speed_std, c.label_std * std::exp(0.5 * a[1][1].item<double>()), 1e-5);
  // A calibrated copy scales the std and nothing else.
  loaded->set_std_scale(1.5);
  SaveWindNet(loaded, *root_ / "roundtrip" / "calibrated.pt");
  const Prediction q = Predictor(*root_ / "roundtrip" / "calibrated.pt", 2, "cpu").Predict({&s})[0];
  EXPECT_NEAR(q.speed, p.speed, 1e-9);
  EXPECT_NEAR(q.speed_std, 1.5 * p.speed_std, 1e-9);
  // A model.json that does not match the weights is refused, naming the file.
  nlohmann::json j = nlohmann::json::parse(std::ifstream(*root_ / "roundtrip" / "copy.json"));
  j["width"] = 16;
  std::ofstream(*root_ / "roundtrip" / "copy.json") << j.dump();
  try {
    LoadWindNet(*root_ / "roundtrip" / "copy.pt");
    ADD_FAILURE() << "mismatching config accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("copy.pt"), std::string::npos) << e.what();
  }
  // Nor one that changes no tensor's shape but what the weights read: another input size and
  // frame rate load the same tensors and answer wrongly, so the configuration saved inside the
  // weights refuses them, naming both fields.
  j["width"] = c.width;
  j["input_size"] = c.input_size * 2;
  j["frame_rate"] = 30.0;
  std::ofstream(*root_ / "roundtrip" / "copy.json") << j.dump();
  try {
    LoadWindNet(*root_ / "roundtrip" / "copy.pt");
    ADD_FAILURE() << "a model.json with another input size accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("copy.json"), std::string::npos) << what;
    EXPECT_NE(what.find("\"input_size\" is " + std::to_string(c.input_size * 2)), std::string::npos) << what;
    EXPECT_NE(what.find("\"frame_rate\""), std::string::npos) << what;
  }
  // Weights saved before they held their configuration still load under their JSON.
  SaveModuleWeights(*loaded, *root_ / "roundtrip" / "old.pt", WeightPrecision::kFloat32);
  nlohmann::json old = ToJson(loaded->config());
  old["input_size"] = c.input_size * 2;
  std::ofstream(*root_ / "roundtrip" / "old.json") << old.dump();
  EXPECT_EQ(LoadWindNet(*root_ / "roundtrip" / "old.pt")->config().input_size, c.input_size * 2);
}

TEST(WindNet, OnlyTheMeanMapSeesAStillPose) {
  // Two clips with the same motion on different still images: the detrended spectral maps are
  // identical, so a plain SDN cannot tell them apart; with the mean map it can. The option
  // survives the model.json round trip, and a model.json written before it existed loads
  // without it.
  ModelConfig c = TinySdn();
  at::manual_seed(5);
  const at::Tensor motion = 0.1 * at::randn({1, 1, 30, 16, 16});
  const at::Tensor still = at::randn({2, 1, 1, 16, 16});
  const at::Tensor clips = motion + still;  // [2, 1, 30, 16, 16]
  at::NoGradGuard no_grad;
  WindNet plain(c);
  plain->eval();
  EXPECT_EQ(c.TrunkInputChannels(), 4);
  const at::Tensor p = plain->forward(clips);
  EXPECT_TRUE(at::allclose(p[0], p[1], 1e-4, 1e-5)) << p;
  c.mean_map = true;
  EXPECT_EQ(c.TrunkInputChannels(), 5);
  EXPECT_EQ(c.Name(), "sdn-k2m-w4-16-30f");
  WindNet posed(c);
  posed->eval();
  const at::Tensor q = posed->forward(clips);
  EXPECT_FALSE(at::allclose(q[0], q[1], 1e-3, 1e-4)) << q;
  EXPECT_TRUE(ModelConfigFromJson(ToJson(c), "x.json").mean_map);
  nlohmann::json old = ToJson(c);
  old.erase("mean_map");
  EXPECT_FALSE(ModelConfigFromJson(old, "x.json").mean_map);
  // The std calibration round-trips, is 1 for models from before it, and must be positive.
  c.std_scale = 1.25;
  EXPECT_DOUBLE_EQ(ModelConfigFromJson(ToJson(c), "x.json").std_scale, 1.25);
  old.erase("std_scale");
  EXPECT_DOUBLE_EQ(ModelConfigFromJson(old, "x.json").std_scale, 1.0);
  nlohmann::json bad = ToJson(c);
  bad["std_scale"] = 0.0;
  ExpectFieldRefused(bad, "std_scale", " must be finite and > 0, got 0");
  // Each field out of range is named with its value (one message listed them all, naming none).
  for (const auto& [field, value, saying] : std::vector<std::tuple<std::string, double, std::string>>{
           {"label_std", 0.0, " must be finite and > 0 [m/s], got 0"},
           {"frame_rate", 0.0, " must be in (0, 1000] Hz, got 0"},
           {"frames", 0, " must be in 1..1000, got 0"},
           {"width", 100000, " must be in 1..512, got 100000"},
           {"input_size", 8, " must be in 16..1024, got 8"},
           {"k", 65, " must be in 1..64, got 65"}}) {
    nlohmann::json j = ToJson(c);
    j[field] = value;
    if (field != "label_std" && field != "frame_rate") j[field] = static_cast<int>(value);
    ExpectFieldRefused(j, field, saying);
  }
}

TEST(WindNet, FrameChannelsAreTheWindowsOwnFramesAfterTheSpectra) {
  ModelConfig c = TinySdn();
  const ModelConfig plain_config = c;
  // Evenly spaced, rounded, first and last included; one frame is the middle one.
  c.frame_channels = 4;
  EXPECT_EQ(c.FrameChannelIndices(), (std::vector<int64_t>{0, 10, 19, 29}));
  ModelConfig one = c, two = c, all = c;
  one.frame_channels = 1;
  two.frame_channels = 2;
  all.frame_channels = 30;
  EXPECT_EQ(one.FrameChannelIndices(), (std::vector<int64_t>{14}));
  EXPECT_EQ(two.FrameChannelIndices(), (std::vector<int64_t>{0, 29}));
  ASSERT_EQ(all.FrameChannelIndices().size(), 30u);
  for (int64_t t = 0; t < 30; ++t) EXPECT_EQ(all.FrameChannelIndices()[t], t);
  EXPECT_EQ(c.Name(), "sdn-k2+f4-w4-16-30f");
  EXPECT_EQ(c.TrunkInputChannels(), plain_config.TrunkInputChannels() + 4);
  ExpectCountFieldRoundTrips(c, &ModelConfig::frame_channels, "frame_channels", 0);

  // The trunk reads the plain SDN's maps, then exactly the chosen frames.
  at::manual_seed(7);
  const at::Tensor clips = at::randn({2, 1, 30, 16, 16});
  at::NoGradGuard no_grad;
  WindNet framed(c), plain(plain_config);
  const at::Tensor in = framed->TrunkInput(clips), plain_in = plain->TrunkInput(clips);
  ASSERT_EQ(in.sizes(), (at::IntArrayRef{2, 8, 16, 16}));
  EXPECT_TRUE(at::equal(in.slice(1, 0, 4), plain_in));
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(at::equal(in.select(1, 4 + i), clips.select(1, 0).select(1, c.FrameChannelIndices()[i])));
  }
  // The same motion over two different still images: the detrended spectra are the same, the
  // frames are not.
  const at::Tensor moving = 0.1 * at::randn({1, 1, 30, 16, 16}) + at::randn({2, 1, 1, 16, 16});
  framed->eval();
  plain->eval();
  const at::Tensor p = plain->forward(moving), q = framed->forward(moving);
  EXPECT_TRUE(at::allclose(p[0], p[1], 1e-4, 1e-5)) << p;
  EXPECT_FALSE(at::allclose(q[0], q[1], 1e-3, 1e-4)) << q;

  // More frames than the clip has, or frames on a baseline that already reads them all, are refused.
  ModelConfig too_many = c, baseline = c;
  too_many.frame_channels = 31;
  baseline.arch = "resnet18";
  EXPECT_THROW(WindNet{too_many}, std::invalid_argument);
  EXPECT_THROW(WindNet{baseline}, std::invalid_argument);
}

TEST(ModelConfig, PaddedDftAndLocalPeaksRoundTripAndChangeThePrediction) {
  ModelConfig c = TinySdn();
  c.dft_size = 120;
  c.local_peaks = true;
  EXPECT_EQ(c.Name(), "sdn-k2d120p-w4-16-30f");
  EXPECT_EQ(c.SpectralCandidates(), 60);
  const ModelConfig back = ModelConfigFromJson(ToJson(c), "x.json");
  EXPECT_EQ(back.dft_size, 120);
  EXPECT_TRUE(back.local_peaks);
  // Models from before the options read as Algorithm 1's bins.
  nlohmann::json old = ToJson(c);
  old.erase("dft_size");
  old.erase("local_peaks");
  EXPECT_EQ(ModelConfigFromJson(old, "x.json").dft_size, 0);
  EXPECT_FALSE(ModelConfigFromJson(old, "x.json").local_peaks);
  // A DFT shorter than the clip is refused by field name, by the file and by the network.
  nlohmann::json bad = ToJson(c);
  bad["dft_size"] = 20;
  ExpectFieldRefused(bad, "dft_size");
  ModelConfig short_dft = c;
  short_dft.dft_size = 20;
  EXPECT_THROW(WindNet{short_dft}, std::invalid_argument);
  // The options reach the layer: the same weights read a clip differently with and without them.
  at::manual_seed(3);
  const at::Tensor clips = at::randn({1, 1, 30, 16, 16});
  at::NoGradGuard no_grad;
  WindNet padded(c);
  padded->eval();
  ModelConfig plain_config = c;
  plain_config.dft_size = 0;
  plain_config.local_peaks = false;
  WindNet plain(plain_config);
  plain->eval();
  CopyParameters(*padded, *plain);
  EXPECT_FALSE(at::allclose(padded->forward(clips), plain->forward(clips), 1e-4, 1e-5));
  // Phase steps add 4C trunk channels, round-trip, and default to off in older files.
  c.phase_steps = true;
  EXPECT_EQ(c.TrunkInputChannels(), 8);
  EXPECT_EQ(c.Name(), "sdn-k2d120ps-w4-16-30f");
  EXPECT_TRUE(ModelConfigFromJson(ToJson(c), "x.json").phase_steps);
  EXPECT_FALSE(ModelConfigFromJson(old, "x.json").phase_steps);
  ExpectOneEstimatePerClip(c, clips);
  // Far phase steps add 4C more, round-trip, default to none in older files, and are refused
  // without the near ones, by field name in a file and by the network.
  c.phase_step_far = 4;
  EXPECT_EQ(c.TrunkInputChannels(), 12);
  EXPECT_EQ(c.Name(), "sdn-k2d120ps4-w4-16-30f");
  EXPECT_EQ(ModelConfigFromJson(ToJson(c), "x.json").phase_step_far, 4);
  EXPECT_EQ(ModelConfigFromJson(old, "x.json").phase_step_far, 0);
  ExpectOneEstimatePerClip(c, clips);
  nlohmann::json no_near = ToJson(c);
  no_near["phase_steps"] = false;
  ExpectFieldRefused(no_near, "phase_step_far");
  ModelConfig bad_far = c;
  bad_far.phase_step_far = 1;
  EXPECT_THROW(WindNet{bad_far}, std::invalid_argument);
  // The mode shape adds 2C, round-trips, defaults to off in older files, reaches the trunk's
  // input (its last two channels are the layer's mode map), and is an SDN's option only.
  c.mode_shape = true;
  EXPECT_EQ(c.TrunkInputChannels(), 14);
  EXPECT_EQ(c.Name(), "sdn-k2d120ps4o-w4-16-30f");
  EXPECT_TRUE(ModelConfigFromJson(ToJson(c), "x.json").mode_shape);
  EXPECT_FALSE(ModelConfigFromJson(old, "x.json").mode_shape);
  ExpectOneEstimatePerClip(c, clips);
  EXPECT_TRUE(at::allclose(WindNet(c)->TrunkInput(clips).narrow(1, 12, 2), SpectralDecomposition(clips, c.Spectral()).mode));
  nlohmann::json baseline = ToJson(c);
  baseline["arch"] = "resnet18";
  baseline["phase_step_far"] = 0;
  baseline["phase_steps"] = false;
  baseline["dft_size"] = 0;  // (the spectral layer's other options are refused on a baseline too)
  baseline["local_peaks"] = false;
  ExpectFieldRefused(baseline, "mode_shape");
  nlohmann::json undetrended = ToJson(c);
  undetrended["include_dc"] = true;
  ExpectFieldRefused(undetrended, "mode_shape");
  ModelConfig bad_mode = TinySdn();
  bad_mode.arch = "resnet18";
  bad_mode.mode_shape = true;
  EXPECT_THROW(WindNet{bad_mode}, std::invalid_argument);
  bad_mode.arch = "sdn";
  bad_mode.include_dc = true;
  EXPECT_THROW(WindNet{bad_mode}, std::invalid_argument);
}

TEST(ModelConfig, SpectralPoolKeepsMotionThatDownsamplingTheFramesErases) {
  // A checkerboard flickering at 5 Hz: every 2x2 block sums to zero, so averaging the frames
  // down to half size first leaves no motion at all, while the spectra of the full-size clip,
  // pooled afterwards, keep its power. The pooled trunk input is the average pool of the
  // unpooled one, channel for channel.
  ModelConfig c = TinySdn();
  c.input_size = 32;
  c.spectral_pool = 2;
  EXPECT_EQ(c.Name(), "sdn-k2/2-w4-32-30f");
  const at::Tensor t = at::arange(30, at::kDouble).to(at::kFloat) / 25.0;
  const at::Tensor x = at::arange(32).view({1, 32}), y = at::arange(32).view({32, 1});
  const at::Tensor checker = ((x + y).remainder(2) * 2 - 1).to(at::kFloat);  // [32, 32] of +-1
  const at::Tensor clip =
      (at::sin(2 * M_PI * 5.0 * t).view({30, 1, 1}) * checker).view({1, 1, 30, 32, 32});
  at::NoGradGuard no_grad;
  WindNet pooled(c);
  const at::Tensor pooled_in = pooled->TrunkInput(clip);
  EXPECT_EQ(pooled_in.sizes(), (at::IntArrayRef{1, 4, 16, 16}));
  ModelConfig full = c;
  full.spectral_pool = 1;
  WindNet unpooled(full);
  EXPECT_TRUE(at::allclose(pooled_in, at::avg_pool2d(unpooled->TrunkInput(clip), {2, 2}), 1e-5, 1e-6));
  ModelConfig half = full;
  half.input_size = 16;
  WindNet small(half);
  const at::Tensor small_in = small->TrunkInput(at::avg_pool3d(clip, {1, 2, 2}));
  // Channels 0..k-1 are log1p(power): the strongest peak's power, on average over the image.
  EXPECT_GT(pooled_in.select(1, 0).mean().item<double>(), 1.0);
  EXPECT_LT(small_in.select(1, 0).mean().item<double>(), 1e-6);
  // Round trip, the default for older files, and refusals by field name.
  EXPECT_EQ(ModelConfigFromJson(ToJson(c), "x.json").spectral_pool, 2);
  nlohmann::json old = ToJson(c);
  old.erase("spectral_pool");
  EXPECT_EQ(ModelConfigFromJson(old, "x.json").spectral_pool, 1);
  nlohmann::json bad = ToJson(c);
  bad["spectral_pool"] = 3;  // 32 px do not pool by 3
  ExpectFieldRefused(bad, "spectral_pool");
  ModelConfig odd = c;
  odd.spectral_pool = 3;
  EXPECT_THROW(WindNet{odd}, std::invalid_argument);
  ModelConfig stacked = c;
  stacked.arch = "resnet18";
  stacked.frames = 10;
  EXPECT_THROW(WindNet{stacked}, std::invalid_argument);
}

TEST(ModelConfig, WithoutTheStemPoolTheTrunkKeepsTwiceTheResolution) {
  // At 64 px ResNet-18's stem (stride 2) and max pool leave 16 px for the first stage and 2 px
  // at the last; without the pool the stages run at 32 px and end at 4 px.
  at::NoGradGuard no_grad;
  const at::Tensor x = at::randn({2, 3, 64, 64});
  ResNet18Trunk pooled(3, 4), unpooled(3, 4, /*stem_pool=*/false);
  EXPECT_EQ(pooled->FeatureMap(x).sizes(), (at::IntArrayRef{2, 32, 2, 2}));
  EXPECT_EQ(unpooled->FeatureMap(x).sizes(), (at::IntArrayRef{2, 32, 4, 4}));
  EXPECT_TRUE(at::allclose(unpooled->forward(x), unpooled->FeatureMap(x).mean({2, 3})));
  // The same weights with and without the pool give other features: the option reaches the net.
  // (In training mode batch norm reads the batch's statistics, so the buffers need no copy.)
  CopyParameters(*pooled, *unpooled);
  EXPECT_TRUE(at::equal(unpooled->named_parameters()["stem.weight"], pooled->named_parameters()["stem.weight"]));
  EXPECT_FALSE(at::allclose(unpooled->forward(x), pooled->forward(x)));
  // The whole network: name, round trip, the default for older files, and an estimate.
  ModelConfig c = TinySdn();
  c.stem_pool = false;
  EXPECT_EQ(c.Name(), "sdn-k2-np-w4-16-30f");
  EXPECT_FALSE(ModelConfigFromJson(ToJson(c), "x.json").stem_pool);
  nlohmann::json old = ToJson(c);
  old.erase("stem_pool");
  EXPECT_TRUE(ModelConfigFromJson(old, "x.json").stem_pool);
  WindNet net(c);
  net->eval();
  EXPECT_EQ(net->forward(at::randn({3, 1, 30, 16, 16})).sizes(), (at::IntArrayRef{3, 2}));
}

TEST(ModelConfig, AHiddenHeadLayerIsReluUnitsBeforeTheOutputAndOlderFilesHaveNone) {
  ModelConfig c = TinySdn();
  c.head_hidden = 8;
  EXPECT_EQ(c.Name(), "sdn-k2-h8-w4-16-30f");
  ExpectCountFieldRoundTrips(c, &ModelConfig::head_hidden, "head_hidden", 0);
  ModelConfig bad = c;
  bad.head_hidden = -2;
  EXPECT_THROW(WindNet{bad}, std::invalid_argument);

  // The linear head keeps its one layer, named as in older files; the hidden one adds a layer
  // before it and the output layer reads the hidden units.
  WindNet linear(TinySdn()), hidden(c);
  auto lp = linear->named_parameters(), hp = hidden->named_parameters();
  EXPECT_EQ(lp.find("head_hidden.weight"), nullptr);
  EXPECT_EQ(lp["head.weight"].sizes(), (at::IntArrayRef{2, 32}));
  EXPECT_EQ(hp["head_hidden.weight"].sizes(), (at::IntArrayRef{8, 32}));
  EXPECT_EQ(hp["head.weight"].sizes(), (at::IntArrayRef{2, 8}));

  // The units are rectified: with every unit's bias far below zero none fires, and the estimate
  // is the output layer's bias whatever the clip (a linear hidden layer would follow the clip).
  at::manual_seed(2);
  hidden->eval();
  const at::Tensor clips = at::randn({3, 1, 30, 16, 16});
  at::NoGradGuard no_grad;
  const at::Tensor live = hidden->forward(clips);
  EXPECT_GT((live.select(1, 0) - live.select(1, 0)[0]).abs().max().item<double>(), 1e-6);
  hp["head_hidden.bias"].fill_(-1e6);
  const at::Tensor dead = hidden->forward(clips);
  const at::Tensor bias = hp["head.bias"];
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(dead[i][0].item<float>(), bias[0].item<float>());
    EXPECT_FLOAT_EQ(dead[i][1].item<float>(), bias[1].item<float>());
  }
}

TEST(ModelConfig, AStillFloorRoundTripsReachesTheLayerAndOlderFilesHaveNone) {
  ModelConfig c = TinySdn();
  c.still_floor = 1e-6;
  EXPECT_EQ(ModelConfigFromJson(ToJson(c), "m.json").still_floor, 1e-6);
  nlohmann::json old = ToJson(c);
  old.erase("still_floor");
  EXPECT_EQ(ModelConfigFromJson(old, "m.json").still_floor, 0.0);
  for (const nlohmann::json& bad : {nlohmann::json(-1e-6), nlohmann::json(1.0)}) {
    nlohmann::json j = ToJson(c);
    j["still_floor"] = bad;
    ExpectFieldRefused(j, "still_floor");
  }
  // The trunk sees frequency 0 where the clip is still (the right half) only with the floor.
  at::Tensor clips = at::zeros({1, 1, 30, 16, 16});
  for (int n = 0; n < 30; ++n) clips.index_put_({0, 0, n, at::indexing::Slice(), at::indexing::Slice(0, 8)}, std::sin(n * 1.3));
  at::NoGradGuard no_grad;
  // Channels 2..3 are the two peaks' frequencies (k = 2, C = 1).
  const at::Tensor with = WindNet(c)->TrunkInput(clips).narrow(1, 2, 2).narrow(3, 8, 8);
  c.still_floor = 0;
  const at::Tensor without = WindNet(c)->TrunkInput(clips).narrow(1, 2, 2).narrow(3, 8, 8);
  EXPECT_EQ(with.abs().max().item<double>(), 0.0);
  EXPECT_GT(without.abs().min().item<double>(), 0.0);
}

TEST(ModelConfig, AFieldThisBuildDoesNotKnowOrANewerVersionIsRefused) {
  // A model written by a newer clothwind: an option unknown here was ignored, and the network
  // computed other features from the same weights. The shipped models carry no unknown field.
  nlohmann::json future = ToJson(ModelConfig{});
  future["future_option"] = 1;
  ExpectFieldRefused(future, "future_option", " is not one this clothwind knows");
  nlohmann::json newer = ToJson(ModelConfig{});
  newer["version"] = kModelFormatVersion + 1;
  ExpectFieldRefused(newer, "version", " is 2, this clothwind reads model format version 1");
  EXPECT_NO_THROW(ModelConfigFromJson(ToJson(ModelConfig{}), "run/model.json"));
  nlohmann::json unversioned = ToJson(ModelConfig{});
  unversioned.erase("version");
  EXPECT_NO_THROW(ModelConfigFromJson(unversioned, "run/model.json"));
  const char* source = std::getenv("CLOTHWIND_SOURCE_DIR");
  for (const char* shipped : {"models/sdn.json"}) {
    const fs::path p = fs::path(source ? source : ".") / shipped;
    if (!fs::exists(p)) continue;
    EXPECT_NO_THROW(ModelConfigFromJson(nlohmann::json::parse(std::ifstream(p)), p.string())) << p;
  }
}

TEST(ModelConfig, IntegerFieldsMustBeWholeNumbersWithinRange) {
  // get<int>() read these as 30, 16 and 2, and the copy stored in the weights agreed with them.
  const nlohmann::json good = ToJson(TinySdn());
  EXPECT_NO_THROW(ModelConfigFromJson(good, "m.json"));
  for (const auto& [key, value] : std::vector<std::pair<std::string, nlohmann::json>>{
           {"frames", 4294967326LL}, {"input_size", 16.7}, {"k", 2.9}, {"head_hidden", "8"}}) {
    nlohmann::json j = good;
    j[key] = value;
    ExpectFieldRefused(j, key, " must be an integer");
  }
}

TEST(ModelConfig, FieldsOfAnotherKindAreRefusedNamingTheField) {
  // nlohmann's own "type must be boolean, but is string" named the file, not the field.
  const nlohmann::json good = ToJson(TinySdn());
  for (const auto& [key, value, kind] : std::vector<std::tuple<std::string, nlohmann::json, std::string>>{
           {"format", 7, "a string"}, {"flow", "no", "true or false"}, {"label_std", "1", "a number"},
           {"include_dc", 1, "true or false"}, {"still_floor", "1e-6", "a number"}}) {
    nlohmann::json j = good;
    j[key] = value;
    ExpectFieldRefused(j, key, " must be " + kind);
  }
}

TEST(ModelConfig, CountsThatWouldAllocateTerabytesAreRefusedNamingTheFile) {
  // aux_outputs 2^31 - 1 asked libtorch for 2 TB before the weights' own config was compared.
  for (const auto& [key, value] : std::vector<std::pair<std::string, int64_t>>{
           {"aux_outputs", 2147483647}, {"dft_size", 2000000000}, {"point_maps", 1000000}}) {
    nlohmann::json j = ToJson(TinySdn());
    j[key] = value;
    try {
      ModelConfigFromJson(j, "m.json");
      ADD_FAILURE() << key << " = " << value << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("m.json: field \"" + key + "\" must be <= "), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("got " + std::to_string(value)), std::string::npos) << e.what();
    }
  }
}

TEST(ModelConfig, WhatTheNetworkCannotBeBuiltWithIsRefusedNamingTheField) {
  // Only the WindNet constructor checked these, with a std::invalid_argument naming no file: a
  // 30-frame model.json with "k": 20 failed in eval, export-model and sdn_node that way.
  struct Case {
    std::function<void(ModelConfig&)> edit;
    std::string field, saying;
  };
  const std::vector<Case> cases = {
      {[](ModelConfig& c) { c.k = 20; }, "k", " must be at most the 15 frequency bins a DFT of 30 frames offers"},
      {[](ModelConfig& c) { c.k = 17, c.include_dc = true; }, "k", " must be at most the 16 frequency bins"},
      {[](ModelConfig& c) { c.k = 40, c.dft_size = 64; }, "k", " must be at most the 32 frequency bins a DFT of 64"},
      {[](ModelConfig& c) { c.frames = 1, c.k = 1; }, "frames", " must be at least 2 on an \"sdn\""},
      {[](ModelConfig& c) { c.frame_channels = 40; }, "frame_channels", " must be 0, or 1 to \"frames\" (30)"},
      {[](ModelConfig& c) { c.arch = "resnet18", c.frame_channels = 2; }, "frame_channels", ""}};
  for (const Case& t : cases) {
    ModelConfig c = TinySdn();
    t.edit(c);
    EXPECT_THROW(WindNet{c}, std::invalid_argument) << t.field;  // what the file check stands in for
    ExpectFieldRefused(ToJson(c), t.field, t.saying);
  }
  // The largest k each DFT allows still reads.
  ModelConfig widest = TinySdn();
  widest.k = 15;
  EXPECT_NO_THROW(ModelConfigFromJson(ToJson(widest), "run/model.json"));
  widest.frame_channels = 30;
  EXPECT_NO_THROW(ModelConfigFromJson(ToJson(widest), "run/model.json"));
}

TEST(ModelConfig, TheSpectralLayersOptionsAreRefusedOnABaseline) {
  // A resnet18 given --mean-map was built without it while its model.json said it had one.
  for (const char* field : {"mean_map", "phase_steps", "include_dc", "dft_size", "local_peaks", "still_floor"}) {
    ModelConfig c = TinySdn();
    c.arch = "resnet18";
    c.mean_map = std::string(field) == "mean_map";
    c.phase_steps = std::string(field) == "phase_steps";
    c.include_dc = std::string(field) == "include_dc";
    c.dft_size = std::string(field) == "dft_size" ? 64 : 0;
    c.local_peaks = std::string(field) == "local_peaks";
    c.still_floor = std::string(field) == "still_floor" ? 1e-6 : 0.0;
    EXPECT_EQ(c.SpectralOptionOffSdn(), field);
    EXPECT_THROW(WindNet{c}, std::invalid_argument) << field;
    try {
      ModelConfigFromJson(ToJson(c), "m.json");
      ADD_FAILURE() << field << " was accepted on a resnet18";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("field \"") + field + "\" is an option of the spectral layer"),
                std::string::npos) << e.what();
    }
  }
}

TEST(ModelConfig, CoordMapsAreEachPixelsColumnAndRowAfterEveryArchitecturesImages) {
  at::manual_seed(5);
  const at::Tensor clips = at::randn({2, 1, 30, 16, 16});
  at::NoGradGuard no_grad;
  // The column map at pixel centres, (2j + 1) / 16 - 1: -15/16 ... 15/16, the centre at 0.
  const at::Tensor column = (at::arange(16, at::kFloat) * 2 + 1) / 16.0 - 1;
  for (const std::string arch : {"sdn", "resnet18", "lstm"}) {
    ModelConfig plain = TinySdn();
    plain.arch = arch;
    ModelConfig c = plain;
    c.coord_maps = true;
    EXPECT_EQ(c.TrunkInputChannels(), plain.TrunkInputChannels() + 2) << arch;
    EXPECT_NE(c.Name().find("-xy-"), std::string::npos) << c.Name();
    const at::Tensor with = WindNet(c)->TrunkInput(clips), without = WindNet(plain)->TrunkInput(clips);
    const int64_t ch = without.size(1);
    ASSERT_EQ(with.size(1), ch + 2) << arch;
    // The images themselves are unchanged, and come first (the stem's weights for them keep
    // their place).
    EXPECT_TRUE(at::equal(with.narrow(1, 0, ch), without)) << arch;
    // Every image (the lstm's every frame) gets the same column and row maps.
    const at::Tensor x = with.select(1, ch), y = with.select(1, ch + 1);
    EXPECT_TRUE(at::allclose(x, column.view({1, 1, 16}).expand_as(x))) << arch;
    EXPECT_TRUE(at::allclose(y, column.view({1, 16, 1}).expand_as(y))) << arch;
    ExpectOneEstimatePerClip(c, clips.narrow(0, 0, 1));
  }
  // Pooled spectra get maps at the pooled size, centred as well.
  ModelConfig pooled = TinySdn();
  pooled.input_size = 32;
  pooled.spectral_pool = 2;
  pooled.coord_maps = true;
  const at::Tensor input = WindNet(pooled)->TrunkInput(at::randn({1, 1, 30, 32, 32}));
  EXPECT_EQ(input.sizes(), (at::IntArrayRef{1, pooled.TrunkInputChannels(), 16, 16}));
  EXPECT_TRUE(at::allclose(input.select(1, input.size(1) - 2).select(1, 3), column));
  // The maps reach the estimate: with their stem weights zeroed the same network reads otherwise.
  ModelConfig c = TinySdn();
  c.coord_maps = true;
  WindNet net(c);
  net->eval();
  const at::Tensor before = net->forward(clips);
  net->named_parameters()["trunk.stem.weight"].narrow(1, c.TrunkInputChannels() - 2, 2).zero_();
  EXPECT_FALSE(at::allclose(net->forward(clips), before, 1e-5, 1e-6));
  // Round trip, and off in older files.
  EXPECT_TRUE(ModelConfigFromJson(ToJson(c), "x.json").coord_maps);
  nlohmann::json old = ToJson(c);
  old.erase("coord_maps");
  EXPECT_FALSE(ModelConfigFromJson(old, "x.json").coord_maps);
}

TEST(ModelConfig, DropoutActsInTrainingOnlyAndRoundTrips) {
  ModelConfig c = TinySdn();
  c.dropout = 0.5;
  EXPECT_DOUBLE_EQ(ModelConfigFromJson(ToJson(c), "x.json").dropout, 0.5);
  nlohmann::json old = ToJson(c);
  old.erase("dropout");
  EXPECT_DOUBLE_EQ(ModelConfigFromJson(old, "x.json").dropout, 0.0);
  nlohmann::json bad = ToJson(c);
  bad["dropout"] = 1.0;
  EXPECT_THROW(ModelConfigFromJson(bad, "x.json"), std::runtime_error);
  at::manual_seed(4);
  const at::Tensor clips = at::randn({2, 1, 30, 16, 16});
  at::NoGradGuard no_grad;
  WindNet net(c);
  net->train();
  EXPECT_FALSE(at::allclose(net->forward(clips), net->forward(clips)));  // a new mask each time
  net->eval();
  EXPECT_TRUE(at::equal(net->forward(clips), net->forward(clips)));
}

TEST(ModelConfig, TheAuxiliaryHeadTrainsTheTrunkAndNotTheWindHeadAndRoundTrips) {
  ModelConfig c = TinySdn();
  c.aux_outputs = 5;
  ExpectCountFieldRoundTrips(c, &ModelConfig::aux_outputs, "aux_outputs", 0);

  at::manual_seed(5);
  const at::Tensor clips = at::randn({3, 1, 30, 16, 16});
  WindNet net(c);
  net->eval();  // batch norm's running statistics: the same numbers from both calls
  const WindNetImpl::Outputs out = net->ForwardWithAux(clips);
  ASSERT_EQ(out.aux.sizes(), (at::IntArrayRef{3, 5}));
  EXPECT_TRUE(at::equal(out.wind, net->forward(clips)));
  // The auxiliary loss reaches the trunk, not the wind head.
  AuxLoss(out.aux, at::zeros({3, 5})).backward();
  for (const auto& p : net->named_parameters()) {
    const bool has = p.value().grad().defined() && p.value().grad().abs().sum().item<double>() > 0;
    if (p.key().rfind("head.", 0) == 0) {
      EXPECT_FALSE(has) << p.key();
    } else if (p.key().rfind("trunk.stem.", 0) == 0 || p.key().rfind("aux_head.", 0) == 0) {
      EXPECT_TRUE(has) << p.key();
    }
  }
  // Shipping drops the head: the same wind from the same weights, without the head's.
  WindNet stripped = WithoutAuxHead(net);
  EXPECT_EQ(stripped->config().aux_outputs, 0);
  EXPECT_FALSE(stripped->ForwardWithAux(clips).aux.defined());
  EXPECT_TRUE(at::equal(stripped->forward(clips), net->forward(clips)));
  int64_t before = 0, after = 0;
  for (const auto& p : net->parameters()) before += p.numel();
  for (const auto& p : stripped->parameters()) after += p.numel();
  EXPECT_EQ(before - after, 5 * (8 * c.width + 1));  // the head: 5 x (8w features + bias)
  // Without the option there is no second head.
  WindNet plain(TinySdn());
  EXPECT_FALSE(plain->ForwardWithAux(clips).aux.defined());
  for (const auto& p : plain->named_parameters()) EXPECT_EQ(p.key().rfind("aux_head", 0), std::string::npos);
}

TEST(LearningRate, StepAndCosineSchedules) {
  TrainOptions o;
  o.epochs = 40;
  o.lr = 1e-3;
  // step (the seed's): the initial rate for half the epochs, then a tenth of it.
  EXPECT_DOUBLE_EQ(LearningRateAt(o, 1), 1e-3);
  EXPECT_DOUBLE_EQ(LearningRateAt(o, 20), 1e-3);
  EXPECT_DOUBLE_EQ(LearningRateAt(o, 21), 1e-4);
  o.lr_decay_epoch = 5;
  EXPECT_DOUBLE_EQ(LearningRateAt(o, 6), 1e-4);
  // cosine: the initial rate at epoch 1, half of it half-way, falling every epoch, still
  // positive but under 1 % of the initial rate at the last epoch.
  o.lr_schedule = "cosine";
  EXPECT_DOUBLE_EQ(LearningRateAt(o, 1), 1e-3);
  EXPECT_NEAR(LearningRateAt(o, 21), 0.5e-3, 1e-15);
  for (int e = 2; e <= 40; ++e) EXPECT_LT(LearningRateAt(o, e), LearningRateAt(o, e - 1)) << e;
  EXPECT_GT(LearningRateAt(o, 40), 0.0);
  EXPECT_LT(LearningRateAt(o, 40), 1e-5);
  o.lr_schedule = "linear";
  EXPECT_THROW(LearningRateAt(o, 1), std::invalid_argument);
}

TEST_F(TrainTest, CosineScheduleIsWhatTrainingUses) {
  TrainOptions t = Options("sdn", "cosine");
  t.epochs = 3;
  t.lr_schedule = "cosine";
  // Progress reports, in order: each epoch opens at step 0, before any batch, and counts to its steps.
  // (Validation's reports, after the steps, are left out here: WeightAverageIsWhatModelHoldsAndResumes.)
  std::vector<TrainProgress> reports;
  t.progress = [&](const TrainProgress& p) {
    if (p.val_total == 0) reports.push_back(p);
  };
  const TrainResult r = Train(t);
  ASSERT_EQ(r.log.size(), 3u);
  for (int e = 1; e <= 3; ++e) EXPECT_DOUBLE_EQ(r.log[e - 1].lr, LearningRateAt(t, e)) << e;
  ASSERT_FALSE(reports.empty());
  const int steps = reports.front().steps;
  ASSERT_GT(steps, 0);
  ASSERT_EQ(reports.size(), 3u * (steps + 1));
  for (size_t i = 0; i < reports.size(); ++i) {
    EXPECT_EQ(reports[i].epoch, static_cast<int>(i / (steps + 1)) + 1) << i;
    EXPECT_EQ(reports[i].step, static_cast<int>(i % (steps + 1))) << i;
    EXPECT_EQ(reports[i].steps, steps) << i;
    EXPECT_EQ(reports[i].epochs, 3) << i;
  }
  // The log's rate is computed, not read from Adam: that the optimiser trains at it shows only
  // against a run at a constant rate, equal in epoch 1 (both at --lr) and apart after it.
  TrainOptions flat = Options("sdn", "cosine_flat");
  flat.epochs = 3;
  flat.lr_decay_epoch = 100;
  const TrainResult f = Train(flat);
  EXPECT_EQ(f.log[0].train_loss, r.log[0].train_loss);
  EXPECT_NE(f.log[2].train_loss, r.log[2].train_loss);
  // A cosine run stopped after its first epoch and resumed with other --epochs would run another
  // schedule, though its one logged rate (--lr) fits both: refused, naming them.
  TrainOptions started = t;
  started.out = *root_ / "cosine_one";
  started.epochs = 1;
  Train(started);
  started.epochs = 4;
  started.resume = true;
  ExpectTrainRefused(started, "a cosine run resumed with other --epochs", {"--epochs 1", "--epochs 4 --lr-decay-epoch"});
  // A step run with the default decay (half its epochs) extended: --epochs alone moves the decay
  // and is refused, naming the decay epoch that extends it; given that, it goes on.
  TrainOptions step = Options("sdn", "step_extended");
  step.epochs = 2;
  Train(step);
  step.epochs = 4;
  step.resume = true;
  ExpectTrainRefused(step, "a step run whose decay --epochs moves", {"extend a step run with --lr-decay-epoch 1"});
  step.lr_decay_epoch = 1;
  const TrainResult extended = Train(step);
  ASSERT_EQ(extended.log.size(), 4u);
  EXPECT_DOUBLE_EQ(extended.log[3].lr, step.lr / step.lr_decay_factor);
  t.lr_schedule = "warm";
  t.out = *root_ / "cosine_bad";
  ExpectTrainRefused(t, "unknown schedule accepted", {"warm"});
}

TEST_F(TrainTest, AResumedRunWithDropoutRepeatsTheUninterruptedOne) {
  // Dropout draws from torch's generator, which no checkpoint holds: it is seeded per epoch, so
  // epoch 2 of a run resumed after epoch 1 draws the masks the uninterrupted run drew.
  TrainOptions whole = Options("sdn", "dropout_whole");
  whole.model.dropout = 0.5;
  whole.epochs = 2;
  const TrainResult uninterrupted = Train(whole);
  TrainOptions part = whole;
  part.out = *root_ / "dropout_resumed";
  const TrainResult resumed = TrainStoppedAndResumed(part, 1);
  ASSERT_EQ(resumed.log.size(), 2u);
  EXPECT_NEAR(resumed.log[1].train_loss, uninterrupted.log[1].train_loss, 1e-6);
  EXPECT_NEAR(resumed.log[1].val_rmse, uninterrupted.log[1].val_rmse, 1e-6);
}

// Clips whose whole image flickers at f = 1 + 0.5 v Hz (25 fps) with a random phase, on a random
// still texture: one frame says nothing about v, the order of the frames says everything.
// Returns {clips [n, 1, 30, 16, 16], v [n] in [0, 10] m/s normalised to (v - 5) / 3}.
std::pair<at::Tensor, at::Tensor> FlickerClips(int64_t n) {
  const at::Tensor v = 10 * at::rand({n});
  const at::Tensor t = at::arange(30, at::kFloat) / 25.0f;
  const at::Tensor phase = 2 * M_PI * at::rand({n, 1});
  const at::Tensor flicker = at::sin(2 * M_PI * (1 + 0.5 * v).unsqueeze(1) * t.unsqueeze(0) + phase);
  const at::Tensor clips = 0.5 * at::randn({n, 1, 1, 16, 16}) + flicker.view({n, 1, 30, 1, 1});
  return {clips, (v - 5) / 3};
}

TEST_F(TrainTest, RecurrentBaselineLearnsFromFrameOrderAndRoundTrips) {
  // Yang et al.'s baseline: a ResNet-18 trunk on each frame, an LSTM over the 30 feature vectors.
  ModelConfig c;
  c.arch = "lstm";
  c.frames = 30;
  c.width = 4;
  c.input_size = 16;
  EXPECT_EQ(c.TrunkInputChannels(), 1);
  EXPECT_EQ(c.Name(), "lstm-w4-16-30f");
  at::manual_seed(2);
  WindNet net(c);
  torch::optim::Adam adam(net->parameters(), torch::optim::AdamOptions(3e-3));
  auto [val_x, val_y] = FlickerClips(64);
  auto rmse = [&]() {
    at::NoGradGuard no_grad;
    net->eval();
    const double r = (net->forward(val_x).select(1, 0) - val_y).square().mean().sqrt().item<double>();
    net->train();
    return r;
  };
  const double before = rmse();
  for (int step = 0; step < 150; ++step) {
    auto [x, y] = FlickerClips(16);
    adam.zero_grad();
    WindLoss(net->forward(x), y).backward();
    torch::nn::utils::clip_grad_norm_(net->parameters(), 10.0);
    adam.step();
  }
  // The labels' std is 0.96 (normalised); reading the flicker rate brings it well below.
  const double after = rmse();
  EXPECT_LT(after, 0.5) << "before " << before;
  // The LSTM's weights are part of the checkpoint: a reload predicts the same numbers, and a
  // batch predicts what its examples predict one by one.
  net->eval();
  SaveWindNet(net, *root_ / "lstm.pt");
  WindNet loaded = LoadWindNet(*root_ / "lstm.pt");
  at::NoGradGuard no_grad;
  const at::Tensor out = net->forward(val_x.narrow(0, 0, 3));
  ASSERT_EQ(out.sizes(), (std::vector<int64_t>{3, 2}));
  EXPECT_TRUE(at::allclose(loaded->forward(val_x.narrow(0, 0, 3)), out, 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(net->forward(val_x.narrow(0, 1, 1))[0], out[1], 1e-4, 1e-5));
  // The order of the frames matters to a recurrent model.
  EXPECT_FALSE(at::allclose(net->forward(val_x.narrow(0, 0, 3).flip({2})), out, 1e-3, 1e-4));
}

TEST_F(TrainTest, RecurrentBaselineTrainsEndToEndWithItsTableName) {
  // The CLI path: train (gradients clipped at 10 by default for lstm), evaluate, Table 1's row.
  TrainOptions t = Options("lstm", "lstm");
  t.epochs = 2;
  const TrainResult r = Train(t);
  ASSERT_EQ(r.log.size(), 2u);
  EXPECT_TRUE(std::isfinite(r.best_val_rmse));
  const std::string table = EvalTable(Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 4));
  EXPECT_NE(table.find("Yang et al. (lstm-w8-32-30f)"), std::string::npos) << table;
}

TEST_F(TrainTest, ResumeContinuesTheRun) {
  TrainOptions t = Options("sdn", "resume");
  t.epochs = 2;
  const TrainResult first = Train(t);
  ASSERT_EQ(first.log.size(), 2u);
  t.epochs = 3;
  t.resume = true;
  const TrainResult resumed = Train(t);
  ASSERT_EQ(resumed.log.size(), 3u);
  EXPECT_EQ(resumed.log[2].epoch, 3);
  EXPECT_DOUBLE_EQ(resumed.log[1].val_rmse, first.log[1].val_rmse);
  // A second run stopped after epoch 2 and resumed (another Train call, which keeps nothing of
  // the first in memory: it reads state.json and the checkpoint) reproduces epoch 3 (same data
  // order, same augmentations, same optimiser state).
  TrainOptions u = Options("sdn", "resume2");
  u.epochs = 3;
  u.resume = true;
  TrainOptions v = Options("sdn", "resume2");
  v.epochs = 2;
  Train(v);
  // What a run stopped while saving epoch 3 leaves: that epoch's checkpoint whole or half made.
  // state.json still names epoch 2's, and the resume reads that one.
  for (const char* stray : {"checkpoint-e0003", ".checkpoint-e0003.tmp"}) {
    fs::create_directories(*root_ / "resume2" / stray);
    std::ofstream(*root_ / "resume2" / stray / "last.pt") << "not a checkpoint";
  }
  // The user's own folders that only start like a checkpoint's: a prefix match deleted them when
  // the next epoch ended (a copy of a good checkpoint kept beside the run among them).
  for (const char* own : {"checkpoint-e0002-keep", "checkpoint-eval-notes"})
    fs::copy(*root_ / "resume2" / "checkpoint-e0002", *root_ / "resume2" / own);
  EXPECT_EQ(CheckpointDir(*root_ / "resume2").filename(), "checkpoint-e0002");
  const TrainResult redo = Train(u);
  EXPECT_EQ(CheckpointDir(*root_ / "resume2").filename(), "checkpoint-e0003");
  EXPECT_FALSE(fs::exists(*root_ / "resume2" / "checkpoint-e0002"));
  EXPECT_FALSE(fs::exists(*root_ / "resume2" / ".checkpoint-e0003.tmp"));
  for (const char* own : {"checkpoint-e0002-keep", "checkpoint-eval-notes"})
    EXPECT_TRUE(fs::exists(*root_ / "resume2" / own / "last.pt")) << own;
  EXPECT_NEAR(redo.log[2].train_loss, resumed.log[2].train_loss, 1e-5);
  EXPECT_NEAR(redo.log[2].val_rmse, resumed.log[2].val_rmse, 1e-5);
  // ... and both are the run never stopped: two resumes that each reloaded nothing, or both
  // started the data order or the schedule again, would agree with each other, not with this.
  TrainOptions straight_options = Options("sdn", "straight");
  straight_options.epochs = 3;
  const TrainResult straight = Train(straight_options);
  EXPECT_NEAR(straight.log[2].train_loss, resumed.log[2].train_loss, 1e-5);
  EXPECT_NEAR(straight.log[2].val_rmse, resumed.log[2].val_rmse, 1e-5);

  // Training into the folder again without --resume (a command rerun after a crash) is refused
  // before anything is written; --overwrite starts it again.
  TrainOptions again = Options("sdn", "resume");
  again.epochs = 1;
  const auto state_before = fs::last_write_time(*root_ / "resume" / "state.json");
  ExpectTrainRefused(again, "a run was trained over without --resume or --overwrite",
                     {"a run is already in", "--resume continues it, --overwrite starts it again"});
  EXPECT_EQ(fs::last_write_time(*root_ / "resume" / "state.json"), state_before);
  // A folder with only an initialised model.pt (what --init-only writes) is a run too.
  TrainOptions fresh = Options("sdn", "resume_overwritten");
  fresh.epochs = 1;
  fresh.init_only = true;
  Train(fresh);
  ASSERT_FALSE(fs::exists(*root_ / "resume_overwritten" / "state.json"));
  ExpectTrainRefused(fresh, "an initialised model was written over without --overwrite",
                     {"model.pt: a run is already in"});
  fresh.overwrite = true;
  EXPECT_NO_THROW(Train(fresh));
  // --overwrite clears the old run before training, not when epoch 1 ends: a new run that fails
  // in its first epoch left the old state.json for --resume to continue (log and all), and
  // raw_model.pt, which a run without a weight average does not write, stayed for good.
  {
    TrainOptions old_run = Options("sdn", "overwritten_then_failed");
    old_run.epochs = 1;
    old_run.weight_average = 0.5;
    Train(old_run);
    ASSERT_TRUE(fs::exists(old_run.out / "raw_model.pt"));
    std::ofstream(old_run.out / "notes.txt") << "the user's own file";
    // Names a run's files only start like: a prefix match took them too.
    std::ofstream(old_run.out / "model.onnx") << "the user's export";
    fs::create_directories(old_run.out / "last_eval");
    fs::create_directories(old_run.out / "checkpoint-e0001-keep");
    TrainOptions again_run = old_run;
    again_run.overwrite = true;
    again_run.weight_average = 0;
    again_run.progress = [](const TrainProgress&) { throw std::runtime_error("stopped in epoch 1"); };
    EXPECT_THROW(Train(again_run), std::runtime_error);
    for (const char* gone : {"state.json", "model.pt", "raw_model.pt", "log.tsv"})
      EXPECT_FALSE(fs::exists(old_run.out / gone)) << gone;
    EXPECT_TRUE(fs::exists(old_run.out / "notes.txt"));
    EXPECT_TRUE(fs::exists(old_run.out / "model.onnx"));
    EXPECT_TRUE(fs::exists(old_run.out / "last_eval"));
    EXPECT_TRUE(fs::exists(old_run.out / "checkpoint-e0001-keep"));
    EXPECT_FALSE(fs::exists(old_run.out / "checkpoint-e0001"));
    TrainOptions resume_it = again_run;
    resume_it.overwrite = false;
    resume_it.resume = true;
    resume_it.progress = nullptr;
    ExpectTrainRefused(resume_it, "the failed --overwrite run resumed the old one", {"nothing to resume"});
  }
  // The model options are the network's shape: resuming with others is refused naming the option
  // (they were ignored, the state's used without a word).
  {
    TrainOptions changed = Options("sdn", "resume");
    changed.epochs = 3;
    changed.resume = true;
    changed.model.width = 16;
    ExpectTrainRefused(changed, "--width changed on resume", {"\"width\" is 8", "these options give 16 (--width)"});
    changed.model.width = 8;
    changed.model.arch = "resnet18";
    ExpectTrainRefused(changed, "--model changed on resume", {"\"arch\" is \"sdn\"", "(--model)"});
  }
  // A batch of one clip cannot be batch-normalised: refused naming --batch, and no folder made.
  {
    TrainOptions single = Options("sdn", "batch_of_one");
    single.batch = 1;
    ExpectTrainRefused(single, "a batch of 1 was trained", {"--batch must be at least 2"});
    EXPECT_FALSE(fs::exists(single.out));
  }
  // A run of the layout before checkpoint folders (no "checkpoint" in state.json) resumes from
  // the files beside state.json.
  const fs::path legacy = *root_ / "legacy_layout";
  fs::create_directories(legacy);
  std::ofstream(legacy / "state.json") << R"({"epoch": 2})";
  EXPECT_EQ(CheckpointDir(legacy), legacy);
  std::ofstream(legacy / "state.json") << R"({"epoch": 2, "checkpoint": "checkpoint-e0002"})";
  EXPECT_THROW(CheckpointDir(legacy), std::runtime_error);  // names a folder that is not there

  // Resuming under another schedule is refused before anything is written: epoch 2 ran at lr / 10
  // (step), the cosine schedule over 4 epochs gives 0.85 lr there.
  TrainOptions w = Options("sdn", "resume");
  w.epochs = 4;
  w.resume = true;
  w.lr_schedule = "cosine";
  const auto log_before = fs::last_write_time(*root_ / "resume" / "state.json");
  ExpectTrainRefused(w, "a resume under another schedule was accepted",
                     {"state.json: the run trained with --lr-schedule step, these options give cosine"});
  EXPECT_EQ(fs::last_write_time(*root_ / "resume" / "state.json"), log_before);
  // A run from before the schedule was recorded is checked against its log's rates.
  fs::copy(*root_ / "resume", *root_ / "resume_unrecorded", fs::copy_options::recursive);
  {
    nlohmann::json state = ReadJson(*root_ / "resume_unrecorded" / "state.json");
    for (const char* key : {"epochs", "lr", "lr_schedule", "lr_decay_epoch"}) state.erase(key);
    std::ofstream(*root_ / "resume_unrecorded" / "state.json") << state.dump(2);
  }
  w.out = *root_ / "resume_unrecorded";
  ExpectTrainRefused(w, "an unrecorded run resumed under another schedule",
                     {"state.json: epoch 2 ran at learning rate", "--lr-schedule cosine"});
  w.out = *root_ / "resume";

  // So is a resume with other crop scales: its augmentation would differ from the log's epochs.
  TrainOptions x = Options("sdn", "resume");
  x.epochs = 3;  // the schedule it ran under
  x.resume = true;
  x.crop_scales = {1.0};
  ExpectTrainRefused(x, "a resume with other crop scales was accepted",
                     {"state.json: the run trained with crop scales [1.0,0.875,0.75,0.66]", "--crop-scales"});
  EXPECT_EQ(fs::last_write_time(*root_ / "resume" / "state.json"), log_before);

  // And one with another seed, batch, weight decay or gradient clip: its samples, steps and
  // optimiser would not be the run's.
  const struct {
    const char* what;
    std::function<void(TrainOptions&)> change;
    std::vector<std::string> says;
  } changes[] = {
      {"seed", [](TrainOptions& o) { o.seed = 7; }, {"state.json: the run trained with --seed 1, these options give 7"}},
      {"batch", [](TrainOptions& o) { o.batch = 4; }, {"state.json: the run trained with --batch 8, these options give 4"}},
      {"weight decay", [](TrainOptions& o) { o.weight_decay = 0.0; }, {"--weight-decay"}},
      {"gradient clip", [](TrainOptions& o) { o.grad_clip = 5.0; }, {"--grad-clip"}},
  };
  for (const auto& c : changes) {
    TrainOptions changed = Options("sdn", "resume");
    changed.epochs = 3;
    changed.resume = true;
    c.change(changed);
    ExpectTrainRefused(changed, std::string("a resume with another ") + c.what + " was accepted", c.says);
  }
  EXPECT_EQ(fs::last_write_time(*root_ / "resume" / "state.json"), log_before);

  // And one that turns the flips off: the run trained with them (state.json "flip": true).
  TrainOptions y = Options("sdn", "resume");
  y.epochs = 3;
  y.resume = true;
  y.flip = false;
  ExpectTrainRefused(y, "a resume without the run's flips was accepted",
                     {"state.json: the run trained with --no-flip off, these options give on"});
  EXPECT_EQ(fs::last_write_time(*root_ / "resume" / "state.json"), log_before);
}

// A resume repeats the uninterrupted run exactly only on the same device with as many threads:
// each epoch's record says where it trained, so a run resumed on another machine shows it (state.json
// and log.tsv recorded neither).
TEST_F(TrainTest, EachEpochRecordsTheDeviceAndThreadsItTrainedWith) {
  TrainOptions o = Options("sdn", "where_trained");
  o.epochs = 2;
  o.threads = 2;
  const TrainResult r = TrainStoppedAndResumed(o, 1);  // resumed with the same options: 2 threads
  ASSERT_EQ(r.log.size(), 2u);
  o.epochs = 3;
  o.threads = 1;
  o.resume = true;
  const TrainResult more = Train(o);
  ASSERT_EQ(more.log.size(), 3u);
  std::vector<std::pair<std::string, int>> where;
  for (const EpochRecord& e : more.log) where.emplace_back(e.device, e.threads);
  EXPECT_EQ(where, (std::vector<std::pair<std::string, int>>{{"cpu", 2}, {"cpu", 2}, {"cpu", 1}}));

  std::ifstream state_file(*root_ / "where_trained" / "state.json");
  const nlohmann::json state = nlohmann::json::parse(state_file);
  EXPECT_EQ(state.at("log").at(0).at("threads"), 2);
  EXPECT_EQ(state.at("log").at(2).at("threads"), 1);
  EXPECT_EQ(state.at("log").at(2).at("device"), "cpu");

  std::ifstream tsv(*root_ / "where_trained" / "log.tsv");
  std::string header, line, last;
  std::getline(tsv, header);
  EXPECT_NE(header.find("\traw_val_rmse\tdevice\tthreads"), std::string::npos) << header;
  while (std::getline(tsv, line)) last = line;
  EXPECT_EQ(last.substr(last.size() - 6), "\tcpu\t1") << last;
}

TEST_F(TrainTest, OverwriteKeepsTheOldRunWhenTheNewOneIsRefused) {
  // --cache-frames with crop scales it cannot cache is refused; it used to be refused only after
  // --overwrite had deleted the old run's state, checkpoints and model.
  TrainOptions t = Options("sdn", "overwrite_refused");
  t.epochs = 1;
  Train(t);
  TrainOptions again = t;
  again.overwrite = true;
  again.cache_frames = true;  // the default crop scales are not 1: the cache would change the samples
  ExpectTrainRefused(again, "--cache-frames with crop scales was accepted", {"--cache-frames would change"});
  for (const char* kept : {"state.json", "model.pt", "log.tsv"})
    EXPECT_TRUE(fs::exists(t.out / kept)) << kept << " deleted by a refused --overwrite";
  EXPECT_NO_THROW(CheckpointDir(t.out));
}

// The bytes of a file.
std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST_F(TrainTest, TheModelBesideStateJsonIsTheBestOfTheEpochsItsLogShows) {
  // model.pt was published before state.json: a run stopped between the two kept a model.pt of
  // an epoch its log does not show, and a resume that did not beat it left it there. Now each
  // checkpoint holds the best models so far, published once state.json names it, and a resume
  // publishes them again first.
  TrainOptions t = Options("sdn", "best_in_checkpoint");
  t.epochs = 2;
  t.weight_average = 0.5;
  Train(t);
  const fs::path checkpoint = CheckpointDir(t.out);
  for (const char* name : {"model.pt", "model.json", "raw_model.pt", "raw_model.json"}) {
    ASSERT_TRUE(fs::exists(checkpoint / name)) << name;
    EXPECT_EQ(Bytes(checkpoint / name), Bytes(t.out / name)) << name;
  }
  // What a stop between publishing and state.json left: another epoch's model beside the state.
  TrainOptions other = Options("sdn", "best_in_checkpoint_other");
  other.epochs = 1;
  other.seed = 9;
  other.weight_average = 0.5;
  Train(other);
  fs::copy_file(other.out / "model.pt", t.out / "model.pt", fs::copy_options::overwrite_existing);
  ASSERT_NE(Bytes(t.out / "model.pt"), Bytes(checkpoint / "model.pt"));
  TrainOptions resumed = t;
  resumed.resume = true;  // nothing left to train: the resume only restores
  Train(resumed);
  EXPECT_EQ(Bytes(t.out / "model.pt"), Bytes(checkpoint / "model.pt"));
  // Epoch 3's checkpoint holds the best so far (its own, or carried over when it is no better),
  // and that is the one published.
  resumed.epochs = 3;
  const TrainResult r = Train(resumed);
  const fs::path third = CheckpointDir(t.out);
  EXPECT_EQ(third.filename(), "checkpoint-e0003");
  EXPECT_EQ(Bytes(third / "model.pt"), Bytes(t.out / "model.pt"));
  EXPECT_FALSE(fs::exists(checkpoint)) << "the older checkpoint should be gone";
  EXPECT_EQ(r.log.size(), 3u);
}

TEST_F(TrainTest, AResumeOnOtherClipsIsRefusedAndAMovedDatasetResumes) {
  // The label scaling comes from state.json, the clips from --data: resuming on a regenerated
  // (or another) dataset trained the run on other clips without a word.
  TrainOptions t = Options("sdn", "fingerprint");
  t.epochs = 1;
  Train(t);
  ToyDatasetOptions other;
  other.clips = 100;
  other.frames = 60;
  other.size = 32;
  other.seed = 2;  // the same shape of dataset, other clips
  WriteToyDataset(*root_ / "data_other", other);
  TrainOptions resumed = t;
  resumed.epochs = 2;
  resumed.resume = true;
  resumed.data = *root_ / "data_other";
  ExpectTrainRefused(resumed, "a resume on other clips was accepted",
                     {"state.json: the run trained on other clips than", "data_other"});
  fs::copy(*root_ / "data", *root_ / "data_moved", fs::copy_options::recursive);
  {  // listed in another order, as a recorded dataset's index lists a replaced clip last
    nlohmann::json index = ReadJson(*root_ / "data_moved" / "index.json");
    std::reverse(index["clips"].begin(), index["clips"].end());
    std::ofstream(*root_ / "data_moved" / "index.json") << index.dump(1);
  }
  resumed.data = *root_ / "data_moved";
  const TrainResult r = Train(resumed);
  EXPECT_EQ(r.log.size(), 2u) << "the same clips in another folder and order should resume";
  // And it trains epoch 2 as the uninterrupted run does: the shuffle and augmentation seeds are
  // positions in the split, which used to follow the index's order.
  TrainOptions straight = Options("sdn", "fingerprint_straight");
  straight.epochs = 2;
  const TrainResult s = Train(straight);
  ASSERT_EQ(s.log.size(), 2u);
  EXPECT_NEAR(r.log[1].train_loss, s.log[1].train_loss, 1e-6)
      << "a resume on the same clips listed in another order trained another epoch";
}

TEST_F(TrainTest, ANonFiniteTrainingLossStopsTheRunNamingTheEpochAndStep) {
  // Weights that overflow the network's float activations (a checkpoint scaled by 1e30 stands in
  // for a run that diverged) give an inf or NaN loss, which used to make every weight NaN
  // through Adam while the run went on to its last epoch. Now it stops at the first such step,
  // before the weights change, and the checkpoint of the epoch before stays as it was.
  TrainOptions t = Options("sdn", "diverged");
  t.epochs = 1;
  Train(t);
  const fs::path checkpoint = CheckpointDir(t.out) / "last.pt";
  {
    WindNet net(ModelConfigFromJson(ReadJson(t.out / "state.json")["model"], "state.json"));
    torch::load(net, checkpoint.string());
    torch::NoGradGuard no_grad;
    for (auto& p : net->parameters()) p.mul_(1e30);
    torch::save(net, checkpoint.string());
  }
  const auto saved = fs::last_write_time(t.out / "state.json");
  TrainOptions resumed = t;
  resumed.epochs = 2;
  resumed.resume = true;
  ExpectTrainRefused(resumed, "a run with an infinite loss went on",
                     {"epoch 2, step 1 of ", "the training loss is ", "The checkpoint of epoch 1 is intact",
                      "start a new run with a lower --lr"});
  EXPECT_EQ(fs::last_write_time(t.out / "state.json"), saved);
  EXPECT_EQ(CheckpointDir(t.out).filename(), "checkpoint-e0001");
}

// With a weight average, validation reads the average and model.pt holds its best epoch while
// raw_model.pt holds the trained weights' best: each reproduces its column of the log when
// evaluated. A resumed run restores the average and repeats the uninterrupted run's epoch.
TEST_F(TrainTest, WeightAverageIsWhatModelHoldsAndResumes) {
  TrainOptions t = Options("sdn", "average");
  t.epochs = 3;
  t.weight_average = 0.9;
  // Validation reports its progress after the steps: the split twice (trained weights, average).
  std::vector<TrainProgress> reports;
  t.progress = [&](const TrainProgress& p) { reports.push_back(p); };
  const TrainResult r = Train(t);
  ASSERT_EQ(r.log.size(), 3u);
  ASSERT_FALSE(reports.empty());
  const TrainProgress& last = reports.back();
  EXPECT_EQ(last.epoch, 3);
  EXPECT_EQ(last.step, last.steps);
  EXPECT_GT(last.val_total, 0);
  EXPECT_EQ(last.val_done, last.val_total);
  EXPECT_EQ(last.val_total % 2, 0);
  int increasing = 0;
  for (size_t i = 1; i < reports.size(); ++i)
    increasing += reports[i].epoch == 3 && reports[i].val_done > reports[i - 1].val_done ? 1 : 0;
  EXPECT_GE(increasing, 2);  // more than one report while validating
  double best_raw = 1e9, largest_gap = 0;
  for (const EpochRecord& e : r.log) {
    EXPECT_GT(e.raw_val_rmse, 0.0) << e.epoch;
    best_raw = std::min(best_raw, e.raw_val_rmse);
    largest_gap = std::max(largest_gap, std::abs(e.val_rmse - e.raw_val_rmse));
  }
  EXPECT_GT(largest_gap, 1e-4);  // the average is not the trained weights
  EXPECT_NEAR(Evaluate(r.model, *root_ / "data", "val", 2, "cpu", 8).metrics.rmse, r.best_val_rmse, 1e-4);
  EXPECT_NEAR(Evaluate(t.out / "raw_model.pt", *root_ / "data", "val", 2, "cpu", 8).metrics.rmse, best_raw, 1e-4);
  // The learning curve's data carries both validations (the sixth column is the trained weights').
  std::ifstream curve(t.out / "learning_curve.png.dat");
  std::string header, line;
  std::getline(curve, header);
  EXPECT_NE(header.find("raw_val_rmse"), std::string::npos) << header;
  for (const EpochRecord& e : r.log) {
    ASSERT_TRUE(std::getline(curve, line));
    std::istringstream row(line);
    double c[6];
    for (double& x : c) row >> x;
    EXPECT_NEAR(c[2], e.val_rmse, 1e-4 * e.val_rmse);
    EXPECT_NEAR(c[5], e.raw_val_rmse, 1e-4 * e.raw_val_rmse);
  }
  EXPECT_TRUE(fs::exists(t.out / "learning_curve.png"));

  TrainOptions u = Options("sdn", "average_resumed");
  u.weight_average = 0.9;
  u.epochs = 3;
  const TrainResult resumed = TrainStoppedAndResumed(u, 2);
  u.resume = true;
  ASSERT_EQ(resumed.log.size(), 3u);
  EXPECT_NEAR(resumed.log[2].val_rmse, r.log[2].val_rmse, 1e-5);
  EXPECT_NEAR(resumed.log[2].raw_val_rmse, r.log[2].raw_val_rmse, 1e-5);

  u.weight_average = 0.99;  // another average than the run's
  ExpectTrainRefused(u, "a resume with another weight average was accepted",
                     {"state.json: the run trained with --weight-average", "--weight-average"});
  TrainOptions w = Options("sdn", "average_bad");
  w.weight_average = 1.0;
  ExpectTrainRefused(w, "a weight average that never moves was accepted", {"--weight-average", "[0, 1)"});
}

TEST_F(TrainTest, CropScalesOutsideTheFrameAreRefused) {
  for (const std::vector<double>& scales : {std::vector<double>{}, {1.0, 0.0}, {1.2}}) {
    TrainOptions t = Options("sdn", "bad_scales");
    t.epochs = 1;
    t.crop_scales = scales;
    ExpectTrainRefused(t, "crop scales " + nlohmann::json(scales).dump() + " were accepted", {"crop_scales"});
    EXPECT_FALSE(fs::exists(*root_ / "bad_scales" / "state.json"));
  }
}

// NaN passes CLI11's range checks: a NaN dropout or gradient clip trained to the end and saved a
// run eval and --resume could not read; a NaN lr failed in libtorch naming no option; a huge
// width asked for terabytes. Each is refused before the run folder is made.
TEST_F(TrainTest, NotANumberOrHugeOptionsAreRefusedBeforeTheRunFolder) {
  const double nan = std::nan("");
  const std::vector<std::pair<std::function<void(TrainOptions&)>, std::string>> cases = {
      {[&](TrainOptions& t) { t.model.dropout = nan; }, "--dropout"},
      {[&](TrainOptions& t) { t.grad_clip = nan; }, "--grad-clip"},
      {[&](TrainOptions& t) { t.lr = nan; }, "--lr"},
      {[&](TrainOptions& t) { t.lr = 1e300; }, "--lr"},
      {[&](TrainOptions& t) { t.weight_decay = nan; }, "--weight-decay"},
      {[&](TrainOptions& t) { t.aux_tracks = nan; }, "--aux-tracks"},
      {[&](TrainOptions& t) { t.lr_decay_epoch = -5; }, "--lr-decay-epoch"},
      {[&](TrainOptions& t) { t.model.width = 100000; }, "\"width\" must be in 1..512, got 100000"},
      {[&](TrainOptions& t) { t.model.head_hidden = 2147483647; }, "head_hidden"},
  };
  for (const auto& [change, names] : cases) {
    TrainOptions t = Options("sdn", "bad_numbers");
    t.epochs = 1;
    change(t);
    ExpectTrainRefused(t, names + " was accepted", {names});
    EXPECT_FALSE(fs::exists(*root_ / "bad_numbers")) << names;
  }
}

TEST_F(TrainTest, FlowChannelsTrainRoundTripAndAreRefusedWhenInconsistent) {
  TrainOptions t = Options("sdn", "flow");
  t.model.flow = true;
  t.model.phase_steps = true;
  t.epochs = 1;
  const TrainResult r = Train(t);
  Predictor p(r.model, 1, "cpu");
  EXPECT_TRUE(p.config().flow);
  EXPECT_EQ(p.config().channels, 3);
  EXPECT_NE(p.config().Name().find("-flow"), std::string::npos) << p.config().Name();
  EXPECT_EQ(p.config().Modality(), "30x3x32x32");
  // (2k + 4 phase) channels per input channel reach the trunk.
  EXPECT_EQ(p.config().TrunkInputChannels(), (2 * 3 + 4) * 3);
  const Dataset dataset = ReadDataset(*root_ / "data");
  SampleOptions o;
  o.frames = 30;
  o.input_size = 32;
  o.flow = true;
  const Sample sample = LoadSample(dataset.clips[0], o, 0);
  const Prediction a = p.Predict({&sample}).front();
  EXPECT_TRUE(std::isfinite(a.speed));
  // The node's path (Prepare: the last N_t frames) builds the same three channels.
  const std::vector<cv::Mat> frames = LoadFrames(dataset.clips[0], 15, 30);
  EXPECT_EQ(p.Prepare(frames).pixels.size(), 3u * 30 * 32 * 32);
  // Flow carries what the grey channel does not: zeroing it changes the estimate.
  Sample no_motion = sample;
  std::fill(no_motion.pixels.begin() + 30 * 32 * 32, no_motion.pixels.end(), 0.0f);
  EXPECT_GT(std::abs(p.Predict({&no_motion}).front().speed - a.speed), 1e-4);
  // A grey-only sample is refused by a flow model, and a model file whose channels disagree with
  // its flow field is refused by name.
  o.flow = false;
  const Sample grey = LoadSample(dataset.clips[0], o, 0);
  EXPECT_THROW(p.Predict({&grey}), std::invalid_argument);
  nlohmann::json j = ToJson(p.config());
  j["channels"] = 1;
  ExpectFieldRefused(j, "channels");
  j = ToJson(p.config());
  j["flow_size"] = 8;
  ExpectFieldRefused(j, "flow_size");
  // Older model files have no "flow" field: greyscale.
  ModelConfig old;
  nlohmann::json without = ToJson(old);
  without.erase("flow");
  EXPECT_FALSE(ModelConfigFromJson(without, "old/model.json").flow);
}

TEST_F(TrainTest, ColourChannelsTrainRoundTripAndAreRefusedWhenInconsistent) {
  TrainOptions t = Options("sdn", "colour");
  t.model.colour = true;
  t.model.phase_steps = true;
  // The toy clips are grey, which a colour model refuses by their labels' encoding: a copy whose
  // labels say rgb8 (the grey JPEGs read as three equal channels).
  t.data = *root_ / "data_rgb";
  fs::remove_all(t.data);
  fs::copy(*root_ / "data", t.data, fs::copy_options::recursive);
  for (const ClipInfo& c : ReadDataset(t.data).clips) {
    nlohmann::json label = ReadJson(c.dir / "label.json");
    label["encoding"] = "rgb8";
    std::ofstream(c.dir / "label.json") << label.dump(2);
  }
  t.epochs = 1;
  t.cache_frames = true;
  t.crop_scales = {1.0};
  const TrainResult r = Train(t);
  Predictor p(r.model, 1, "cpu");
  EXPECT_TRUE(p.config().colour);
  EXPECT_EQ(p.config().channels, 3);
  EXPECT_NE(p.config().Name().find("-ycc"), std::string::npos) << p.config().Name();
  EXPECT_EQ(p.config().Modality(), "30x3x32x32");
  EXPECT_EQ(p.config().TrunkInputChannels(), (2 * 3 + 4) * 3);
  // Evaluation's path (the files) and the node's (Prepare: the last N_t frames) agree.
  const Dataset dataset = ReadDataset(*root_ / "data");
  const Sample sample = LoadSample(dataset.clips[0], p.config().Sampling(), 0);
  const std::vector<cv::Mat> frames = LoadFrames(dataset.clips[0], 0, 30, true);
  EXPECT_EQ(p.Prepare(std::vector<cv::Mat>(frames.begin(), frames.end())).pixels,
            LoadSample(dataset.clips[0], [&] { SampleOptions o = p.config().Sampling(); o.first_frame = 0; return o; }(), 0).pixels);
  EXPECT_TRUE(std::isfinite(p.Predict({&sample}).front().speed));
  // Grey frames are refused by a colour model, by name; so is a model file with flow and colour.
  try {
    p.PredictFrames(LoadFrames(dataset.clips[0], 0, 30));
    ADD_FAILURE() << "grey frames accepted by a colour model";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("YCrCb"), std::string::npos) << e.what();
  }
  nlohmann::json j = ToJson(p.config());
  j["flow"] = true;
  ExpectFieldRefused(j, "colour");
  j = ToJson(p.config());
  j["channels"] = 1;
  ExpectFieldRefused(j, "channels");
  // Older model files have no "colour" field: greyscale.
  nlohmann::json without = ToJson(ModelConfig());
  without.erase("colour");
  EXPECT_FALSE(ModelConfigFromJson(without, "old/model.json").colour);
}

// Gives every clip of the dataset in `dir` a tracks.json: a 2x2 grid whose points swing 1.5 px
// across at the clip's stripe frequency (1 + 0.5 v Hz, ToyDatasetOptions' defaults); with
// `world`, also their positions, swinging 0.1 m across the wind at that frequency.
void WriteToyTracks(const fs::path& dir, bool world = false) {
  for (const ClipInfo& c : ReadDataset(dir).clips) {
    const double f = 1.0 + 0.5 * c.wind_speed;
    nlohmann::json xy = nlohmann::json::array(), xyz = nlohmann::json::array();
    for (int k = 0; k < c.num_frames; ++k) {
      nlohmann::json row = nlohmann::json::array(), row3 = nlohmann::json::array();
      for (int p = 0; p < 4; ++p) {
        const double swing = std::sin(2 * M_PI * f * k / c.frame_rate + p);
        row.push_back(8.0 + 16 * (p / 2) + 1.5 * swing);
        row.push_back(8.0 + 16 * (p % 2));
        for (double v : {1.5 * (p / 2), 0.1 * swing, 1.0 * (p % 2)}) row3.push_back(v);
      }
      xy.push_back(row);
      xyz.push_back(row3);
    }
    nlohmann::json j = {{"format", "clothwind-tracks"}, {"version", 1},         {"grid", {2, 2}},
                        {"width", c.width},             {"height", c.height}, {"xy", xy}};
    if (world) j["world"] = xyz;
    std::ofstream(c.dir / "tracks.json") << j.dump();
  }
}

// A copy of the toy dataset at `root`/data in `root`/`name`, its clips given WriteToyTracks' tracks.
fs::path ToyDataWithTracks(const fs::path& root, const std::string& name, bool world = false) {
  const fs::path data = root / name;
  fs::copy(root / "data", data, fs::copy_options::recursive);
  WriteToyTracks(data, world);
  return data;
}

TEST_F(TrainTest, AuxTracksTrainASecondHeadOnTheClipsTracks) {
  // A dataset without tracks is refused, naming the file it lacks.
  TrainOptions t = Options("sdn", "aux");
  t.epochs = 6;
  t.aux_tracks = 1.0;
  ExpectTrainRefused(t, "--aux-tracks trained without tracks", {"tracks.json not found"});
  t.data = ToyDataWithTracks(*root_, "data_tracks");
  const TrainResult r = Train(t);
  ASSERT_EQ(r.log.size(), 6u);
  // The head regresses what the targets hold: its loss (about 1 per standardised target at the
  // start) falls as it learns the swing's frequency, which the spectral maps show (the means of
  // a swing cut at any phase stay partly unpredictable).
  EXPECT_GT(r.log[0].train_aux_loss, 0.0);
  EXPECT_LT(r.log[5].train_aux_loss, 0.6 * r.log[0].train_aux_loss);  // 0.96 -> 0.42 measured
  EXPECT_LT(r.best_val_rmse, LabelStd(SelectSplit(ReadDataset(t.data), "val")));
  const WindNet net = LoadWindNet(r.model);
  EXPECT_EQ(net->config().aux_outputs, 4 * kTargetsPerPoint);
  // Resuming under another weight would make another run than the log's.
  TrainOptions again = t;
  again.epochs = 7;
  again.resume = true;
  again.aux_tracks = 0.5;
  ExpectTrainRefused(again, "a resume with another --aux-tracks was accepted", {"--aux-tracks"});
  // Phase targets widen the head by 4 per point and phase bin; they need the auxiliary loss, and
  // a resume keeps the count the run started with.
  TrainOptions phases = t;
  phases.out = *root_ / "aux_phases";
  phases.epochs = 1;
  phases.aux_phase_bins = 2;
  EXPECT_EQ(LoadWindNet(Train(phases).model)->config().aux_outputs, TrackTargetCount(4, 2));
  TrainOptions other = phases;
  other.epochs = 2;
  other.resume = true;
  other.aux_phase_bins = 3;
  ExpectTrainRefused(other, "a resume with another --aux-phases was accepted", {"--aux-phases 2"});
  TrainOptions without = phases;
  without.out = *root_ / "aux_phases_alone";
  without.aux_tracks = 0;
  ExpectTrainRefused(without, "phase targets without the auxiliary loss were accepted", {"aux_phase_bins"});
  // The points' positions add kWorldTargetsPerPoint a point; tracks without them are refused, naming
  // the file and the field, and so is a resume that changes the flag.
  TrainOptions world = t;
  world.out = *root_ / "aux_world";
  world.epochs = 1;
  world.aux_world = true;
  ExpectTrainRefused(world, "--aux-world on tracks without positions was accepted", {"tracks.json", "'world'"});
  world.data = ToyDataWithTracks(*root_, "data_world", /*world=*/true);
  EXPECT_EQ(LoadWindNet(Train(world).model)->config().aux_outputs, 4 * (kTargetsPerPoint + kWorldTargetsPerPoint));
  TrainOptions changed = world;
  changed.epochs = 2;
  changed.resume = true;
  changed.aux_world = false;
  ExpectTrainRefused(changed, "a resume without the run's --aux-world was accepted", {"--aux-world"});
  TrainOptions alone = world;
  alone.out = *root_ / "aux_world_alone";
  alone.aux_tracks = 0;
  ExpectTrainRefused(alone, "positions without the auxiliary loss were accepted", {"aux_world"});
}

TEST_F(TrainTest, PointMapsFindThePointsWithTheTrainSplitsPositionScale) {
  const fs::path data = ToyDataWithTracks(*root_, "data_point_maps");
  TrainOptions t = Options("sdn", "point_maps");
  t.data = data;
  t.epochs = 4;
  t.point_maps = true;
  ExpectTrainRefused(t, "--point-maps without the auxiliary loss was accepted", {"point_maps", "--aux-tracks"});
  t.aux_tracks = 1.0;
  const TrainResult r = Train(t);
  ASSERT_EQ(r.log.size(), 4u);
  EXPECT_LT(r.log[3].train_aux_loss, r.log[0].train_aux_loss);
  WindNet net = LoadWindNet(r.model);
  EXPECT_EQ(net->config().point_maps, 4);
  // The maps' positions are standardised by the scale the targets are: the train split's.
  const AuxTargets train =
      ReadAuxTargets(SelectSplit(ReadDataset(data), "train"), net->config().Sampling(), 0, false);
  auto buffers = net->named_buffers();
  ASSERT_NE(buffers.find("point_mean"), nullptr);
  for (int p = 0; p < 4; ++p) {
    for (int c = 0; c < 2; ++c) {
      EXPECT_FLOAT_EQ(buffers["point_mean"][p][c].item<float>(), train.scale.mean[p * kTargetsPerPoint + c]);
      EXPECT_FLOAT_EQ(buffers["point_std"][p][c].item<float>(), train.scale.std[p * kTargetsPerPoint + c]);
    }
  }
  TrainOptions again = t;
  again.epochs = 5;
  again.resume = true;
  again.point_maps = false;
  ExpectTrainRefused(again, "a resume without the run's --point-maps was accepted", {"--point-maps"});
}

TEST_F(TrainTest, TrackHeadEvaluationReadsTheHeadBackInTheTargetsUnits) {
  const fs::path data = ToyDataWithTracks(*root_, "data_head");
  TrainOptions t = Options("sdn", "head");
  t.data = data;
  t.epochs = 2;
  t.aux_tracks = 1.0;
  const TrainResult r = Train(t);
  const TrackHeadReport head = EvaluateTrackHead(r.model, data, "val", 1, 3);
  const std::vector<ClipInfo> val = SelectSplit(ReadDataset(data), "val");
  ASSERT_EQ(head.names.size(), val.size());
  ASSERT_EQ(head.points, 4);
  // Each clip's row is the head's output for its evaluation window, unstandardised by the train
  // split's scale (training's), beside that window's own targets.
  WindNet net = LoadWindNet(r.model);
  const SampleOptions options = net->config().Sampling();
  const AuxTargets train = ReadAuxTargets(SelectSplit(ReadDataset(data), "train"), options, 0, false);
  for (size_t i : {size_t{0}, val.size() - 1}) {
    ASSERT_EQ(head.names[i], val[i].name);
    Sample s = LoadSample(val[i], options, 0);
    at::NoGradGuard no_grad;
    const at::Tensor aux =
        net->ForwardWithAux(at::from_blob(s.pixels.data(), {1, 1, options.frames, options.input_size,
                                                            options.input_size}, at::kFloat))
            .aux;
    const std::vector<float> truth = AuxTargetsOf(ReadTracks(val[i].dir / "tracks.json"), s.first_frame,
                                                  options.frames, s.crop, val[i].width, false, 0, false);
    ASSERT_EQ(head.predicted[i].size(), truth.size());
    for (size_t k = 0; k < truth.size(); ++k) {
      EXPECT_NEAR(head.predicted[i][k], aux[0][k].item<float>() * train.scale.std[k] + train.scale.mean[k], 1e-4)
          << i << " " << k;
      EXPECT_FLOAT_EQ(head.truth[i][k], truth[k]) << i << " " << k;
    }
  }
  // On the train split the tracks the scale was read from are the rows' own.
  const TrackHeadReport on_train = EvaluateTrackHead(r.model, data, "train", 1, 8);
  const std::vector<ClipInfo> train_clips = SelectSplit(ReadDataset(data), "train");
  ASSERT_EQ(on_train.names.size(), train_clips.size());
  const ClipInfo& last = train_clips.back();
  EXPECT_EQ(on_train.names.back(), last.name);
  EXPECT_EQ(on_train.truth.back(),
            AuxTargetsOf(ReadTracks(last.dir / "tracks.json"), (last.num_frames - options.frames) / 2, options.frames,
                         CentreSquare(last.width, last.height), last.width, false, 0, false));
  // The figures are the rows': positions in pixels of the 32-px input, where [-1, 1] spans it.
  double se_x = 0, se = 0, n = 0;
  for (size_t i = 0; i < val.size(); ++i)
    for (int p = 0; p < 4; ++p) {
      se_x += std::pow(head.predicted[i][p * kTargetsPerPoint] - head.truth[i][p * kTargetsPerPoint], 2);
      n += 1;
      for (int k = 0; k < kTargetsPerPoint; ++k) {
        const int o = p * kTargetsPerPoint + k;
        se += std::pow((head.predicted[i][o] - head.truth[i][o]) / train.scale.std[o], 2);
      }
    }
  EXPECT_NEAR(head.position_rmse_x, std::sqrt(se_x / n) * 16, 1e-4);
  EXPECT_NEAR(head.standardised_mse, se / (n * kTargetsPerPoint), 1e-5);
  ASSERT_EQ(head.amplitude_rmse.size(), static_cast<size_t>(kTrackBins));
  for (double e : head.amplitude_rmse) EXPECT_TRUE(std::isfinite(e) && e >= 0);
  // The rows file holds both rows per clip after a header.
  const fs::path rows = *root_ / "head_rows.tsv";
  WriteTrackHeadRows(head, rows);
  std::ifstream in(rows);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("# name", 0), 0u);
  std::getline(in, line);
  std::istringstream fields(line);
  std::string name;
  fields >> name;
  EXPECT_EQ(name, val[0].name);
  int values = 0;
  for (double v; fields >> v;) ++values;
  EXPECT_EQ(values, 1 + 2 * 4 * kTargetsPerPoint);
  // An exported model has no head: refused, naming the file.
  const fs::path stripped = *root_ / "head_stripped" / "model.pt";
  fs::create_directories(stripped.parent_path());
  WindNet without = WithoutAuxHead(net);
  SaveWindNet(without, stripped);
  try {
    EvaluateTrackHead(stripped, data, "val", 1, 3);
    ADD_FAILURE() << "a model without a head was evaluated";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(stripped.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no track head"), std::string::npos) << e.what();
  }
  // A per-frame network (one frame a sample) trains the head on where the points are: its
  // targets' motion is zero, not the NaN of a one-frame Hann window.
  TrainOptions frame = Options("resnet18", "head_frame");
  frame.data = data;
  frame.model.frames = 1;
  frame.epochs = 1;
  frame.aux_tracks = 1.0;
  const TrainResult one = Train(frame);
  EXPECT_TRUE(std::isfinite(one.log[0].train_aux_loss) && one.log[0].train_aux_loss > 0) << one.log[0].train_aux_loss;
  EXPECT_TRUE(std::isfinite(EvaluateTrackHead(one.model, data, "val", 1, 3).position_rmse_x));
  // Read over a 30-frame window, the per-frame head's positions are its 30 frames' mean, against
  // the 30-frame window's own targets: what a tracker would give the SDN's window.
  const TrackHeadReport over = EvaluateTrackHead(one.model, data, "val", 1, 2, {}, 30);
  EXPECT_EQ(over.window, 30);
  WindNet per_frame = LoadWindNet(one.model);
  const SampleOptions frame_options = per_frame->config().Sampling();
  const int first = (val[1].num_frames - 30) / 2;
  std::vector<double> mean(2 * 4, 0.0);
  for (int q = 0; q < 30; ++q) {
    SampleOptions o = frame_options;
    o.first_frame = first + q;
    Sample s = LoadSample(val[1], o, 0);
    at::NoGradGuard no_grad;
    const at::Tensor aux =
        per_frame->ForwardWithAux(at::from_blob(s.pixels.data(), {1, 1, 1, o.input_size, o.input_size}, at::kFloat))
            .aux;
    const AuxTargets frame_scale = ReadAuxTargets(SelectSplit(ReadDataset(data), "train"), frame_options, 0, false);
    for (int p = 0; p < 4; ++p)
      for (int c = 0; c < 2; ++c) {
        const int k = p * kTargetsPerPoint + c;
        mean[p * 2 + c] += (aux[0][k].item<float>() * frame_scale.scale.std[k] + frame_scale.scale.mean[k]) / 30;
      }
  }
  const std::vector<float> window_truth = AuxTargetsOf(ReadTracks(val[1].dir / "tracks.json"), first, 30,
                                                       CentreSquare(val[1].width, val[1].height), val[1].width,
                                                       false, 0, false);
  for (int p = 0; p < 4; ++p)
    for (int c = 0; c < 2; ++c) {
      const int k = p * kTargetsPerPoint + c;
      EXPECT_NEAR(over.predicted[1][k], mean[p * 2 + c], 1e-4) << p << " " << c;
      EXPECT_FLOAT_EQ(over.truth[1][k], window_truth[k]) << p << " " << c;
    }
  // A window longer than the clips, or not made of whole model inputs, is refused.
  EXPECT_THROW(EvaluateTrackHead(one.model, data, "val", 1, 2, {}, 61), std::runtime_error);
  EXPECT_THROW(EvaluateTrackHead(r.model, data, "val", 1, 2, {}, 45), std::invalid_argument);
  // Clips at another rate than the model reads are refused naming the clip, as eval and train
  // refuse them (the head's figures were reported for another input without a word).
  {
    const fs::path other_rate = *root_ / "data_head_5hz";
    fs::copy(data, other_rate, fs::copy_options::recursive);
    for (const auto& clip : fs::directory_iterator(other_rate)) {
      if (!fs::exists(clip.path() / "label.json")) continue;
      nlohmann::json label = nlohmann::json::parse(std::ifstream(clip.path() / "label.json"));
      label["frame_rate"] = 5.0;
      std::ofstream(clip.path() / "label.json") << label.dump();
    }
    try {
      EvaluateTrackHead(r.model, other_rate, "val", 1, 2);
      ADD_FAILURE() << "5 Hz clips were read by a 25 Hz model's head";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("the model reads clips at 25"), std::string::npos) << e.what();
    }
  }
  // The same refusals before any data is read (eval checks them before its evaluation, which ran
  // whole and then lost its results to them), and a state.json option of another type named.
  EXPECT_NO_THROW(CheckTrackHead(r.model, 0));
  EXPECT_NO_THROW(CheckTrackHead(one.model, 30));
  EXPECT_THROW(CheckTrackHead(r.model, 45), std::invalid_argument);
  EXPECT_THROW(CheckTrackHead(stripped, 0), std::runtime_error);
  const fs::path state = fs::path(one.model).parent_path() / "state.json";
  nlohmann::json edited = ReadJson(state);
  edited["aux_world"] = "yes";
  std::ofstream(state) << edited.dump();
  try {
    CheckTrackHead(one.model, 30);
    ADD_FAILURE() << "a state.json with aux_world \"yes\" was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(state.string() + ": field \"aux_world\" is \"yes\""), std::string::npos)
        << e.what();
  }
}

// A tiny initialised SDN (width 4, 32 px), written without data into `out`.
TrainOptions InitOnly(const fs::path& out) {
  TrainOptions t;
  t.model.arch = "sdn";
  t.model.width = 4;
  t.model.input_size = 32;
  t.out = out;
  t.init_only = true;
  return t;
}

TEST_F(TrainTest, ADatasetWithoutAValSplitSaysItValidatedOnTrain) {
  // The toy dataset with its val clips moved to train: validation (and the choice of model.pt)
  // falls back to the train split, which the result and state.json now say.
  const fs::path data = *root_ / "no-val";
  fs::copy(*root_ / "data", data, fs::copy_options::recursive);
  nlohmann::json index = ReadJson(data / "index.json");
  int moved = 0;
  for (auto& clip : index["clips"]) {
    if (clip.value("split", "") != "val") continue;
    clip["split"] = "train";
    const fs::path label = data / clip["name"].get<std::string>() / "label.json";
    nlohmann::json j = ReadJson(label);
    j["split"] = "train";
    std::ofstream(label) << j.dump(2);
    ++moved;
  }
  ASSERT_GT(moved, 0);
  std::ofstream(data / "index.json") << index.dump(2);
  TrainOptions o = Options("sdn", "no-val-run");
  o.data = data;
  o.epochs = 1;
  const TrainResult r = Train(o);
  EXPECT_EQ(r.validated_on, "train (the dataset has no val split)");
  EXPECT_EQ(ReadJson(o.out / "state.json").value("validated_on", ""), r.validated_on);
  // Its learning curve says what it validated on (its legend said "validation RMSE").
  {
    std::ifstream script(o.out / "learning_curve.png.gp");  // written before gnuplot runs
    const std::string gp((std::istreambuf_iterator<char>(script)), std::istreambuf_iterator<char>());
    EXPECT_NE(gp.find("title 'RMSE on train (the dataset has no val split)'"), std::string::npos) << gp;
    EXPECT_EQ(gp.find("validation RMSE"), std::string::npos) << gp;
  }
  // With a val split, validation is on it.
  o = Options("sdn", "val-run");
  o.epochs = 1;
  EXPECT_EQ(Train(o).validated_on, "val");
}

TEST_F(TrainTest, AStateFileOfWrongTypesOrAFolderIsRefusedNamingTheField) {
  TrainOptions o = Options("sdn", "bad-state");
  o.epochs = 1;
  Train(o);
  const fs::path state = o.out / "state.json";
  const nlohmann::json good = ReadJson(state);
  o.epochs = 2;
  o.resume = true;
  for (const auto& [field, value] : {std::pair<const char*, nlohmann::json>{"seed", "1"},
                                     {"lr_schedule", 3}, {"flip", "yes"}, {"crop_scales", {1.0, "x"}}}) {
    nlohmann::json bad = good;
    bad[field] = value;
    std::ofstream(state) << bad.dump();
    ExpectTrainRefused(o, std::string("a state.json with ") + field + " = " + value.dump() + " resumed",
                       {state.string() + ": field \"" + field + "\" must be"});
  }
  fs::remove(state);
  fs::create_directories(state);  // a folder where the file should be
  ExpectTrainRefused(o, "a folder as state.json resumed", {state.string() + ": not a regular file"});
  fs::remove(state);
  std::ofstream(state) << good.dump();
}

TEST_F(TrainTest, AnEpochWhoseValidationIsNotFiniteResumesAndABadEpochFieldIsNamed) {
  // nlohmann writes NaN and inf as null: an epoch whose validation diverged made state.json
  // unreadable on --resume ("type must be number, but is null", naming no field).
  TrainOptions o = Options("sdn", "nan-epoch");
  o.epochs = 1;
  Train(o);
  const fs::path state = o.out / "state.json";
  const nlohmann::json good = ReadJson(state);
  nlohmann::json nan_epoch = good;
  nan_epoch["log"][0]["val_rmse"] = nullptr;
  std::ofstream(state) << nan_epoch.dump(2);
  TrainOptions resumed = o;
  resumed.epochs = 2;
  resumed.resume = true;
  const TrainResult r = Train(resumed);
  ASSERT_EQ(r.log.size(), 2u);
  EXPECT_TRUE(std::isnan(r.log[0].val_rmse)) << r.log[0].val_rmse;
  EXPECT_TRUE(std::isfinite(r.log[1].val_rmse));
  EXPECT_DOUBLE_EQ(r.best_val_rmse, r.log[1].val_rmse);
  // A field of another type is refused naming the epoch and the field.
  for (const auto& [field, value] : {std::pair<const char*, nlohmann::json>{"train_loss", "x"}, {"epoch", 1.5}}) {
    nlohmann::json bad = ReadJson(state);
    bad["log"][0][field] = value;
    std::ofstream(state) << bad.dump(2);
    ExpectTrainRefused(resumed, std::string("log[0].") + field + " = " + value.dump() + " resumed",
                       {state.string() + ": log[0]." + field + ": expected "});
  }
  // An "epoch" other than its log's length, or a log not numbered from 1, is refused (an edited
  // state.json resumed after its log's last epoch, whatever it said).
  for (const auto& [where, value] : {std::pair<std::string, int>{"epoch", 99}, {"epoch", -5}, {"log0", 3}}) {
    nlohmann::json bad = good;  // one epoch, numbered 1
    if (where == "epoch")
      bad["epoch"] = value;
    else
      bad["log"][0]["epoch"] = value;
    std::ofstream(state) << bad.dump(2);
    ExpectTrainRefused(resumed, where + " = " + std::to_string(value) + " resumed",
                       {state.string() + ": field \"epoch\" is ", "numbered from 1"});
  }
  nlohmann::json no_epoch = good;
  no_epoch.erase("epoch");
  std::ofstream(state) << no_epoch.dump(2);
  ExpectTrainRefused(resumed, "no epoch resumed", {state.string() + ": field \"epoch\" is missing"});
}

TEST_F(TrainTest, InitOnlyWithResumeIsRefusedAndTheModelKept) {
  // --init-only with --resume wrote the last epoch's raw weights over the run's best model.pt.
  TrainOptions o = Options("sdn", "init-resume");
  o.epochs = 1;
  Train(o);
  const std::string model = Bytes(o.out / "model.pt");
  o.resume = true;
  o.init_only = true;
  ExpectTrainRefused(o, "--init-only with --resume was accepted", {"--init-only", "--resume"});
  EXPECT_EQ(Bytes(o.out / "model.pt"), model);
}

TEST_F(TrainTest, ATrainSplitOfOneClipIsRefusedNamingTheIndex) {
  // One training clip trains batches of one, which batch normalisation cannot normalise (libtorch
  // threw mid-epoch, naming no option).
  const fs::path data = *root_ / "one-train-clip";
  ToyDatasetOptions d;
  d.clips = 6;
  d.frames = 40;
  d.size = 32;
  WriteToyDataset(data, d);
  nlohmann::json index = ReadJson(data / "index.json");
  nlohmann::json kept = nlohmann::json::array();
  int train = 0;
  for (const auto& clip : index["clips"])
    if (clip["split"] != "train" || train++ == 0) kept.push_back(clip);
  ASSERT_GE(train, 2) << "the toy dataset should have two train clips to drop one";
  index["clips"] = kept;
  std::ofstream(data / "index.json") << index.dump(2);
  TrainOptions o = Options("sdn", "one-train-clip-run");
  o.data = data;
  o.epochs = 1;
  ExpectTrainRefused(o, "a train split of one clip was trained",
                     {(data / "index.json").string() + ": split train has 1 clip; training needs at least 2"});
  EXPECT_FALSE(fs::exists(o.out)) << "refused before the run folder is made";
}

TEST_F(TrainTest, InitOnlyWritesALoadableModelWithoutData) {
  const TrainResult r = Train(InitOnly(*root_ / "init"));
  Predictor p(r.model, 1, "cpu");
  std::vector<cv::Mat> frames(30, cv::Mat(40, 50, CV_8UC1, cv::Scalar(9)));
  for (int i = 0; i < 30; ++i) frames[i] = cv::Mat(40, 50, CV_8UC1, cv::Scalar(9 + 3 * (i % 2)));
  PeakMaps maps;
  const Prediction pred = p.PredictFrames(frames, &maps);
  EXPECT_TRUE(std::isfinite(pred.speed));
  ASSERT_EQ(maps.frequency.size(), cv::Size(32, 32));
  // Every pixel alternates each frame: the strongest peak is the Nyquist rate, 12.5 Hz.
  EXPECT_NEAR(maps.frequency.at<float>(10, 10), 12.5f, 1e-4);
  EXPECT_THROW(p.PredictFrames(std::vector<cv::Mat>(29, frames[0])), std::invalid_argument);
  // Trained with flips (the default): it reads clips as they come.
  EXPECT_TRUE(p.config().flips_in_training);
  EXPECT_EQ(p.flag_flies(), FlagFlies::kRight);
  EXPECT_FALSE(pred.turned);
}

TEST_F(TrainTest, AModelTrainedWithoutFlipsTurnsFlagsFlyingLeft) {
  TrainOptions t = InitOnly(*root_ / "no-flip");
  t.flip = false;
  const TrainResult r = Train(t);
  std::ifstream json(r.model.parent_path() / "model.json");
  EXPECT_FALSE(nlohmann::json::parse(json).at("flips_in_training").get<bool>());
  Predictor p(r.model, 1, "cpu");
  EXPECT_FALSE(p.config().flips_in_training);
  EXPECT_EQ(p.flag_flies(), FlagFlies::kAuto);  // the node's default for it

  cv::RNG rng(3);
  std::vector<cv::Mat> frames(30), mirrored(30);
  for (int i = 0; i < 30; ++i) {
    frames[i] = cv::Mat(40, 50, CV_8UC1);
    rng.fill(frames[i], cv::RNG::UNIFORM, 0, 256);
    cv::flip(frames[i], mirrored[i], 1);
  }
  p.set_flag_flies(FlagFlies::kRight);
  const Prediction filmed = p.PredictFrames(frames), other_way = p.PredictFrames(mirrored);
  EXPECT_FALSE(filmed.turned);
  // The network is not mirror-symmetric (its outputs before the clamp at 0: an untrained one's
  // may both be below 0).
  EXPECT_NE(filmed.raw_speed, other_way.raw_speed);
  p.set_flag_flies(FlagFlies::kLeft);
  const Prediction turned = p.PredictFrames(mirrored);
  EXPECT_TRUE(turned.turned);
  EXPECT_DOUBLE_EQ(turned.raw_speed, filmed.raw_speed);
  EXPECT_DOUBLE_EQ(turned.speed, filmed.speed);
  EXPECT_DOUBLE_EQ(turned.speed_std, filmed.speed_std);
}

// A float below FLT_MIN: with denormals flushed it becomes 0 when multiplied. volatile keeps the
// compiler from folding the product at compile time.
float DenormalProduct() {
  volatile float tiny = 1e-39f, one = 1.0f;
  return tiny * one;
}

TEST_F(TrainTest, TrainingAndInferenceFlushDenormals) {
  // Denormal weights made CPU epochs several times slower late in training (docs/sdn-experiments.md).
  at::globalContext().setFlushDenormal(false);
  ASSERT_NE(DenormalProduct(), 0.0f);  // the check can see the difference
  const TrainResult r = Train(InitOnly(*root_ / "denormal"));
  EXPECT_EQ(DenormalProduct(), 0.0f);
  at::globalContext().setFlushDenormal(false);
  Predictor p(r.model, 1, "cpu");
  EXPECT_EQ(DenormalProduct(), 0.0f);
}

}  // namespace
}  // namespace clothwind::learn
