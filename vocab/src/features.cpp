#include "pdvo/vocab/features.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {

// SIFT's layout (4x4 cells x 8 orientations), upright and at one scale: the (patch+1)^2 pixels centred on the
// point vote with their Gaussian-weighted gradient magnitude into the two nearest orientation bins and the
// (bilinearly) nearest cells; the histogram is normalised, clipped at 0.2, renormalised and scaled by 512.
// `gaussian`: GaussianWeights(patch).
void DescribeGradient(const cv::Mat& magnitude, const cv::Mat& angle, cv::Point c, int patch,
                      const std::vector<float>& gaussian, float* out) {
  std::fill(out, out + kGradientDims, 0.0f);
  const int h = patch / 2;
  const float cell = patch / 4.0f;
  const float* g = gaussian.data();
  for (int dy = -h; dy <= h; ++dy) {
    const float* m = magnitude.ptr<float>(c.y + dy);
    const float* a = angle.ptr<float>(c.y + dy);
    const float fy = (dy + h) / cell - 0.5f;  // cell coordinate, cell centres at 0..3
    const int y0 = static_cast<int>(std::floor(fy));
    const float wy = fy - y0;
    for (int dx = -h; dx <= h; ++dx) {
      const float w = m[c.x + dx] * *g++;
      if (w == 0) continue;
      const float fo = a[c.x + dx] * (8.0f / static_cast<float>(2 * CV_PI));
      const int o0 = static_cast<int>(std::floor(fo));
      const float wo = fo - o0;
      const float fx = (dx + h) / cell - 0.5f;
      const int x0 = static_cast<int>(std::floor(fx));
      const float wx = fx - x0;
      for (int iy = 0; iy < 2; ++iy) {
        const int cy = y0 + iy;
        if (cy < 0 || cy > 3) continue;
        const float vy = iy ? wy : 1 - wy;
        for (int ix = 0; ix < 2; ++ix) {
          const int cx = x0 + ix;
          if (cx < 0 || cx > 3) continue;
          const float v = w * vy * (ix ? wx : 1 - wx);
          float* bins = out + (cy * 4 + cx) * 8;
          bins[o0 & 7] += v * (1 - wo);
          bins[(o0 + 1) & 7] += v * wo;
        }
      }
    }
  }
  for (int pass = 0; pass < 2; ++pass) {
    float norm = 0;
    for (int k = 0; k < kGradientDims; ++k) norm += out[k] * out[k];
    norm = std::sqrt(norm);
    if (norm <= 0) return;
    for (int k = 0; k < kGradientDims; ++k) out[k] = pass == 0 ? std::min(out[k] / norm, 0.2f) : 512.0f * out[k] / norm;
  }
}

// The Gaussian weight (sigma: half the patch) of each pixel of a (patch+1)^2 window, row by row.
std::vector<float> GaussianWeights(int patch) {
  const int h = patch / 2;
  const float sigma = static_cast<float>(h);
  std::vector<float> weights;
  for (int dy = -h; dy <= h; ++dy) {
    for (int dx = -h; dx <= h; ++dx) weights.push_back(std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)));
  }
  return weights;
}

// Mean CIE Lab (each channel / 255) of the 2x2 cells of the patch, from the image's integral.
void DescribeColour(const cv::Mat& lab_sum, cv::Point c, int patch, float* out) {
  const int h = patch / 2;
  int k = 0;
  for (int cy = 0; cy < 2; ++cy) {
    for (int cx = 0; cx < 2; ++cx) {
      const int x0 = c.x - h + cx * h, y0 = c.y - h + cy * h;  // cell [x0, x0+h) x [y0, y0+h)
      const cv::Vec3d sum = lab_sum.at<cv::Vec3d>(y0 + h, x0 + h) - lab_sum.at<cv::Vec3d>(y0, x0 + h) -
                            lab_sum.at<cv::Vec3d>(y0 + h, x0) + lab_sum.at<cv::Vec3d>(y0, x0);
      for (int ch = 0; ch < 3; ++ch) out[k++] = static_cast<float>(sum[ch] / (h * h) / 255.0);
    }
  }
}

}  // namespace

bool FeatureOptions::Check() const {
  PDVO_CHECK_OPTION(detector == "fast" || detector == "gftt" || detector == "dense");
  PDVO_CHECK_OPTION(max_points >= 1);
  PDVO_CHECK_OPTION(patch_size >= 4 && patch_size % 2 == 0);
  PDVO_CHECK_OPTION(quality > 0 && quality < 1 && min_distance >= 1);
  PDVO_CHECK_OPTION(fast_threshold >= 1 && grid_step >= 1);
  return true;
}

Features ExtractFeatures(const cv::Mat& image, const FeatureOptions& o, const cv::Mat& mask) {
  CheckOptionsOrThrow(o, "feature options");
  PDVO_THROW_CHECK(image.type() == CV_8UC3, InvalidArgument, "features: the image must be 8-bit BGR");
  PDVO_THROW_CHECK(mask.empty() || (mask.type() == CV_8U && mask.size() == image.size()), InvalidArgument,
                   "features: the mask must be 8-bit and of the image's size");
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> candidates;
  if (o.detector == "fast") {
    cv::FAST(grey, candidates, o.fast_threshold, true);
  } else if (o.detector == "gftt") {
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(grey, corners, o.max_points * 2, o.quality, o.min_distance);
    for (const auto& c : corners) candidates.emplace_back(c, static_cast<float>(o.patch_size), -1, 1.0f);
  } else {
    for (int y = o.patch_size / 2; y < grey.rows - o.patch_size / 2; y += o.grid_step) {
      for (int x = o.patch_size / 2; x < grey.cols - o.patch_size / 2; x += o.grid_step) {
        candidates.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(o.patch_size), -1,
                                1.0f);
      }
    }
  }
  // Keep points whose patch is inside the image (and the mask), strongest first, ties by position.
  // Integer centres whose (patch+1)^2 window lies inside the image.
  const int half = o.patch_size / 2;
  std::vector<cv::KeyPoint> kept;
  for (cv::KeyPoint k : candidates) {
    const int x = cvRound(k.pt.x), y = cvRound(k.pt.y);
    if (x < half || y < half || x > grey.cols - 1 - half || y > grey.rows - 1 - half) continue;
    if (!mask.empty() && !mask.at<uchar>(cvRound(k.pt.y), cvRound(k.pt.x))) continue;
    k.size = static_cast<float>(o.patch_size);
    k.angle = 0;  // upright: orientation is what the recogniser learns from
    kept.push_back(k);
  }
  std::stable_sort(kept.begin(), kept.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    if (a.response != b.response) return a.response > b.response;
    return a.pt.y != b.pt.y ? a.pt.y < b.pt.y : a.pt.x < b.pt.x;
  });
  if (static_cast<int>(kept.size()) > o.max_points) kept.resize(o.max_points);

  Features f;
  f.image_size = image.size();
  f.gradient.create(static_cast<int>(kept.size()), kGradientDims, CV_32F);
  f.colour.create(static_cast<int>(kept.size()), kColourDims, CV_32F);
  if (kept.empty()) return f;
  cv::Mat gx, gy, magnitude, angle;
  cv::Sobel(grey, gx, CV_32F, 1, 0, 1);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 1);
  cv::cartToPolar(gx, gy, magnitude, angle);
  // Structure tensor sums over each point's window, from integral images of gx^2, gy^2 and gx gy.
  cv::Mat tensor_sum;
  {
    std::vector<cv::Mat> products = {gx.mul(gx), gy.mul(gy), gx.mul(gy)};
    cv::Mat stacked;
    cv::merge(products, stacked);
    cv::integral(stacked, tensor_sum, CV_64F);
  }
  cv::Mat lab, lab_sum;
  cv::cvtColor(image, lab, cv::COLOR_BGR2Lab);
  cv::integral(lab, lab_sum, CV_64F);
  const std::vector<float> gaussian = GaussianWeights(o.patch_size);
  for (size_t i = 0; i < kept.size(); ++i) {
    const cv::Point c(cvRound(kept[i].pt.x), cvRound(kept[i].pt.y));
    f.points.emplace_back(static_cast<float>(c.x), static_cast<float>(c.y));
    DescribeGradient(magnitude, angle, c, o.patch_size, gaussian, f.gradient.ptr<float>(static_cast<int>(i)));
    DescribeColour(lab_sum, c, o.patch_size, f.colour.ptr<float>(static_cast<int>(i)));
    const int x0 = c.x - half, y0 = c.y - half, x1 = c.x + half + 1, y1 = c.y + half + 1;  // the window
    const cv::Vec3d t = tensor_sum.at<cv::Vec3d>(y1, x1) - tensor_sum.at<cv::Vec3d>(y0, x1) -
                        tensor_sum.at<cv::Vec3d>(y1, x0) + tensor_sum.at<cv::Vec3d>(y0, x0);
    double theta = 0.5 * std::atan2(2 * t[2], t[0] - t[1]);  // (-pi/2, pi/2]
    if (theta < 0) theta += CV_PI;
    f.orientation.push_back(static_cast<float>(std::min(theta, CV_PI - 1e-9)));
    const double energy = t[0] + t[1];
    f.coherence.push_back(energy > 0 ? static_cast<float>(std::hypot(t[0] - t[1], 2 * t[2]) / energy) : 0.0f);
  }
  return f;
}

}  // namespace pdvo
