// The point map head: the soft argmax's geometry (the coordinate maps' and the track targets'
// pixel-centre convention), the head on a trunk's stage maps, and a WindNet whose auxiliary
// positions come from it: the wind unchanged, the scale a saved buffer, shipping without it.
#include "learn/point_maps.h"

#include <filesystem>
#include <unistd.h>

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "learn/networks.h"
#include "learn/track_targets.h"
#include "learn/weight_average.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

TEST(SoftArgmax2d, APeakedMapReadsItsPixelCentreAndTwoPeaksTheirMidpoint) {
  // One map per case, 4 rows x 8 columns, so that a swapped axis or scale shows.
  at::Tensor logits = at::zeros({1, 3, 4, 8});
  logits[0][0][1][6] = 60;  // row 1, column 6 -> ((2·6 + 1)/8 - 1, (2·1 + 1)/4 - 1) = (0.625, -0.25)
  logits[0][1][3][0] = 60;  // the bottom-left pixel: (-0.875, 0.75)
  logits[0][1][3][1] = 60;  //   and its right neighbour, as likely: their midpoint (-0.75, 0.75)
  // Map 2 stays flat: the image's centre.
  const at::Tensor uv = SoftArgmax2d(logits);
  ASSERT_EQ(uv.sizes(), (at::IntArrayRef{1, 3, 2}));
  EXPECT_NEAR(uv[0][0][0].item<double>(), 0.625, 1e-6);
  EXPECT_NEAR(uv[0][0][1].item<double>(), -0.25, 1e-6);
  EXPECT_NEAR(uv[0][1][0].item<double>(), -0.75, 1e-6);
  EXPECT_NEAR(uv[0][1][1].item<double>(), 0.75, 1e-6);
  EXPECT_NEAR(uv[0][2][0].item<double>(), 0.0, 1e-6);
  EXPECT_NEAR(uv[0][2][1].item<double>(), 0.0, 1e-6);
  EXPECT_THROW(SoftArgmax2d(at::zeros({3, 4, 8})), std::invalid_argument);
}

TEST(SoftArgmax2d, ItsGradientIsTheFiniteDifferencesOfThePosition) {
  at::manual_seed(3);
  const at::Tensor logits = at::randn({2, 2, 3, 5}, at::kDouble).requires_grad_(true);
  const at::Tensor weights = at::randn({2, 2, 2}, at::kDouble);
  (SoftArgmax2d(logits) * weights).sum().backward();
  const at::Tensor grad = logits.grad();
  at::NoGradGuard no_grad;
  const double h = 1e-6;
  at::Tensor flat = logits.detach().clone().flatten();
  for (int64_t i = 0; i < flat.numel(); ++i) {
    at::Tensor plus = flat.clone(), minus = flat.clone();
    plus[i] += h;
    minus[i] -= h;
    const double fd = ((SoftArgmax2d(plus.view_as(logits)) * weights).sum().item<double>() -
                       (SoftArgmax2d(minus.view_as(logits)) * weights).sum().item<double>()) /
                      (2 * h);
    EXPECT_NEAR(grad.flatten()[i].item<double>(), fd, 1e-7) << "logit " << i;
  }
}

TEST(PointMapHead, ReadsStageMapsOfHalvingSizesOntoTheFinestGrid) {
  at::manual_seed(4);
  PointMapHead head(std::vector<int>{4, 8, 16}, /*points=*/5, /*features=*/6);
  const std::vector<at::Tensor> stages = {at::randn({2, 4, 8, 8}), at::randn({2, 8, 4, 4}), at::randn({2, 16, 2, 2})};
  EXPECT_EQ(head->Logits(stages).sizes(), (at::IntArrayRef{2, 5, 8, 8}));
  const at::Tensor uv = head->forward(stages);
  ASSERT_EQ(uv.sizes(), (at::IntArrayRef{2, 5, 2}));
  // Inside the square spanned by the outermost pixel centres.
  EXPECT_LE(uv.abs().max().item<double>(), 7.0 / 8 + 1e-6);
  // The coarsest stage reaches the maps through the pyramid.
  std::vector<at::Tensor> changed = stages;
  changed[2] = at::randn({2, 16, 2, 2});
  EXPECT_GT((head->forward(changed) - uv).abs().max().item<double>(), 1e-6);
  EXPECT_THROW(head->forward({stages[0], stages[1]}), std::invalid_argument);
}

ModelConfig TinySdnWithPointMaps(int points) {
  ModelConfig c;
  c.arch = "sdn";
  c.frames = 30;
  c.k = 2;
  c.width = 4;
  c.input_size = 32;
  c.aux_outputs = TrackTargetCount(points, 0);
  c.point_maps = points;
  return c;
}

TEST(WindNetPointMaps, PositionColumnsAreTheMapsStandardisedTheRestTheLinearHeads) {
  const int points = 3;
  const ModelConfig c = TinySdnWithPointMaps(points);
  EXPECT_EQ(c.Name(), "sdn-k2-pm-w4-32-30f");
  at::manual_seed(6);
  WindNet net(c);
  const at::Tensor mean = at::tensor({0.1f, -0.2f, 0.3f, 0.0f, -0.5f, 0.4f}).view({points, 2});
  const at::Tensor std = at::tensor({0.5f, 0.25f, 2.0f, 1.0f, 0.1f, 0.2f}).view({points, 2});
  net->SetPointScale(mean, std);
  EXPECT_THROW(net->SetPointScale(mean, -std), std::invalid_argument);
  EXPECT_THROW(net->SetPointScale(mean.view({-1}), std.view({-1})), std::invalid_argument);
  net->eval();
  at::NoGradGuard no_grad;
  const at::Tensor clips = at::randn({2, 1, 30, 32, 32});
  const WindNetImpl::Outputs out = net->ForwardWithAux(clips);
  ASSERT_EQ(out.aux.sizes(), (at::IntArrayRef{2, c.aux_outputs}));

  // The same weights without the maps: the wind and every column but the positions agree.
  ModelConfig linear_config = c;
  linear_config.point_maps = 0;
  WindNet linear(linear_config);
  CopyWeights(*net, *linear);
  linear->eval();
  const WindNetImpl::Outputs plain = linear->ForwardWithAux(clips);
  EXPECT_TRUE(at::allclose(out.wind, plain.wind));

  // Zero weights on the maps' last layer make every map flat: each point at the image's centre,
  // so its columns read (0 - mean) / std.
  for (auto& p : net->named_parameters()) {
    if (p.key().rfind("point_head.out.", 0) == 0) p.value().zero_();
  }
  const at::Tensor centred = net->ForwardWithAux(clips).aux;
  for (int p = 0; p < points; ++p) {
    for (int k = 0; k < kTargetsPerPoint; ++k) {
      const int column = p * kTargetsPerPoint + k;
      for (int i = 0; i < 2; ++i) {
        const double expected = k < 2 ? -(mean[p][k] / std[p][k]).item<double>() : plain.aux[i][column].item<double>();
        EXPECT_NEAR(centred[i][column].item<double>(), expected, 1e-5) << "point " << p << " target " << k;
      }
    }
  }
}

TEST(WindNetPointMaps, TheScaleIsSavedWithTheWeightsAndShippingDropsTheMaps) {
  const ModelConfig c = TinySdnWithPointMaps(2);
  at::manual_seed(7);
  WindNet net(c);
  net->SetPointScale(at::full({2, 2}, 0.25), at::full({2, 2}, 0.5));
  net->eval();
  const fs::path dir = fs::temp_directory_path() / ("point_maps_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  SaveWindNet(net, dir / "model.pt");
  WindNet loaded = LoadWindNet(dir / "model.pt");
  EXPECT_EQ(loaded->config().point_maps, 2);
  at::NoGradGuard no_grad;
  const at::Tensor clips = at::randn({2, 1, 30, 32, 32});
  EXPECT_TRUE(at::allclose(loaded->ForwardWithAux(clips).aux, net->ForwardWithAux(clips).aux));
  WindNet stripped = WithoutAuxHead(net);
  EXPECT_EQ(stripped->config().point_maps, 0);
  EXPECT_TRUE(at::allclose(stripped->forward(clips), net->forward(clips)));
  for (const auto& p : stripped->named_buffers()) EXPECT_EQ(p.key().rfind("point_", 0), std::string::npos) << p.key();
  fs::remove_all(dir);

  // A file whose maps outnumber its head's points, or on the per-frame LSTM, is refused by field.
  nlohmann::json j = ToJson(c);
  j["point_maps"] = 3;
  EXPECT_THROW(ModelConfigFromJson(j, "run/model.json"), std::runtime_error);
  j["point_maps"] = -1;
  EXPECT_THROW(ModelConfigFromJson(j, "run/model.json"), std::runtime_error);
  nlohmann::json old = ToJson(c);
  old.erase("point_maps");
  EXPECT_EQ(ModelConfigFromJson(old, "run/model.json").point_maps, 0);
  ModelConfig lstm = c;
  lstm.arch = "lstm";
  EXPECT_THROW(WindNet{lstm}, std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::learn
