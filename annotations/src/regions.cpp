#include "pdvo/annotations/regions.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {

bool RegionSamplingOptions::Check() const {
  PDVO_CHECK_OPTION(windows_per_shape >= 0);
  PDVO_CHECK_OPTION(min_window >= 8);
  PDVO_CHECK_OPTION(max_window_fraction > 0 && max_window_fraction <= 1);
  PDVO_CHECK_OPTION(max_window_aspect >= 1 && max_window_aspect <= 100);
  PDVO_CHECK_OPTION(min_shape_area >= 0);
  PDVO_CHECK_OPTION(whole_shapes || windows_per_shape > 0);
  return true;
}

bool Region::Contains(const cv::Point2f& p) const {
  const cv::Point q = NearestPixel(p);
  const int x = q.x - box.x, y = q.y - box.y;
  if (x < 0 || y < 0 || x >= box.width || y >= box.height) return false;
  return mask.empty() || mask.at<uchar>(y, x) != 0;
}

double Region::Area() const { return mask.empty() ? box.area() : cv::countNonZero(mask); }

std::vector<LabelledRegion> SampleRegions(const Annotation& a, cv::Size size, const RegionSamplingOptions& o,
                                          std::mt19937_64& rng) {
  CheckOptionsOrThrow(o, "region sampling options");
  PDVO_THROW_CHECK(size.width > 0 && size.height > 0, InvalidArgument, "regions: empty working size");
  std::vector<LabelledRegion> out;
  const int largest_side = static_cast<int>(o.max_window_fraction * std::min(size.width, size.height));
  for (size_t s = 0; s < a.shapes.size(); ++s) {
    const AnnotationShape& shape = a.shapes[s];
    if (!shape.IsPlane() && !shape.IsNonPlane()) continue;
    const cv::Mat mask = RasteriseShape(shape, a, size);
    const int area = cv::countNonZero(mask);
    if (area == 0 || area < o.min_shape_area) continue;
    LabelledRegion base;
    base.planar = shape.IsPlane();
    base.normal = shape.normal;
    base.shape = static_cast<int>(s);
    const cv::Rect box = cv::boundingRect(mask);
    if (o.whole_shapes) {
      LabelledRegion r = base;
      r.region = Region{box, mask(box).clone()};
      r.whole_shape = true;
      out.push_back(std::move(r));
    }
    // The largest size that fits the box at some allowed aspect ratio.
    const double fitting = std::min(
        {std::sqrt(o.max_window_aspect) * std::min(box.width, box.height), std::sqrt(static_cast<double>(box.area()))});
    const int largest = static_cast<int>(std::min<double>(largest_side, fitting));
    if (o.windows_per_shape == 0 || largest < o.min_window) continue;
    cv::Mat inside;  // integral image of the shape's pixels: a window is pure if it counts its own area
    cv::integral(mask / 255, inside, CV_32S);
    std::uniform_real_distribution<double> log_side(std::log(o.min_window), std::log(largest + 1.0));
    std::uniform_real_distribution<double> log_aspect(-std::log(o.max_window_aspect), std::log(o.max_window_aspect));
    int found = 0;
    for (int attempt = 0; attempt < 20 * o.windows_per_shape && found < o.windows_per_shape; ++attempt) {
      const double side = std::min<double>(largest, std::exp(log_side(rng)));
      // Squares draw no aspect ratio, so that they are the same windows as before there were rectangles.
      const double stretch = o.max_window_aspect > 1 ? std::exp(0.5 * log_aspect(rng)) : 1.0;
      const int width = static_cast<int>(side * stretch), height = static_cast<int>(side / stretch);
      if (width > box.width || height > box.height) continue;
      const int x = box.x + std::uniform_int_distribution<int>(0, box.width - width)(rng);
      const int y = box.y + std::uniform_int_distribution<int>(0, box.height - height)(rng);
      const int count = inside.at<int>(y + height, x + width) - inside.at<int>(y, x + width) -
                        inside.at<int>(y + height, x) + inside.at<int>(y, x);
      if (count != width * height) continue;
      LabelledRegion r = base;
      r.region = Region{cv::Rect(x, y, width, height), cv::Mat()};
      out.push_back(std::move(r));
      ++found;
    }
  }
  return out;
}

}  // namespace pdvo
