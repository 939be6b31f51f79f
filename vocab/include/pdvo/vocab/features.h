// Salient points and their descriptors (the paper's section III, steps 1-2): a gradient descriptor (SIFT's
// 4x4 cells x 8 orientations, 128-D, upright and at one scale: OpenCV's SIFT builds a scale pyramid per image
// and takes about 5x longer, see bench/recogniser_bench) and a colour descriptor (mean CIE Lab in the 2x2
// cells of the point's patch, 12-D), for every point of an image or of a region. Points are integer pixels.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace pdvo {

struct FeatureOptions {
  // Salient points: gftt (Shi-Tomasi), fast or dense (a grid).
  std::string detector = "gftt";
  int max_points = 1500;    // per image, strongest first
  int patch_size = 16;      // px, the patch described around each point
  double quality = 0.01;    // gftt: corners whose score is at least this share of the image's strongest
  double min_distance = 4;  // px, gftt: the least distance between two points
  int fast_threshold = 15;  // FAST intensity threshold
  int grid_step = 8;        // px, dense detector spacing

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("detector", self.detector);
    visit("max_points", self.max_points);
    visit("patch_size", self.patch_size);
    visit("quality", self.quality);
    visit("min_distance", self.min_distance);
    visit("fast_threshold", self.fast_threshold);
    visit("grid_step", self.grid_step);
  }
  bool Check() const;
  bool operator==(const FeatureOptions&) const = default;
};

inline constexpr int kGradientDims = 128;
inline constexpr int kColourDims = 12;

struct Features {
  std::vector<cv::Point2f> points;  // pixels
  cv::Mat gradient;                 // N x 128, CV_32F
  cv::Mat colour;                   // N x 12, CV_32F
  std::vector<float> orientation;   // radians in [0, pi): the patch's dominant gradient direction (structure tensor)
  std::vector<float> coherence;     // in [0, 1]: how much of the patch's gradient energy lies along that direction
  cv::Size image_size;              // of the described image
  size_t size() const { return points.size(); }
};

// Points whose whole (patch+1)^2 window lies inside the image (and inside `mask` where it is non-zero, if given).
// `image` is 8-bit BGR. Throws InvalidArgument for another type or bad options.
Features ExtractFeatures(const cv::Mat& image, const FeatureOptions& options, const cv::Mat& mask = cv::Mat());

}  // namespace pdvo
