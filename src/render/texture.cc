#include "render/texture.h"

#include <cmath>
#include <stdexcept>

namespace clothwind::render {

Texture::Texture(int width, int height, const Rgb& fill, float alpha)
    : width_(width), height_(height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("Texture: size must be positive, got " + std::to_string(width) +
                                "x" + std::to_string(height));
  rgb_.assign(static_cast<size_t>(width) * height, fill);
  alpha_.assign(static_cast<size_t>(width) * height, alpha);
}

namespace {
inline int WrapIndex(int i, int n, Wrap wrap) {
  switch (wrap) {
    case Wrap::kClamp:
      return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case Wrap::kRepeat: {
      int m = i % n;
      return m < 0 ? m + n : m;
    }
    case Wrap::kMirror: {
      int period = 2 * n;
      int m = i % period;
      if (m < 0) m += period;
      return m < n ? m : period - 1 - m;
    }
  }
  return 0;
}

// A texel coordinate int can hold: float to int of NaN or of anything past int's range is
// undefined (x86 gives INT_MIN, so u = 1e30 clamped to the left edge instead of the right).
// Beyond 2^24 texels float has no fractional part left, so clamping there changes no lookup
// that meant anything.
inline float SafeTexelCoordinate(float x) {
  constexpr float kLimit = 16777216.0f;  // 2^24
  return x < -kLimit ? -kLimit : (x > kLimit ? kLimit : x);
}
}  // namespace

Rgb Texture::Sample(float u, float v, Wrap wrap, float* alpha_out) const {
  if (empty() || std::isnan(u) || std::isnan(v)) {
    if (alpha_out) *alpha_out = 0.0f;
    return Rgb::Zero();
  }
  const float x = SafeTexelCoordinate(u * width_ - 0.5f);
  const float y = SafeTexelCoordinate((1.0f - v) * height_ - 0.5f);
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = WrapIndex(static_cast<int>(fx), width_, wrap);
  const int x1 = WrapIndex(static_cast<int>(fx) + 1, width_, wrap);
  const int y0 = WrapIndex(static_cast<int>(fy), height_, wrap);
  const int y1 = WrapIndex(static_cast<int>(fy) + 1, height_, wrap);
  const float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
  if (alpha_out)
    *alpha_out = w00 * alpha(x0, y0) + w10 * alpha(x1, y0) + w01 * alpha(x0, y1) +
                 w11 * alpha(x1, y1);
  return w00 * at(x0, y0) + w10 * at(x1, y0) + w01 * at(x0, y1) + w11 * at(x1, y1);
}

Texture Texture::FromBgr8(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 4))
    throw std::invalid_argument("Texture::FromBgr8: expected a non-empty 8-bit BGR or BGRA image");
  Texture t(image.cols, image.rows);
  const float* lut = SrgbToLinearTable();
  const int ch = image.channels();
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      const uint8_t* p = row + ch * x;
      t.at(x, y) = Rgb(lut[p[2]], lut[p[1]], lut[p[0]]);
      t.alpha(x, y) = ch == 4 ? p[3] / 255.0f : 1.0f;
    }
  }
  return t;
}

cv::Mat Texture::ToBgr8() const {
  cv::Mat out(height_, width_, CV_8UC3);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const Rgb& c = at(x, y);
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(ToSrgb8(c[2]), ToSrgb8(c[1]), ToSrgb8(c[0]));
    }
  return out;
}

}  // namespace clothwind::render
