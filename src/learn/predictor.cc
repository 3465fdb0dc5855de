#include "learn/predictor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/cuda.h>
#include <opencv2/imgproc.hpp>
#include <ATen/core/grad_mode.h>

#include "learn/fly_judge.h"
#include "learn/full_float32.h"
#include "learn/networks.h"
#include "learn/spectral_layer.h"

namespace clothwind::learn {

struct Predictor::Impl {
  WindNet net{nullptr};
  at::Device device = at::kCPU;
};

Predictor::Predictor(const std::filesystem::path& weights, int threads, const std::string& device,
                     bool channels_last)
    : impl_(std::make_unique<Impl>()) {
  // Flush denormals to zero: weight decay drives many weights and activations towards zero, and
  // denormal floats made CPU training epochs 3x slower after ~10 epochs. Set before the intra-op
  // threads exist: new threads inherit this thread's floating-point mode.
  at::globalContext().setFlushDenormal(true);
  if (threads > 0) at::set_num_threads(threads);
  if (device == "cuda" && !torch::cuda::is_available()) {
    throw std::runtime_error("device cuda requested but libtorch finds no CUDA device");
  }
  if (device != "cpu" && device != "cuda" && device != "auto") {
    throw std::runtime_error("device must be cpu, cuda or auto, got \"" + device + "\"");
  }
  impl_->device = (device != "cpu" && torch::cuda::is_available()) ? at::Device(at::kCUDA) : at::Device(at::kCPU);
  if (impl_->device.is_cuda()) UseFullFloat32OnCuda();
  impl_->net = LoadWindNet(weights);
  impl_->net->to(impl_->device);
  impl_->net->eval();
  if (channels_last && impl_->device.is_cpu()) UseChannelsLast(*impl_->net);
  flag_flies_ = config().DefaultFlagFlies();
  const std::filesystem::path beside = weights.parent_path() / kFlyJudgeFile;
  if (std::filesystem::exists(beside)) {
    try {
      LoadFlyJudge(beside);
    } catch (const std::exception& e) {
      // The model itself is fine: estimates go on (as filmed, or by the motion cues on auto), and
      // the caller reports the judge it could not read.
      fly_judge_error_ = std::string("the fly judge beside the model did not load: ") + e.what();
    }
  }
}

void Predictor::LoadFlyJudge(const std::filesystem::path& path) {
  if (path.empty()) {
    fly_judge_.reset();
  } else {
    fly_judge_ = std::make_shared<const FlyJudge>(FlyJudge::Load(path));
  }
  fly_judge_path_ = path;
  fly_judge_error_.clear();
}

Predictor::~Predictor() = default;

const ModelConfig& Predictor::config() const { return impl_->net->config(); }

std::string Predictor::device() const { return impl_->device.is_cuda() ? "cuda" : "cpu"; }

std::vector<Prediction> Predictor::Predict(const std::vector<const Sample*>& samples) {
  if (samples.empty()) return {};
  const ModelConfig& c = config();
  const int64_t per = static_cast<int64_t>(c.channels) * c.frames * c.input_size * c.input_size;
  at::Tensor batch = at::empty({static_cast<int64_t>(samples.size()), c.channels, c.frames, c.input_size, c.input_size});
  for (size_t i = 0; i < samples.size(); ++i) {
    if (static_cast<int64_t>(samples[i]->pixels.size()) != per) {
      throw std::invalid_argument("Predictor: sample " + std::to_string(i) + " has " +
                                  std::to_string(samples[i]->pixels.size()) + " values, the model reads " +
                                  std::to_string(per));
    }
    std::copy(samples[i]->pixels.begin(), samples[i]->pixels.end(), batch[i].data_ptr<float>());
  }
  at::NoGradGuard no_grad;
  at::Tensor out = impl_->net->forward(batch.to(impl_->device)).to(at::kCPU).to(at::kDouble).contiguous();
  std::vector<Prediction> predictions(samples.size());
  const double* o = out.data_ptr<double>();
  for (size_t i = 0; i < samples.size(); ++i) {
    predictions[i].raw_speed = c.label_mean + c.label_std * o[2 * i];
    predictions[i].speed = ClampSpeed(predictions[i].raw_speed);
    predictions[i].speed_std = c.std_scale * c.label_std * std::exp(0.5 * o[2 * i + 1]);
  }
  return predictions;
}

Sample Predictor::Prepare(const std::vector<cv::Mat>& frames) const {
  const ModelConfig& c = config();
  if (static_cast<int>(frames.size()) < c.frames) {
    throw std::invalid_argument("clip has " + std::to_string(frames.size()) + " frames, the model " + c.Name() +
                                " needs " + std::to_string(c.frames));
  }
  for (const cv::Mat& f : frames) {
    if (f.type() != FrameType(c.colour) || f.size() != frames[0].size() || f.empty()) {
      throw std::invalid_argument(c.colour ? "clip frames must be non-empty 8-bit YCrCb images of one size (the model " +
                                                 c.Name() + " reads colour)"
                                           : std::string("clip frames must be non-empty mono8 images of one size"));
    }
  }
  SampleOptions options = c.Sampling();
  options.flag_flies = flag_flies_;
  options.fly_judge = fly_judge_;
  options.undecided_turns = last_turned_;
  std::vector<cv::Mat> last(frames.end() - c.frames, frames.end());
  std::mt19937_64 unused(0);
  return MakeSample(last, options, unused);
}

double ClipMotion(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) return 0.0;
  const int rows = frames[0].rows, cols = frames[0].cols;
  // Each pixel's differences from the first frame, summed and squared in integers: exact (a
  // frozen clip reads 0, and 29 squares of 255 fit), and on sdn_node's path per clip, where
  // cv::accumulate's doubles took 1.9 ms of a 300 px clip's 13. The spread of x is that of x - x0.
  std::vector<int32_t> sum(static_cast<size_t>(rows) * cols, 0), squares(sum.size(), 0);
  const int first_step = frames[0].channels();
  for (size_t t = 1; t < frames.size(); ++t) {
    const int step = frames[t].channels();  // the first channel: grey, or Y
    for (int y = 0; y < rows; ++y) {
      const uint8_t* first = frames[0].ptr<uint8_t>(y);
      const uint8_t* row = frames[t].ptr<uint8_t>(y);
      int32_t* s = sum.data() + static_cast<size_t>(y) * cols;
      int32_t* q = squares.data() + static_cast<size_t>(y) * cols;
      if (step == 1 && first_step == 1) {  // grey: contiguous, which the compiler vectorises
        for (int x = 0; x < cols; ++x) {
          const int32_t d = row[x] - first[x];
          s[x] += d;
          q[x] += d * d;
        }
      } else {
        for (int x = 0; x < cols; ++x) {
          const int32_t d = row[x * step] - first[x * first_step];
          s[x] += d;
          q[x] += d * d;
        }
      }
    }
  }
  const double n = static_cast<double>(frames.size());
  double total = 0;
  for (size_t i = 0; i < sum.size(); ++i) {
    const double mean = sum[i] / n;
    total += std::sqrt(std::max(squares[i] / n - mean * mean, 0.0));
  }
  return sum.empty() ? 0.0 : total / static_cast<double>(sum.size());
}

double ClipContrast(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) return 0.0;
  double total = 0;
  int counted = 0;
  for (size_t t = 0; t < frames.size(); t += 5) {
    // In float: an 8-bit blur rounded spreads of a level or two to whole levels. One spread over
    // the whole frame, about its mean: a fit of the frame's broad shading (tried, to take out a
    // light leak's gradient) read a small flag in a graded sky, a plain flag's broad shading and a
    // horizon in an 8 px clip as no scene.
    cv::Mat blurred;
    cv::boxFilter(frames[t], blurred, CV_32F, cv::Size(9, 9), cv::Point(-1, -1), true, cv::BORDER_REFLECT);
    cv::Scalar mean, spread;
    cv::meanStdDev(blurred, mean, spread);
    double largest = 0;
    for (int c = 0; c < frames[t].channels(); ++c) largest = std::max(largest, spread[c]);
    total += largest;
    ++counted;
  }
  return total / counted;
}

Prediction Predictor::PredictFrames(const std::vector<cv::Mat>& frames, PeakMaps* maps) {
  Sample sample = Prepare(frames);
  Prediction p = Predict({&sample})[0];
  p.motion = ClipMotion(std::vector<cv::Mat>(frames.end() - config().frames, frames.end()));
  p.no_motion = p.motion < kMinClipMotion;
  p.contrast = ClipContrast(std::vector<cv::Mat>(frames.end() - config().frames, frames.end()));
  p.no_scene = p.contrast < kMinClipContrast;
  p.turned = sample.turned;
  p.undecided = sample.undecided;
  // A clip without motion or scene is no measurement, of the way either (a covered lens's noise
  // was judged, and set the way a later calm clip was read).
  if (flag_flies_ == FlagFlies::kAuto && !sample.undecided && !p.no_motion && !p.no_scene)
    last_turned_ = sample.turned;
  const ModelConfig& c = config();
  if (maps != nullptr && c.arch == "sdn") {
    // The grey channel's maps (channel 0; flow channels, when the model has them, follow it).
    at::Tensor clip = at::from_blob(sample.pixels.data(), {1, 1, c.frames, c.input_size, c.input_size}, at::kFloat);
    SpectralOptions strongest = c.Spectral();
    strongest.k = 1;
    // The node shows power and frequency only: none of the extra channels (phase_step_far without
    // phase_steps is refused, so a model trained with it lost every estimate while rviz watched).
    strongest.phase_steps = false;
    strongest.phase_step_far = 0;
    strongest.mode_shape = false;
    SpectralMaps m = SpectralDecomposition(clip, strongest);
    maps->power = cv::Mat(c.input_size, c.input_size, CV_32F);
    maps->frequency = cv::Mat(c.input_size, c.input_size, CV_32F);
    std::copy_n(m.power.contiguous().data_ptr<float>(), m.power.numel(), maps->power.ptr<float>());
    std::copy_n(m.frequency.contiguous().data_ptr<float>(), m.frequency.numel(), maps->frequency.ptr<float>());
    // The maps show the camera's picture: a clip turned round for the model is turned back (the
    // layer is per pixel, so this is exactly the maps of the clip as filmed).
    if (sample.flipped) {
      cv::flip(maps->power, maps->power, 1);
      cv::flip(maps->frequency, maps->frequency, 1);
    }
  }
  return p;
}

cv::Mat ColourMapped(const cv::Mat& value, double lo, double hi, int colormap) {
  cv::Mat scaled;
  const double range = hi > lo ? hi - lo : 1.0;
  value.convertTo(scaled, CV_8U, 255.0 / range, -lo * 255.0 / range);  // saturates outside [lo, hi]
  cv::Mat colour;
  cv::applyColorMap(scaled, colour, colormap);
  return colour;
}

cv::Mat FrequencyMapImage(const PeakMaps& maps, double nyquist) {
  cv::Mat image = ColourMapped(maps.frequency, 0, nyquist, cv::COLORMAP_JET);
  double strongest = 0;
  cv::minMaxLoc(maps.power, nullptr, &strongest);
  image.setTo(cv::Scalar::all(0), maps.power < kFrequencyMapPowerFraction * strongest);
  return image;
}

}  // namespace clothwind::learn
