// A keypoint head that finds the cloth's grid of material points as heat maps on the trunk's
// feature maps rather than regressing them from its pooled features (--point-maps). The linear
// auxiliary head reads a 64-px clip's points from a 2x2 map averaged to one vector and knows their
// window-mean positions to ~1.1 px (docs/sdn-experiments.md, "What the head knows of the points"),
// where the wind needs a fraction of a pixel. Heat maps with a soft argmax (integral regression,
// Sun et al., ECCV 2018) keep where things are in the image; a feature pyramid (Lin et al., CVPR
// 2017) brings the deep stages' context to the 4x-downsampled grid the maps live on.
#ifndef CLOTHWIND_LEARN_POINT_MAPS_H_
#define CLOTHWIND_LEARN_POINT_MAPS_H_

#include <vector>

#include <ATen/ATen.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/batchnorm.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/pimpl.h>

namespace clothwind::learn {

// The centres of `n` pixels along one image axis in the unit square: (2j + 1) / n - 1 for j = 0..n-1,
// so the image's edges are -1 and 1 and its centre 0 at any n (the coordinate maps' and TrackTargets'
// convention). Output: [n] with `options`' dtype and device.
at::Tensor PixelCentres(int64_t n, const at::TensorOptions& options);

// The expected position under each map's softmax, in the image's unit square.
// Inputs: logits [N, P, H, W]. Output: [N, P, 2], each point's (u, v) = Σ softmax(logits) · (x, y),
//   with pixel (row i, column j) at x = (2j + 1) / W - 1, y = (2i + 1) / H - 1: the coordinate maps'
//   and TrackTargets' convention, so (-1, -1) is the image's top-left corner, whatever H and W.
at::Tensor SoftArgmax2d(const at::Tensor& logits);

// Heat maps of `points` points from a ResNet trunk's stage maps, and their soft argmax.
class PointMapHeadImpl : public torch::nn::Module {
 public:
  // stage_channels  the channels of the stage maps forward() is given, finest first (ResNet-18:
  //   w, 2w, 4w, 8w); points  maps to output; features  the pyramid's channels.
  PointMapHeadImpl(const std::vector<int>& stage_channels, int points, int features = 64);
  // Inputs: stages  the trunk's stage maps, finest first, each [N, stage_channels[s], H_s, W_s] with
  //   each coarser one about half the size of the one before (ResNet18Trunk::StageMaps).
  // Output: [N, points, 2] positions (u, v) in the input image's unit square (SoftArgmax2d's
  //   convention), the maps living on the finest stage's grid.
  at::Tensor forward(const std::vector<at::Tensor>& stages);
  // The maps' logits [N, points, H_0, W_0] before the soft argmax (for inspection and tests).
  at::Tensor Logits(const std::vector<at::Tensor>& stages);

 private:
  torch::nn::ModuleList laterals_{nullptr};  // a 1x1 convolution per stage to `features` channels
  torch::nn::Conv2d smooth_{nullptr};        // 3x3 on the summed pyramid
  torch::nn::BatchNorm2d smooth_bn_{nullptr};
  torch::nn::Conv2d out_{nullptr};           // 1x1 to one map per point
};
TORCH_MODULE(PointMapHead);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_POINT_MAPS_H_
