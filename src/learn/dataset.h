// Reading the clothwind dataset format (docs/dataset.md: index.json + <name>/label.json + JPEG
// frames), the seed's training augmentations, and a small synthetic dataset for tests.
// Torch-free: samples are plain float arrays, so tools and nodes need no torch headers.
#ifndef CLOTHWIND_LEARN_DATASET_H_
#define CLOTHWIND_LEARN_DATASET_H_

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "learn/fly_direction.h"

namespace clothwind::learn {

class FlyJudge;  // fly_judge.h

// One example as listed by index.json and described by its label.json.
struct ClipInfo {
  std::string name;
  std::filesystem::path dir;   // folder of its frames and label.json
  std::string split;           // "train", "val" or "test"
  int simulation = -1;         // index.json's "simulation" (a simulated dataset's views share it); -1: none
  double wind_speed = 0;       // regression target [m/s]
  int num_frames = 0;
  double frame_rate = 25;      // [Hz]
  int width = 0, height = 0;   // [px]
  std::string frame_pattern;   // printf pattern of one integer, e.g. "%03d.jpg"
  std::string encoding = "mono8";  // of its frames: "mono8" or "rgb8"
};

struct Dataset {
  std::filesystem::path root;
  std::string kind;  // "flag", "cloth", "real" or "toy" (make-toy-dataset); others are refused
  std::vector<ClipInfo> clips;
  // Recorded clips (kind "real") whose anemometer gave no reading in their label window
  // (wind_speed null: the anemometer started late, a serial dropout): kept on disk for their
  // video, left out of `clips` (no target to train or score on) and counted here, in all and
  // by the split index.json (or label.json) gives them ("train", "val", "test").
  size_t unlabelled = 0;
  std::map<std::string, size_t> unlabelled_by_split;
};

// Parses a JSON file. Throws std::runtime_error naming the file when it cannot be opened or parsed.
nlohmann::json ReadJson(const std::filesystem::path& path);

// Reads DIR/index.json and every listed DIR/<name>/label.json (frames are read lazily). A
// recorded clip without a wind label is left out and counted (Dataset::unlabelled); in any other
// kind of dataset a missing label is an error.
// Throws std::runtime_error naming the file and the field that is missing or wrong.
Dataset ReadDataset(const std::filesystem::path& dir);

// The examples of one split ("train", "val", "test"), or all of them for "all".
std::vector<ClipInfo> SelectSplit(const Dataset& dataset, const std::string& split);

// The recorded clips without a wind label that SelectSplit(dataset, split) leaves out: those of
// `split`, or all of them for "all" (0 for a split with none).
size_t UnlabelledIn(const Dataset& dataset, const std::string& split);

// Throws std::runtime_error naming the first clip's label.json whose frame_rate differs from
// `model_rate` [Hz] by more than 1 %: the SDN reads frequencies in Hz at its own rate, so a clip
// at another rate gives a wrong wind without any other sign (sdn_node refuses them too). With
// `colour` (a model that reads Y Cr Cb), also the first clip whose encoding is "mono8": its frames
// would read as colourless, two of the model's three channels constant. And the first clip with
// fewer than `frames` frames (the model's N_t), naming its field num_frames.
void CheckClipsSuitModel(const std::vector<ClipInfo>& clips, double model_rate, bool colour, int frames);

// Frames first..first+count-1 of a clip as greyscale CV_8UC1 images (colour JPEGs converted) or,
// with `colour`, as CV_8UC3 images in YCrCb order (OpenCV's BGR2YCrCb: Y is the grey of the
// greyscale frames, Cr and Cb say how red and how blue a pixel is beyond its grey).
// Throws std::runtime_error naming the frame file when it is missing, unreadable or of a size
// other than the label's.
std::vector<cv::Mat> LoadFrames(const ClipInfo& clip, int first, int count, bool colour = false);

// The OpenCV type of LoadFrames' frames: CV_8UC1 (grey) or, with `colour`, CV_8UC3 (YCrCb).
inline int FrameType(bool colour) { return colour ? CV_8UC3 : CV_8UC1; }

// Camera clip frames (the clip buffer's mono8 or bgr8) as LoadFrames would give them, so a node
// feeds a model what it was trained on: grey frames for a grey model (BGR converted), YCrCb for a
// colour one.
// Inputs:
//   frames  T images of one size, all CV_8UC1 (grey) or all CV_8UC3 (BGR)
//   colour  the model reads colour (ModelConfig::colour)
// Returns T images of type FrameType(colour); grey frames for a grey model are returned as they
// are (no copy). Throws std::invalid_argument for grey frames given to a colour model (the grey
// cannot be coloured back: the clip buffer must send bgr8, its ~colour parameter) and for other
// image types.
std::vector<cv::Mat> CameraFramesForModel(const std::vector<cv::Mat>& frames, bool colour);

// How a clip becomes a network input [C, frames, input_size, input_size]: C = 1 (greyscale, as
// the seed) or, with `flow`, C = 3 (greyscale, then the optical flow's x and y components) or,
// with `colour`, C = 3 (Y, Cr, Cb).
struct SampleOptions {
  int frames = 30;        // N_t
  int input_size = 112;   // output side [px]
  bool augment = false;   // training: random temporal offset, multi-scale crop, flip
  // Augmenting: flip horizontally with probability 1/2 (the seed's). false keeps every sample
  // the way round the camera filmed it, why: FlagSim's cameras all stand on one side of the flag,
  // so its test clips all fly one way. The coin is still drawn, so that the other draws are the
  // same either way.
  bool flip = true;
  int first_frame = -1;   // >= 0: start the window here (evaluation over several windows)
  bool mirror = false;    // not augmenting: flip horizontally (evaluation's mirror averaging)
  // Not augmenting: mirror the clip before anything else, as if its flag flew the other way
  // (eval --mirror-clips: how a model reads flags that fly left, which FlagSim has none of).
  bool mirror_clip = false;
  // Not augmenting: which way the clip's flag flies, so that it is turned to fly right before
  // the model reads it (after mirror_clip, before mirror): kRight reads it as it comes, kLeft
  // mirrors it, kAuto mirrors it when fly_judge (or, without one, EstimateFlyDirection) of the
  // cropped, resized grey (or Y) frames says left. Why: a model trained without flips (train
  // --no-flip) knows only flags that fly right.
  FlagFlies flag_flies = FlagFlies::kRight;
  // With kAuto: the learned judge that decides (fly_judge.h; shared, it is only read). Null: the
  // clip's motion cues (EstimateFlyDirection), right for only ~91 % of FlagSim's clips.
  std::shared_ptr<const FlyJudge> fly_judge;
  // With kAuto and a judge: whether a clip it cannot tell (FlyJudge::Judge's margin: a calm or
  // featureless clip) is turned round. False: read as filmed; the node's Predictor passes the way
  // it last knew (a calm spell keeps the flag's side rather than a coin's).
  bool undecided_turns = false;
  bool flow = false;      // two more channels: each frame's optical flow from the one before (FrameFlow)
  // Side [px] the crop is resized to for the flow, which is then resized to input_size and
  // scaled with it (0: input_size). A finer flow reads the cloth's sub-pixel motion more exactly.
  int flow_size = 0;
  // Colour frames (LoadFrames' YCrCb) instead of grey, why: the grey of a flag's colours can
  // coincide (FlagSim's red and green differ by 4 of 255 in grey, sky blue and orange by 7), and
  // a stripe edge the grey hides moves without changing a grey pixel. Not with flow.
  bool colour = false;
  // Crop side as fractions of the frame's shorter side (multi-scale cropping, as TSN).
  std::vector<double> crop_scales = {1.0, 0.875, 0.75, 0.66};
  // C, the channels per frame of the samples these options make: 1 (grey), 3 with flow or colour.
  int channels() const { return flow || colour ? 3 : 1; }
};

// A network input with the augmentation that produced it (for tests and logs).
struct Sample {
  // C x frames x input_size x input_size. Channel 0: grey (or Y), less its per-clip mean; a
  // grey sample is divided by its per-clip std (unit std; at least 1e-3 is divided by).
  // Colour samples: Y, Cr and Cb (channels 1, 2) each less its own per-clip mean, all three
  // divided by one std, the root mean of their three variances (at least 1e-3): the three have
  // unit mean variance, not Y alone (a colourless clip's Y has std √3). So a flag whose colours
  // share one grey keeps its colour edges at their strength, and a black-and-white one gets no
  // amplified JPEG noise.
  // Channels 1, 2 (options.flow): flow x (right) and y (down) [input pixels per frame], unnormalised:
  // how far the cloth moves is the measurement, so it keeps its scale.
  std::vector<float> pixels;
  int channels = 1;           // C
  float wind_speed = 0;       // [m/s]
  int first_frame = 0;        // temporal offset used
  cv::Rect crop;              // square crop taken from the frames [px]
  bool flipped = false;       // the pixels are mirrored relative to the frames given
  bool turned = false;        // SampleOptions::flag_flies mirrored the clip (its flag flies left)
  double fly_score = 0;       // with flag_flies kAuto: the fly judge's (or motion cues') score (> 0: right)
  bool undecided = false;     // with kAuto: the judge could not tell (turned by undecided_turns)
};

// The frame window of a clip: options.first_frame when set, else uniformly random when augmenting,
// centred otherwise. Throws std::runtime_error when the clip is too short for the window.
int ChooseFirstFrame(int num_frames, const SampleOptions& options, std::mt19937_64& rng);

// The centred square of the shorter side of a width x height frame: evaluation's crop.
cv::Rect CentreSquare(int width, int height);

// Resizes frame(crop) to side x side into `out` (area interpolation when shrinking, linear when
// enlarging), as MakeSample does for every frame. An `out` already side x side of the frame's type
// is written in place.
void ResizeCrop(const cv::Mat& frame, const cv::Rect& crop, int side, cv::Mat& out);

// Dense optical flow from `previous` to `next` (DIS, OpenCV's medium preset), why: the intensity
// spectra read texture, not motion — a stripe running along the wind changes few pixels as a
// wave travels down it — while the flow is how far each pixel's content moved whatever it shows.
// Inputs: two CV_8UC1 images of one size H x W. Output: H x W CV_32FC2, (dx, dy) [px] per pixel
// of `previous`. DIS reads a sub-pixel shift of a textured image to ~0.05 px (test
// FrameFlowReadsAKnownShift). Throws std::invalid_argument for images of other types or sizes.
cv::Mat FrameFlow(const cv::Mat& previous, const cv::Mat& next);

// Flow is kept on a grid of 1/kFlowSteps px (far finer than DIS reads it), so that a cache can
// hold it in 16 bits per component and still give exactly the samples computed afresh.
constexpr double kFlowSteps = 256;

// The flow channels of a window of T frames: T - 1 flows between consecutive frames (flows[i] from
// frame i to frame i + 1), as a Sample holds them: frame t's flow is the one that arrives at it
// (flows[t - 1]) and frame 0, which has none, repeats frame 1's (the spectral layer's Hann window
// gives the first sample zero weight).
// Inputs: frames, T mono8 images of one size; crop, the square of them the sample shows; flow_side,
// the side the crop is resized to for FrameFlow; side, the sample's input size.
// Output: T - 1 side x side CV_32FC2 flows [input px per frame]: FrameFlow at flow_side, resized
// to side (area) and scaled by side / flow_side, on the 1/kFlowSteps grid.
std::vector<cv::Mat> WindowFlows(const std::vector<cv::Mat>& frames, const cv::Rect& crop, int flow_side, int side);
// The same for frames that are already the sample's squares (crop: all of them; flow_side = side).
std::vector<cv::Mat> WindowFlows(const std::vector<cv::Mat>& frames);

// Turns greyscale frames (all of one size, count = options.frames; CV_8UC3 YCrCb with
// options.colour) into a Sample: crop (random
// multi-scale position and size when augmenting, the centred square of the shorter side
// otherwise), resize to input_size (area interpolation), flip horizontally with probability
// 1/2 when augmenting (not augmenting: once for each of options.mirror_clip, a turn by
// options.flag_flies and options.mirror), and normalise the whole clip (Sample::pixels: zero mean, unit
// std for grey; one joint std for Y Cr Cb).
// With options.flow, the flow of the resized frames (WindowFlows) follows as channels 1 and 2,
// flipped with the frames (mirrored, x negated). `flows`, when given, are those T - 1 flows
// already computed (a cache's): only for frames that are already input_size squares, whose crop
// is then the whole frame.
Sample MakeSample(const std::vector<cv::Mat>& frames, const SampleOptions& options, std::mt19937_64& rng,
                  const std::vector<cv::Mat>* flows = nullptr);

// The starts of `windows` evenly spaced frame windows of `frames` frames in a clip of `num_frames`:
// the first at 0 and the last at num_frames - frames (one window: the centred one, as evaluation
// takes). Distinct and increasing: a clip with fewer than `windows` starts (num_frames - frames + 1)
// gets each of them once, so its size is min(windows, num_frames - frames + 1) (windows > 1).
// Throws std::invalid_argument for windows < 1 or a clip shorter than one window.
std::vector<int> EvenWindowStarts(int num_frames, int frames, int windows);

// Frames first..first+count-1 of a clip, from wherever they are held (LoadFrames: the files).
using FrameReader = std::function<std::vector<cv::Mat>(int first, int count)>;
// The count - 1 flows between frames first..first+count-1 (WindowFlows of those frames), from
// wherever they are held.
using FlowReader = std::function<std::vector<cv::Mat>(int first, int count)>;

// ChooseFirstFrame + `read` + MakeSample for one example, deterministic in `seed`: the window,
// crop and flip are drawn from one generator in that order, whatever supplies the frames.
// `read_flows`, when set and options.flow, supplies the window's flows (see MakeSample).
Sample LoadSample(const ClipInfo& clip, const SampleOptions& options, uint64_t seed, const FrameReader& read,
                  const FlowReader& read_flows = nullptr);

// LoadSample with the frames read from the clip's files (LoadFrames).
Sample LoadSample(const ClipInfo& clip, const SampleOptions& options, uint64_t seed);

// A synthetic dataset in the docs/dataset.md format whose content is a known function of the
// label: a textured patch ("flag") on a noisy background whose stripes travel at
// frequency f = base_frequency + frequency_per_speed · v [Hz]; v uniform in [0, max_speed].
struct ToyDatasetOptions {
  int clips = 40;
  int frames = 60;
  int size = 64;               // frames are size x size
  double frame_rate = 25;      // [Hz]
  double max_speed = 10;       // [m/s]
  double base_frequency = 1.0;        // [Hz]
  double frequency_per_speed = 0.5;   // [Hz per m/s]
  uint64_t seed = 1;
};
// Writes the dataset into `dir` (created; examples are replaced; an earlier index.json and
// examples beyond `clips` are removed first, so a stopped run leaves no index over a mix of
// runs, and the new index is written last). Splits: 60% train, 20% val,
// 20% test, by the example's seed. `progress`, when set, is called with (0, examples) first and
// (examples written, examples) after each. Returns the frequency of each example [Hz], in index order.
std::vector<double> WriteToyDataset(const std::filesystem::path& dir, const ToyDatasetOptions& options,
                                    const std::function<void(int, int)>& progress = {});

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_DATASET_H_
