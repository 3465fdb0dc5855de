#include "learn/weights_io.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <torch/nn/modules/batchnorm.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>
#include <torch/serialize.h>
#include <unistd.h>

#include "learn/networks.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

// A small module with every kind of tensor a WindNet holds: weights, biases, batch-norm
// running statistics (float buffers) and its batch counter (an int64 buffer), in children.
torch::nn::Sequential SmallNet(uint64_t seed) {
  at::manual_seed(seed);
  torch::nn::Sequential net(torch::nn::Conv2d(torch::nn::Conv2dOptions(3, 5, 3)),
                            torch::nn::BatchNorm2d(5), torch::nn::Linear(4, 2));
  at::NoGradGuard no_grad;
  auto buffers = net->named_buffers();
  buffers["1.running_mean"].uniform_(-2, 2);
  buffers["1.running_var"].uniform_(0.5, 3);
  buffers["1.num_batches_tracked"].fill_(123);
  return net;
}

class WeightsIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_weights_io_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(WeightsIoTest, Float32RoundTripIsExact) {
  torch::nn::Sequential a = SmallNet(1), b = SmallNet(2);
  SaveModuleWeights(*a, dir_ / "a.pt", WeightPrecision::kFloat32);
  EXPECT_EQ(LoadModuleWeights(*b, dir_ / "a.pt"), WeightPrecision::kFloat32);
  auto pa = a->named_parameters(), pb = b->named_parameters();
  for (const auto& item : pa) EXPECT_TRUE(at::equal(item.value(), pb[item.key()])) << item.key();
  auto ba = a->named_buffers(), bb = b->named_buffers();
  for (const auto& item : ba) EXPECT_TRUE(at::equal(item.value(), bb[item.key()])) << item.key();
  EXPECT_EQ(bb["1.num_batches_tracked"].scalar_type(), at::kLong);
}

// A write into a folder that is not there fails naming the file it tried and why, and leaves
// nothing behind; the same text into an existing folder lands whole under its final name.
TEST_F(WeightsIoTest, AtomicWriteNamesTheFileAndTheReason) {
  const fs::path missing = dir_ / "no_such_folder" / "model.json";
  try {
    WriteFileAtomically(missing, "{}\n");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir_ / "no_such_folder" / "model.json.tmp").string()), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(dir_ / "no_such_folder"));
  WriteFileAtomically(dir_ / "model.json", "{\"a\": 1}\n");
  EXPECT_EQ(fs::file_size(dir_ / "model.json"), 9u);
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_EQ(entry.path().filename(), "model.json");
}

TEST_F(WeightsIoTest, Float16HalvesTheFileAndRoundsEachParameterOnce) {
  // Wide enough that the file is mostly weights, not archive overhead.
  at::manual_seed(4);
  torch::nn::Linear big(256, 256), back(256, 256);
  SaveModuleWeights(*big, dir_ / "f32.pt", WeightPrecision::kFloat32);
  SaveModuleWeights(*big, dir_ / "f16.pt", WeightPrecision::kFloat16);
  const double ratio = static_cast<double>(fs::file_size(dir_ / "f16.pt")) / fs::file_size(dir_ / "f32.pt");
  EXPECT_LT(ratio, 0.55);
  EXPECT_GT(ratio, 0.45);
  EXPECT_EQ(LoadModuleWeights(*back, dir_ / "f16.pt"), WeightPrecision::kFloat16);
  EXPECT_EQ(back->weight.scalar_type(), at::kFloat);
  // Round to nearest in float16: relative error at most 2^-11 (absolute 2^-25 among subnormals).
  const at::Tensor err = (back->weight - big->weight).abs();
  const at::Tensor bound = big->weight.abs() * std::ldexp(1.0, -11) + std::ldexp(1.0, -25);
  EXPECT_TRUE(at::all(err <= bound).item<bool>());
  EXPECT_GT(err.max().item<double>(), 0.0);  // it did go through float16
  // Saving the loaded weights in float16 again changes nothing: they are float16 values.
  SaveModuleWeights(*back, dir_ / "again.pt", WeightPrecision::kFloat16);
  torch::nn::Linear third(256, 256);
  LoadModuleWeights(*third, dir_ / "again.pt");
  EXPECT_TRUE(at::equal(third->weight, back->weight));

  // Buffers keep their precision and type.
  torch::nn::Sequential a = SmallNet(1), b = SmallNet(2);
  SaveModuleWeights(*a, dir_ / "small16.pt", WeightPrecision::kFloat16);
  LoadModuleWeights(*b, dir_ / "small16.pt");
  auto ba = a->named_buffers(), bb = b->named_buffers();
  for (const auto& item : ba) EXPECT_TRUE(at::equal(item.value(), bb[item.key()])) << item.key();
}

TEST_F(WeightsIoTest, ReadsFilesWrittenByTorchSave) {
  torch::nn::Sequential a = SmallNet(1), b = SmallNet(2);
  torch::save(a, (dir_ / "torch.pt").string());
  EXPECT_EQ(LoadModuleWeights(*b, dir_ / "torch.pt"), WeightPrecision::kFloat32);
  auto pa = a->named_parameters(), pb = b->named_parameters();
  for (const auto& item : pa) EXPECT_TRUE(at::equal(item.value(), pb[item.key()])) << item.key();
}

TEST_F(WeightsIoTest, RefusesOtherShapesAndOutOfRangeHalves) {
  torch::nn::Sequential a = SmallNet(1);
  SaveModuleWeights(*a, dir_ / "a.pt", WeightPrecision::kFloat16);
  torch::nn::Sequential wider(torch::nn::Conv2d(torch::nn::Conv2dOptions(3, 6, 3)), torch::nn::BatchNorm2d(6),
                              torch::nn::Linear(4, 2));
  try {
    LoadModuleWeights(*wider, dir_ / "a.pt");
    ADD_FAILURE() << "a file of another shape was loaded";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("a.pt: tensor 0.weight is [5, 3, 3, 3], the network expects [6, 3, 3, 3]"),
              std::string::npos) << what;
  }
  // 1e5 is beyond float16 (max 65504): refused, naming the parameter, and nothing written.
  {
    at::NoGradGuard no_grad;
    a->named_parameters()["2.bias"][1].fill_(1e5);
  }
  try {
    SaveModuleWeights(*a, dir_ / "big.pt", WeightPrecision::kFloat16);
    ADD_FAILURE() << "an out-of-range parameter was saved in float16";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("2.bias exceeds float16's range"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "big.pt"));
  EXPECT_THROW(LoadModuleWeights(*a, dir_ / "missing.pt"), std::runtime_error);
  // Values that are not finite (what corrupt bytes in an archive read as) are refused by name.
  torch::nn::Sequential nan_net = SmallNet(3);
  {
    at::NoGradGuard no_grad;
    nan_net->named_parameters()["0.weight"][0][0][0][0].fill_(std::nan(""));
  }
  SaveModuleWeights(*nan_net, dir_ / "nan.pt", WeightPrecision::kFloat32);
  try {
    LoadModuleWeights(*SmallNet(4), dir_ / "nan.pt");
    ADD_FAILURE() << "weights with a NaN were loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nan.pt: tensor 0.weight holds values that are not finite"),
              std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseWeightPrecision("bfloat16"), std::invalid_argument);
  EXPECT_EQ(ParseWeightPrecision(ToString(WeightPrecision::kFloat16)), WeightPrecision::kFloat16);
}

TEST_F(WeightsIoTest, HalfSdnPredictsAsTheFullOne) {
  ModelConfig c;
  c.arch = "sdn";
  c.width = 8;
  c.input_size = 32;
  at::manual_seed(5);
  WindNet net(c);
  net->eval();
  SaveWindNet(net, dir_ / "sdn.pt", WeightPrecision::kFloat16);
  WindNet half = LoadWindNet(dir_ / "sdn.pt");
  const at::Tensor x = at::randn({2, 1, 30, 32, 32});
  at::NoGradGuard no_grad;
  const at::Tensor full_out = net->forward(x), half_out = half->forward(x);
  EXPECT_FALSE(at::equal(full_out, half_out));
  EXPECT_TRUE(at::allclose(full_out, half_out, /*rtol=*/1e-2, /*atol=*/1e-2))
      << full_out << half_out;
}

}  // namespace
}  // namespace clothwind::learn
