#ifndef CLOTHWIND_RENDER_TEXTURE_H_
#define CLOTHWIND_RENDER_TEXTURE_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "render/color.h"

namespace clothwind::render {

// How a lookup outside [0,1] is answered.
enum class Wrap { kClamp, kRepeat, kMirror };

// A linear-RGB + alpha image with bilinear lookup by texture coordinates.
//
// Convention (also the cloth's UV convention): u runs left to right across the image
// (u = 0 is the flag's hoist, u = 1 its fly end), v runs bottom to top (v = 1 is the top edge);
// texel (x, y) with y = 0 the top row covers u in [x/W, (x+1)/W], v in [1-(y+1)/H, 1-y/H].
class Texture {
 public:
  Texture() = default;
  // Inputs: width, height  size in texels (> 0); fill  initial linear colour; alpha in [0,1].
  Texture(int width, int height, const Rgb& fill = Rgb::Zero(), float alpha = 1.0f);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0; }

  // Texel access; (x, y) with y = 0 the top row.
  Rgb& at(int x, int y) { return rgb_[static_cast<size_t>(y) * width_ + x]; }
  const Rgb& at(int x, int y) const { return rgb_[static_cast<size_t>(y) * width_ + x]; }
  float& alpha(int x, int y) { return alpha_[static_cast<size_t>(y) * width_ + x]; }
  float alpha(int x, int y) const { return alpha_[static_cast<size_t>(y) * width_ + x]; }

  // Bilinear lookup.
  // Inputs: u, v  texture coordinates, any float (infinite ones clamp to +-2^24 texels);
  //   wrap  behaviour outside [0,1].
  // Outputs: alpha_out  (optional) interpolated alpha.
  // Returns the interpolated linear colour; zero (and alpha 0) if u or v is NaN.
  Rgb Sample(float u, float v, Wrap wrap = Wrap::kClamp, float* alpha_out = nullptr) const;

  // From an 8-bit BGR or BGRA OpenCV image (sRGB encoded, as cv::imread gives it).
  static Texture FromBgr8(const cv::Mat& image);
  // To an 8-bit BGR sRGB image (alpha dropped), e.g. to look at a texture.
  cv::Mat ToBgr8() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<Rgb> rgb_;
  std::vector<float> alpha_;
};

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_TEXTURE_H_
