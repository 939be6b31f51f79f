// Training and evaluation regions from annotations (the paper's section III): each annotated polygon, and
// rectangular sub-windows of it at several sizes and shapes that are pure in its label. Regions live at a working
// resolution (the annotation's image scaled); the same seed gives the same regions.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo {

struct RegionSamplingOptions {
  bool whole_shapes = true;   // each annotated polygon is a region
  int windows_per_shape = 8;  // sub-windows tried per shape (fewer if they do not fit)
  // A sub-window's size is its geometric mean side, sqrt(width x height), log-uniform between these bounds.
  int min_window = 40;               // px at the working resolution
  double max_window_fraction = 0.8;  // as a fraction of the image's smaller side
  // Its aspect ratio, width / height, is log-uniform in [1 / max_window_aspect, max_window_aspect] (1: squares).
  double max_window_aspect = 1;
  double min_shape_area = 900;  // px^2 at the working resolution: smaller shapes are skipped

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("whole_shapes", self.whole_shapes);
    visit("windows_per_shape", self.windows_per_shape);
    visit("min_window", self.min_window);
    visit("max_window_fraction", self.max_window_fraction);
    visit("max_window_aspect", self.max_window_aspect);
    visit("min_shape_area", self.min_shape_area);
  }
  bool Check() const;
  bool operator==(const RegionSamplingOptions&) const = default;
};

// The pixel a point (pixel coordinates, (0, 0) the centre of the top-left pixel) falls in.
inline cv::Point NearestPixel(const cv::Point2f& p) {
  return {static_cast<int>(std::floor(p.x + 0.5f)), static_cast<int>(std::floor(p.y + 0.5f))};
}

// An image region: a box and, for polygons, a mask of the box's size (empty: the whole box).
struct Region {
  cv::Rect box;
  cv::Mat mask;  // CV_8U, box-sized, non-zero inside; empty for a plain window

  bool Contains(const cv::Point2f& p) const;
  double Area() const;
};

struct LabelledRegion {
  Region region;
  bool planar = false;
  std::optional<Eigen::Vector3d> normal;  // planes with a normal, camera frame
  int shape = -1;                         // index of the annotated shape it came from
  bool whole_shape = false;               // the shape's own polygon, not a sub-window
};

// Regions of `annotation` at working size `size` (the image's size scaled). Shapes of unknown labels are
// skipped. Sub-window positions and sizes (log-uniform) come from `rng`.
std::vector<LabelledRegion> SampleRegions(const Annotation& annotation, cv::Size size,
                                          const RegionSamplingOptions& options, std::mt19937_64& rng);

}  // namespace pdvo
