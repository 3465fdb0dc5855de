// Test helper: a clip's frames mirrored left to right, as a camera on the other side of the flag
// would see them (the fly direction's cues and the fly judge must both change sign under it).
#ifndef CLOTHWIND_LEARN_TEST_MIRRORED_FRAMES_H_
#define CLOTHWIND_LEARN_TEST_MIRRORED_FRAMES_H_

#include <vector>

#include <opencv2/core.hpp>

namespace clothwind::learn {

// Inputs: frames  any number of images of any type. Returns each frame flipped about its vertical
// axis (cv::flip code 1), in the same order; the inputs are not changed.
inline std::vector<cv::Mat> Mirrored(const std::vector<cv::Mat>& frames) {
  std::vector<cv::Mat> out;
  for (const cv::Mat& f : frames) {
    cv::Mat m;
    cv::flip(f, m, 1);
    out.push_back(m);
  }
  return out;
}

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TEST_MIRRORED_FRAMES_H_
