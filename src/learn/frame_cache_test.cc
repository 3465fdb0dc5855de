#include "learn/frame_cache.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <future>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "learn/fly_judge.h"
#include "learn/train.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

class FrameCacheTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("clothwind_frame_cache_" + std::to_string(::getpid())));
    ToyDatasetOptions o;
    o.clips = 6;
    o.frames = 40;
    o.size = 48;
    WriteToyDataset(*dir_, o);
    clips_ = new std::vector<ClipInfo>(ReadDataset(*dir_).clips);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete clips_;
    delete dir_;
  }
  static SampleOptions Training() {
    SampleOptions o;
    o.frames = 20;
    o.input_size = 32;  // 48 -> 32: INTER_AREA, as FlagSim's 128 -> 64
    o.augment = true;
    o.crop_scales = {1.0};
    return o;
  }
  static void ExpectSameSample(const Sample& direct, const Sample& cached) {
    EXPECT_EQ(direct.first_frame, cached.first_frame);
    EXPECT_EQ(direct.flipped, cached.flipped);
    EXPECT_EQ(direct.wind_speed, cached.wind_speed);
    ASSERT_EQ(direct.pixels.size(), cached.pixels.size());
    EXPECT_EQ(direct.pixels, cached.pixels);  // bit for bit
  }
  static fs::path* dir_;
  static std::vector<ClipInfo>* clips_;
};
fs::path* FrameCacheTest::dir_ = nullptr;
std::vector<ClipInfo>* FrameCacheTest::clips_ = nullptr;

TEST_F(FrameCacheTest, TrainingSamplesEqualTheFilesBitForBitOnFirstAndLaterReads) {
  FrameCache cache(*clips_, 32);
  const SampleOptions o = Training();
  ASSERT_TRUE(FrameCache::Exact(o, (*clips_)[0], nullptr));
  int flipped = 0;
  std::set<int> starts;
  for (int pass = 0; pass < 2; ++pass) {  // pass 0 fills the cache, pass 1 reads it
    for (size_t i = 0; i < clips_->size(); ++i) {
      for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Sample direct = LoadSample((*clips_)[i], o, seed * 1000 + i);
        ExpectSameSample(direct, LoadSample(cache, i, o, seed * 1000 + i));
        flipped += direct.flipped;
        starts.insert(direct.first_frame);
      }
    }
  }
  // The draws did vary, so equality covers flips and temporal offsets, not one fixed window.
  EXPECT_GT(flipped, 0);
  EXPECT_GT(starts.size(), 3u);
}

TEST_F(FrameCacheTest, EvaluationSamplesEqualTheFilesWithAndWithoutMirror) {
  FrameCache cache(*clips_, 32);
  SampleOptions o = Training();
  o.augment = false;
  for (bool mirror : {false, true}) {
    o.mirror = mirror;
    for (int first : {-1, 0, 20}) {
      o.first_frame = first;
      for (size_t i = 0; i < clips_->size(); ++i) ExpectSameSample(LoadSample((*clips_)[i], o, 7), LoadSample(cache, i, o, 7));
    }
  }
}

TEST_F(FrameCacheTest, ColourSamplesEqualTheFilesBitForBit) {
  FrameCache cache(*clips_, 32, true);
  EXPECT_TRUE(cache.colour());
  SampleOptions o = Training();
  o.colour = true;
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < clips_->size(); ++i) {
      ExpectSameSample(LoadSample((*clips_)[i], o, 11 + i), LoadSample(cache, i, o, 11 + i));
    }
  }
  EXPECT_EQ(cache.Frames(0, 0, 1)[0].type(), CV_8UC3);
  EXPECT_EQ(cache.bytes(), clips_->size() * 40u * 32 * 32 * 3);
  o.augment = false;
  ExpectSameSample(LoadSample((*clips_)[2], o, 3), LoadSample(cache, 2, o, 3));
  // Grey samples from a colour cache, colour ones from a grey cache, and flow from colour frames
  // are refused.
  FrameCache grey(*clips_, 32);
  EXPECT_THROW(LoadSample(grey, 0, o, 1), std::invalid_argument);
  o.colour = false;
  EXPECT_THROW(LoadSample(cache, 0, o, 1), std::invalid_argument);
  EXPECT_THROW(cache.Flows(0, 0, 4), std::invalid_argument);
}

TEST_F(FrameCacheTest, HoldsEachFrameOnceAndOnlyTheFramesRead) {
  FrameCache cache(*clips_, 32);
  EXPECT_EQ(cache.bytes(), 0u);
  cache.Frames(0, 5, 10);
  EXPECT_EQ(cache.frames_held(), 10u);
  EXPECT_EQ(cache.bytes(), 40u * 32 * 32);  // the clip's 40 frames, allocated at once
  cache.Frames(0, 10, 10);  // 5 of these are held already
  EXPECT_EQ(cache.frames_held(), 15u);
  const std::vector<cv::Mat> frames = cache.Frames(0, 5, 15);
  EXPECT_EQ(cache.frames_held(), 15u);
  EXPECT_EQ(cache.bytes(), 40u * 32 * 32);
  cache.Frames(3, 0, 1);
  EXPECT_EQ(cache.bytes(), 80u * 32 * 32);
  ASSERT_EQ(frames.size(), 15u);
  EXPECT_EQ(frames[0].cols, 32);
  EXPECT_EQ(frames[0].rows, 32);
  EXPECT_EQ(frames[0].type(), CV_8UC1);
}

TEST_F(FrameCacheTest, ThreadsFillingOneCacheGetWhatOneThreadGets) {
  FrameCache shared(*clips_, 32), serial(*clips_, 32);
  const SampleOptions o = Training();
  std::vector<std::future<std::vector<Sample>>> parts;
  for (int t = 0; t < 4; ++t) {
    parts.push_back(std::async(std::launch::async, [&, t] {
      std::vector<Sample> out;
      for (size_t i = 0; i < clips_->size(); ++i) out.push_back(LoadSample(shared, i, o, 100 * t + i));
      return out;
    }));
  }
  for (int t = 0; t < 4; ++t) {
    const std::vector<Sample> got = parts[t].get();
    for (size_t i = 0; i < clips_->size(); ++i) ExpectSameSample(LoadSample(serial, i, o, 100 * t + i), got[i]);
  }
  EXPECT_EQ(shared.bytes(), serial.bytes());
  EXPECT_EQ(shared.frames_held(), serial.frames_held());
}

TEST_F(FrameCacheTest, FlowSamplesEqualTheFilesBitForBitAndAreComputedOnce) {
  FrameCache cache(*clips_, 32);
  SampleOptions o = Training();
  o.flow = true;
  int flipped = 0;
  for (int pass = 0; pass < 2; ++pass) {  // pass 0 fills the cache, pass 1 reads it
    for (size_t i = 0; i < clips_->size(); ++i) {
      for (uint64_t seed = 1; seed <= 3; ++seed) {
        const Sample direct = LoadSample((*clips_)[i], o, seed * 1000 + i);
        ASSERT_EQ(direct.channels, 3);
        ExpectSameSample(direct, LoadSample(cache, i, o, seed * 1000 + i));
        flipped += direct.flipped;
      }
    }
  }
  EXPECT_GT(flipped, 0);
  SampleOptions eval = o;
  eval.augment = false;
  for (bool mirror : {false, true}) {
    eval.mirror = mirror;
    for (size_t i = 0; i < clips_->size(); ++i) ExpectSameSample(LoadSample((*clips_)[i], eval, 7), LoadSample(cache, i, eval, 7));
  }
  // One allocation per clip read, of 16 bits x 2 components per pixel and frame.
  EXPECT_EQ(cache.flow_bytes(), clips_->size() * 40u * 32 * 32 * 4);
  // A flow computed on the files' 48-px frames, brought to 32 px, is cached alike; one cache holds
  // one flow size.
  FrameCache fine(*clips_, 32);
  SampleOptions fine_options = o;
  fine_options.flow_size = 48;
  for (size_t i = 0; i < clips_->size(); ++i) {
    const Sample direct = LoadSample((*clips_)[i], fine_options, 5 + i);
    ExpectSameSample(direct, LoadSample(fine, i, fine_options, 5 + i));
    ExpectSameSample(direct, LoadSample(fine, i, fine_options, 5 + i));
    EXPECT_NE(direct.pixels, LoadSample((*clips_)[i], o, 5 + i).pixels);  // the flow differs
  }
  EXPECT_THROW(LoadSample(fine, 0, o, 1), std::invalid_argument);
  // Flows of a window equal WindowFlows of its frames.
  const std::vector<cv::Mat> flows = cache.Flows(2, 3, 10);
  const std::vector<cv::Mat> fresh = WindowFlows(cache.Frames(2, 3, 10));
  ASSERT_EQ(flows.size(), 9u);
  for (size_t t = 0; t < flows.size(); ++t) EXPECT_EQ(cv::norm(flows[t], fresh[t], cv::NORM_INF), 0.0) << t;
}

TEST_F(FrameCacheTest, SaysWhenItWouldChangeTheSamples) {
  SampleOptions o = Training();
  std::string why;
  o.crop_scales = {1.0, 0.75};
  EXPECT_FALSE(FrameCache::Exact(o, (*clips_)[0], &why));
  EXPECT_THAT(why, ::testing::HasSubstr("--crop-scales 1"));
  o.crop_scales = {1.0};
  ClipInfo wide = (*clips_)[0];
  wide.width = 64;
  EXPECT_FALSE(FrameCache::Exact(o, wide, &why));
  EXPECT_THAT(why, ::testing::HasSubstr("64x48"));
  o.augment = false;  // evaluation takes the centre square of any frame
  EXPECT_TRUE(FrameCache::Exact(o, wide, &why));
  // Unless a fly judge decides the turn: it reads the files' crops at its own side.
  o.flag_flies = FlagFlies::kAuto;
  EXPECT_TRUE(FrameCache::Exact(o, wide, &why));  // motion cues without a judge: the same pixels
  const int cells = kMotionMapGrid * kMotionMapGrid;
  o.fly_judge = std::make_shared<const FlyJudge>(Eigen::MatrixXf::Zero(2, cells), Eigen::VectorXf::Zero(2),
                                                 Eigen::VectorXf::Zero(2), 0.0f);
  EXPECT_FALSE(FrameCache::Exact(o, wide, &why));
  EXPECT_THAT(why, ::testing::HasSubstr("fly judge"));

  FrameCache cache(*clips_, 24);
  EXPECT_THROW(LoadSample(cache, 0, Training(), 1), std::invalid_argument);  // 32 px asked of a 24 px cache
  EXPECT_THROW(cache.Frames(0, 30, 20), std::runtime_error);                 // past the clip's 40 frames
}

// With the cache, training keeps its validation split's trunk input images after the first
// validation (train.cc, ValidationImages) and drops the frames: every later validation, of the
// trained and of the averaged weights, reads those images. The run must be the files' run to the bit.
TEST_F(FrameCacheTest, TrainingWithTheCacheIsTheFilesRunBitForBit) {
  auto run = [&](bool cache_frames) {
    TrainOptions o;
    o.data = *dir_;
    o.out = *dir_ / (cache_frames ? "run_cached" : "run_files");
    o.model.arch = "sdn";
    o.model.frames = 20;
    o.model.input_size = 32;
    o.model.width = 8;
    o.model.phase_steps = true;
    o.crop_scales = {1.0};
    o.batch = 2;  // validation in several batches, the last a short one where the split is odd
    o.epochs = 3;
    o.lr = 1e-3;
    o.weight_average = 0.5;  // two validations an epoch
    o.cache_frames = cache_frames;
    return Train(o);
  };
  const TrainResult files = run(false), cached = run(true);
  ASSERT_EQ(files.log.size(), 3u);
  ASSERT_EQ(cached.log.size(), 3u);
  for (size_t e = 0; e < files.log.size(); ++e) {
    EXPECT_EQ(files.log[e].train_loss, cached.log[e].train_loss) << "epoch " << e + 1;
    EXPECT_EQ(files.log[e].val_loss, cached.log[e].val_loss) << "epoch " << e + 1;
    EXPECT_EQ(files.log[e].val_rmse, cached.log[e].val_rmse) << "epoch " << e + 1;
    EXPECT_EQ(files.log[e].raw_val_rmse, cached.log[e].raw_val_rmse) << "epoch " << e + 1;
  }
  // The epochs differ from one another, so equal figures are not equal constants.
  EXPECT_NE(files.log[0].val_rmse, files.log[2].val_rmse);
  EXPECT_NE(files.log[2].val_rmse, files.log[2].raw_val_rmse);
  for (const char* name : {"model.pt", "raw_model.pt", "last.pt", "last_average.pt"}) {
    const bool checkpoint = std::string(name).rfind("last", 0) == 0;
    const fs::path dir_a = checkpoint ? CheckpointDir(*dir_ / "run_files") : *dir_ / "run_files";
    const fs::path dir_b = checkpoint ? CheckpointDir(*dir_ / "run_cached") : *dir_ / "run_cached";
    std::ifstream a(dir_a / name, std::ios::binary), b(dir_b / name, std::ios::binary);
    const std::string bytes_a((std::istreambuf_iterator<char>(a)), {}), bytes_b((std::istreambuf_iterator<char>(b)), {});
    EXPECT_FALSE(bytes_a.empty()) << name;
    EXPECT_TRUE(bytes_a == bytes_b) << name << " differs";
  }
}

TEST_F(FrameCacheTest, TrainingRefusesTheCacheWithTheSeedsMultiScaleCrops) {
  TrainOptions o;
  o.data = *dir_;
  o.out = *dir_ / "run";
  o.model.frames = 20;
  o.model.input_size = 32;
  o.epochs = 1;
  o.cache_frames = true;  // with the default crop scales 1, 0.875, 0.75, 0.66
  try {
    Train(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("--cache-frames"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("--crop-scales 1"));
  }
}

}  // namespace
}  // namespace clothwind::learn
