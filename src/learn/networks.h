// The wind regression networks of Table 1 written with torch::nn: the SDN (spectral layer +
// ResNet-18), the ResNet-18 baseline that reads N_t frames stacked as channels, and the
// recurrent baseline of Yang et al. (ICCV 2017: a CNN per frame, an LSTM over the frames). All
// end in a head predicting the (normalised) wind speed and its log variance.
#ifndef CLOTHWIND_LEARN_NETWORKS_H_
#define CLOTHWIND_LEARN_NETWORKS_H_

#include <filesystem>

#include <torch/nn/init.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/batchnorm.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/rnn.h>
#include <torch/nn/pimpl.h>

#include "learn/model_config.h"
#include "learn/point_maps.h"
#include "learn/spectral_layer.h"
#include "learn/weights_io.h"

namespace clothwind::learn {

// ResNet's basic block: two 3x3 convolutions with batch norm and an identity (or 1x1 strided
// projection) shortcut.
class BasicBlockImpl : public torch::nn::Module {
 public:
  BasicBlockImpl(int in_channels, int out_channels, int stride);
  at::Tensor forward(const at::Tensor& x);

 private:
  torch::nn::Conv2d conv1_{nullptr}, conv2_{nullptr};
  torch::nn::BatchNorm2d bn1_{nullptr}, bn2_{nullptr};
  torch::nn::Sequential shortcut_{nullptr};
};
TORCH_MODULE(BasicBlock);

// ResNet-18 trunk: 7x7/2 convolution, 3x3/2 max pool, four stages of two basic blocks
// (widths w, 2w, 4w, 8w; stride 2 from the second stage), global average pooling.
class ResNet18TrunkImpl : public torch::nn::Module {
 public:
  // in_channels  channels of the input image; width  w, the first stage's width (64 originally);
  // stem_pool  the 3×3 stride-2 max pool after the stem (ResNet-18's; false: the stages see twice
  // the resolution)
  ResNet18TrunkImpl(int in_channels, int width, bool stem_pool = true);
  // x [N_b, in_channels, H, W] -> features [N_b, 8w]: FeatureMap averaged over its pixels
  at::Tensor forward(const at::Tensor& x);
  // map [N_b, C, h, w] -> [N_b, C], averaged over its pixels (forward's pooling)
  static at::Tensor Pooled(const at::Tensor& map);
  // x [N_b, in_channels, H, W] -> the last stage's map [N_b, 8w, ⌈H/32⌉, ⌈W/32⌉] (⌈H/16⌉, ⌈W/16⌉
  // without the stem pool)
  at::Tensor FeatureMap(const at::Tensor& x);
  // x [N_b, in_channels, H, W] -> the four stages' maps, finest first: [N_b, w, H/4, W/4],
  // [N_b, 2w, H/8, W/8], [N_b, 4w, H/16, W/16], [N_b, 8w, H/32, W/32] (sizes rounded up; twice
  // each without the stem pool). The last is FeatureMap's.
  std::vector<at::Tensor> StageMaps(const at::Tensor& x);
  // Channels of StageMaps' maps, finest first.
  std::vector<int> stage_channels() const;
  int feature_size() const { return features_; }

 private:
  torch::nn::Conv2d stem_{nullptr};
  torch::nn::BatchNorm2d stem_bn_{nullptr};
  torch::nn::Sequential stages_{nullptr};
  bool stem_pool_ = true;
  int features_ = 0;
};
TORCH_MODULE(ResNet18Trunk);

// A whole wind network as described by a ModelConfig.
class WindNetImpl : public torch::nn::Module {
 public:
  explicit WindNetImpl(const ModelConfig& config);
  // Inputs:
  //   clips  [N_b, C, N_t, H, W] per-clip normalised frames (N_t = config.frames, H = W =
  //          config.input_size)
  // Outputs:
  //   [N_b, 2]: column 0 the normalised speed (v - label_mean) / label_std, column 1 its log
  //   variance (normalised units), clamped to [-12, 8]
  at::Tensor forward(const at::Tensor& clips);
  // forward's output and, with config.aux_outputs > 0, the auxiliary head's [N_b, aux_outputs]
  // (standardised track targets; undefined without the head), from one pass through the trunk.
  // With config.point_maps = P > 0 the window-mean positions among them (columns 12p and 12p + 1,
  // TrackTargets' order) are the point map head's, standardised by SetPointScale's scale; the
  // other columns stay the linear head's.
  struct Outputs {
    at::Tensor wind, aux;
  };
  Outputs ForwardWithAux(const at::Tensor& clips);
  // ForwardWithAux from the trunk's input images of `batch` clips (images = TrunkInput(clips)):
  // the same outputs, for a caller that computed the images beforehand. TrunkInput has no
  // weights, so training computes its validation clips' images once, not every epoch.
  Outputs ForwardImages(const at::Tensor& images, int64_t batch);
  // The trunk's input images: the stacked spectral maps [N_b, 2kC, H, W] (SDN: log1p of the
  // power, frequency divided by the Nyquist rate, so both are O(1)), the frames as channels
  // [N_b, N_t·C, H, W] (resnet18), or every frame on its own [N_b·N_t, C, H, W] (lstm). An SDN
  // with spectral_pool p > 1 returns its maps average-pooled to [N_b, ·, H/p, W/p]; one with
  // frame_channels N appends the frames FrameChannelIndices() picks as N·C channels after them.
  // With coord_maps every architecture's images get two more channels last: the column and the
  // row of each pixel centre, scaled to (-1, 1).
  at::Tensor TrunkInput(const at::Tensor& clips) const;
  const ModelConfig& config() const { return config_; }
  // Sets the calibration factor of the predicted std (no weight depends on it).
  void set_std_scale(double scale) { config_.std_scale = scale; }
  // With point_maps = P > 0: the mean and std [P, 2] that standardise the (u, v) positions the
  // point map head finds, as the targets are (training sets them from its train split; they are
  // buffers, saved with the weights). Throws std::invalid_argument on other shapes or without maps.
  void SetPointScale(const at::Tensor& mean, const at::Tensor& std);

 private:
  // TrunkInput without the coordinate maps: the architecture's own images of checked clips.
  at::Tensor ArchImages(const at::Tensor& clips) const;
  // images [N, ch, H, W] -> [N, ch + 2, H, W] with coord_maps (column, row), else unchanged.
  at::Tensor WithCoordMaps(const at::Tensor& images) const;

  ModelConfig config_;
  ResNet18Trunk trunk_{nullptr};
  torch::nn::LSTM lstm_{nullptr};  // lstm only: hidden size = the trunk's 8w features
  torch::nn::Linear head_hidden_{nullptr};  // head_hidden > 0 only: features -> ReLU units
  torch::nn::Linear head_{nullptr};
  torch::nn::Linear aux_head_{nullptr};  // aux_outputs > 0 only
  PointMapHead point_head_{nullptr};     // point_maps > 0 only
  at::Tensor point_mean_, point_std_;    // point_maps > 0 only: [P, 2] buffers
};
TORCH_MODULE(WindNet);

// The training loss of a batch: mean squared error of the speed plus the Gaussian negative log
// likelihood of the residual under the predicted variance, with the mean detached in the NLL so
// the variance head cannot slow down the regression (normalised units).
// Inputs: output [N_b, 2] of WindNet, target [N_b] normalised speeds. Output: scalar loss.
at::Tensor WindLoss(const at::Tensor& output, const at::Tensor& target);

// The auxiliary loss: mean squared error of the auxiliary head's outputs [N_b, A] against the
// standardised targets [N_b, A] (each target then weighs about 1 whatever its units).
at::Tensor AuxLoss(const at::Tensor& aux, const at::Tensor& target);

// Saves the network's parameters and buffers to `weights` (torch::save's layout; parameters
// in float16 when asked: half the file, for the shipped model) with its ModelConfig inside, and
// the ModelConfig to ConfigPathFor(weights), both atomically (temporary file, then rename).
void SaveWindNet(WindNet& net, const std::filesystem::path& weights,
                 WeightPrecision precision = WeightPrecision::kFloat32);

// The same network without its auxiliary head (ModelConfig::aux_outputs 0), for shipping: the head
// is a training aid that no estimate reads. Every other parameter and buffer is copied, so
// forward() gives the same output. A network without the head is returned as a copy.
// Inputs: net  a WindNet (any config). Output: a new WindNet in eval mode on the CPU.
WindNet WithoutAuxHead(WindNet& net);

// Loads a network saved by SaveWindNet in either precision (config from the JSON beside the
// weights) as float32, in eval mode on the CPU. Throws std::runtime_error naming the file
// that is missing or does not match, and the tensor; naming the JSON and its field for a
// network that cannot be built (ModelConfigFromJson; e.g. "k" beyond the DFT's bins); and naming the JSON and each field in
// which it differs from the configuration saved inside the weights (a model.json edited or
// swapped: input_size, frames, frame_rate, label scale, ... shape no tensor). Weights saved
// before the configuration was stored inside them load under their JSON as it is.
WindNet LoadWindNet(const std::filesystem::path& weights);

// Puts every 4-D parameter and buffer of `module` (the convolutions' kernels) in channels-last
// (NHWC) memory order, values unchanged. Why: on the CPU a convolution with an NHWC kernel runs
// oneDNN's NHWC path and hands its activations on in that order, so the whole trunk runs there;
// with OpenBLAS the shipped SDN's inference per clip takes ~10 % less time (3 ms of 28 on one
// thread; bench/sdn_bench --both-orders). Outputs match the default order's to float rounding,
// not bit for bit. For inference: saving or training such a module works but is untested.
// Inputs: module  any torch module (a WindNet); modified in place.
void UseChannelsLast(torch::nn::Module& module);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_NETWORKS_H_
