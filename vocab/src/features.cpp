#include "pdvo/vocab/features.h"

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {

bool FeatureOptions::Check() const {
  PDVO_CHECK_OPTION(detector == "fast" || detector == "gftt" || detector == "dense");
  PDVO_CHECK_OPTION(max_points >= 1);
  PDVO_CHECK_OPTION(patch_size >= 4 && patch_size % 2 == 0);
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
    cv::goodFeaturesToTrack(grey, corners, o.max_points * 2, 0.01, o.patch_size / 4.0);
    for (const auto& c : corners) candidates.emplace_back(c, static_cast<float>(o.patch_size), -1, 1.0f);
  } else {
    for (int y = o.patch_size / 2; y < grey.rows - o.patch_size / 2; y += o.grid_step) {
      for (int x = o.patch_size / 2; x < grey.cols - o.patch_size / 2; x += o.grid_step) {
        candidates.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(o.patch_size), -1, 1.0f);
      }
    }
  }
  // Keep points whose patch is inside the image (and the mask), strongest first, ties by position.
  const float half = o.patch_size / 2.0f;
  std::vector<cv::KeyPoint> kept;
  for (cv::KeyPoint k : candidates) {
    if (k.pt.x < half || k.pt.y < half || k.pt.x > grey.cols - 1 - half || k.pt.y > grey.rows - 1 - half) continue;
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
  if (kept.empty()) {
    f.gradient.create(0, kGradientDims, CV_32F);
    f.colour.create(0, kColourDims, CV_32F);
    return f;
  }
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  std::vector<cv::KeyPoint> described = kept;
  sift->compute(grey, described, f.gradient);
  PDVO_THROW_CHECK(described.size() == kept.size(), Error, "features: SIFT dropped points");
  cv::Mat lab;
  cv::cvtColor(image, lab, cv::COLOR_BGR2Lab);
  f.colour.create(static_cast<int>(kept.size()), kColourDims, CV_32F);
  const int h = o.patch_size / 2;
  for (size_t i = 0; i < kept.size(); ++i) {
    const cv::Point c(cvRound(kept[i].pt.x), cvRound(kept[i].pt.y));
    f.points.push_back(kept[i].pt);
    int k = 0;
    for (int cy = 0; cy < 2; ++cy) {
      for (int cx = 0; cx < 2; ++cx) {
        const cv::Rect cell(c.x - h + cx * h, c.y - h + cy * h, h, h);
        const cv::Scalar mean = cv::mean(lab(cell & cv::Rect(0, 0, lab.cols, lab.rows)));
        for (int ch = 0; ch < 3; ++ch) f.colour.at<float>(static_cast<int>(i), k++) = static_cast<float>(mean[ch] / 255.0);
      }
    }
  }
  return f;
}

}  // namespace pdvo
