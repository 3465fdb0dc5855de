// UseChannelsLast: the convolutions' kernels change memory order and nothing else, so a network
// answers as in torch's default order to float rounding, and so does the Predictor built on it.
// LoadWindNet: a model.json no network can be built from is refused naming the file and field.
#include "learn/networks.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "learn/predictor.h"
#include "learn/test_small_sdn.h"

namespace clothwind::learn {
namespace {


// Clips whose pixels oscillate at frequencies that vary across the frame, plus noise: the
// spectral maps then vary, so the trunk's convolutions see varied inputs.
at::Tensor WavyClips(int64_t n, int64_t size) {
  at::manual_seed(7);
  const at::Tensor t = at::arange(30, at::kFloat).reshape({1, 1, 30, 1, 1});
  const at::Tensor x = at::arange(size, at::kFloat).reshape({1, 1, 1, 1, size});
  const at::Tensor phase = at::rand({n, 1, 1, 1, 1}) * 6.0;
  return at::sin(0.4 * t + 0.3 * x + phase) + 0.1 * at::randn({n, 1, 30, size, size});
}

TEST(UseChannelsLastTest, ConvertsEveryKernelAndKeepsTheValues) {
  at::manual_seed(1);
  WindNet net(SmallSdn());
  net->eval();
  std::vector<at::Tensor> before;
  for (const at::Tensor& p : net->parameters()) before.push_back(p.detach().clone());
  UseChannelsLast(*net);
  int kernels = 0;
  size_t i = 0;
  for (const at::Tensor& p : net->parameters()) {
    EXPECT_TRUE(at::equal(p, before[i++]));
    if (p.dim() == 4) {
      ++kernels;
      EXPECT_TRUE(p.is_contiguous(at::MemoryFormat::ChannelsLast));
      // A 1x1 kernel's two orders are one and the same layout; a larger one's are not.
      if (p.size(2) > 1) {
        EXPECT_FALSE(p.is_contiguous());
      }
    }
  }
  // ResNet-18: the stem, 16 convolutions in the stages and 3 projection shortcuts.
  EXPECT_EQ(kernels, 20);
}

TEST(UseChannelsLastTest, NetworkAnswersAsInTheDefaultOrder) {
  at::manual_seed(2);
  WindNet first(SmallSdn());
  // Train-mode steps so the batch norms' running statistics are not the identity.
  {
    torch::optim::Adam adam(first->parameters(), torch::optim::AdamOptions(1e-3));
    first->train();
    for (int step = 0; step < 3; ++step) {
      adam.zero_grad();
      WindLoss(first->forward(WavyClips(4, 32)), at::randn({4})).backward();
      adam.step();
    }
  }
  first->eval();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("clothwind_networks_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  SaveWindNet(first, dir / "model.pt");
  WindNet last = LoadWindNet(dir / "model.pt");
  UseChannelsLast(*last);
  at::NoGradGuard no_grad;
  const at::Tensor clips = WavyClips(5, 32);
  const at::Tensor a = first->forward(clips), b = last->forward(clips);
  ASSERT_EQ(a.sizes(), b.sizes());
  EXPECT_TRUE(at::allclose(a, b, /*rtol=*/1e-4, /*atol=*/1e-5)) << (a - b).abs().max().item<double>();
  // Not the same numbers by accident of an unconverted path: the outputs differ between clips.
  EXPECT_GT((a.select(1, 0) - a.select(1, 0).mean()).abs().max().item<double>(), 1e-4);

  // The Predictor converts on the CPU by default; without it, torch's order: same speeds.
  Sample sample;
  const at::Tensor one = clips[2].contiguous();
  sample.pixels.assign(one.data_ptr<float>(), one.data_ptr<float>() + one.numel());
  Predictor nhwc(dir / "model.pt", 1, "cpu"), nchw(dir / "model.pt", 1, "cpu", /*channels_last=*/false);
  const Prediction p = nhwc.Predict({&sample})[0], q = nchw.Predict({&sample})[0];
  const ModelConfig& c = first->config();
  EXPECT_NEAR(q.raw_speed, c.label_mean + c.label_std * a[2][0].item<double>(), 1e-5 * c.label_std);
  EXPECT_NEAR(p.raw_speed, q.raw_speed, 1e-4 * c.label_std);
  EXPECT_NEAR(p.speed_std, q.speed_std, 1e-4 * q.speed_std);
  std::filesystem::remove_all(dir);
}

TEST(LoadWindNetTest, AFolderGivenAsTheModelIsNamedAsOne) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("clothwind_networks_folder_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  try {
    LoadWindNet(dir);
    ADD_FAILURE() << "a folder loaded as a model";
  } catch (const std::runtime_error& e) {
    // It was told "<folder>.json: cannot open".
    EXPECT_EQ(std::string(e.what()), dir.string() + ": a folder, expected a model's weights file (a .pt with its .json beside it)");
  }
  // A mistyped name: it was told "<name>.json: cannot open", the .pt unnamed.
  const std::filesystem::path none = dir / "nope.pt";
  try {
    LoadWindNet(none);
    ADD_FAILURE() << "a missing file loaded as a model";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), none.string() + ": no such file, expected a model's weights file (a .pt with its .json beside it)");
  }
  std::filesystem::remove_all(dir);
}

TEST(LoadWindNetTest, AModelJsonTheNetworkCannotBeBuiltFromIsNamed) {
  // "k": 20 on 30 frames passed the file's checks and stopped eval, export-model and sdn_node
  // with the constructor's std::invalid_argument, which named no file.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("clothwind_networks_load_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "model.pt") << "";  // there (a missing one is named first), never read
  for (const auto& [field, value] : std::vector<std::pair<std::string, int>>{{"k", 20}, {"frame_channels", 40}}) {
    nlohmann::json j = ToJson(SmallSdn());
    j[field] = value;
    std::ofstream(dir / "model.json") << j.dump();
    try {
      LoadWindNet(dir / "model.pt");
      ADD_FAILURE() << field << " " << value << " was loaded";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find((dir / "model.json").string() + ": field \"" + field + "\""), std::string::npos) << what;
    } catch (const std::exception& e) {
      ADD_FAILURE() << field << ": not a std::runtime_error naming model.json: " << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::learn
