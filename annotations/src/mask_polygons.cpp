#include "pdvo/annotations/mask_polygons.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/logging.h"

namespace pdvo {
namespace {

void FillSmallHolesAndCutLargeOnes(cv::Mat& mask, int min_hole_pixels) {
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(mask.clone(), contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  for (size_t i = 0; i < contours.size(); ++i) {
    if (hierarchy[i][3] < 0) continue;  // an outer boundary, not a hole
    // The hole's area in pixels: its contour runs through the region pixels around it.
    cv::Mat hole(mask.size(), CV_8U, cv::Scalar(0));
    cv::drawContours(hole, contours, static_cast<int>(i), cv::Scalar(255), cv::FILLED);
    hole &= ~mask;
    if (cv::countNonZero(hole) < min_hole_pixels) {
      mask |= hole;
      continue;
    }
    // A keyhole: a cut two pixels wide from the hole's top straight up, until it leaves the region.
    const auto top = std::min_element(contours[i].begin(), contours[i].end(),
                                      [](const cv::Point& a, const cv::Point& b) { return a.y < b.y; });
    const int x = std::clamp(top->x, 0, mask.cols - 2);
    for (int y = top->y; y >= 0; --y) {
      if (mask.at<uchar>(y, x) == 0 && mask.at<uchar>(y, x + 1) == 0 && y < top->y) break;
      mask.at<uchar>(y, x) = 0;
      mask.at<uchar>(y, x + 1) = 0;
    }
  }
}

}  // namespace

std::vector<std::vector<Eigen::Vector2d>> MaskToPolygons(const cv::Mat& mask_in, int min_pixels, int min_hole_pixels,
                                                         double scale, double epsilon_full_px) {
  cv::Mat mask = mask_in > 0;
  // Opening removes one-pixel necks and spurs, whose contours would touch themselves.
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  FillSmallHolesAndCutLargeOnes(mask, min_hole_pixels);
  std::vector<std::vector<Eigen::Vector2d>> polygons;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  for (const auto& contour : contours) {
    if (cv::contourArea(contour) < min_pixels) continue;
    // Try the requested tolerance, then finer ones, until the polygon does not cross itself.
    for (double eps = epsilon_full_px / scale; eps >= 0.05; eps *= 0.5) {
      std::vector<cv::Point> simple;
      cv::approxPolyDP(contour, simple, eps, true);
      std::vector<Eigen::Vector2d> polygon;
      for (const cv::Point& p : simple) polygon.emplace_back((p.x + 0.5) * scale - 0.5, (p.y + 0.5) * scale - 0.5);
      if (polygon.size() >= 3 && !PolygonSelfIntersects(polygon)) {
        polygons.push_back(std::move(polygon));
        break;
      }
    }
  }
  return polygons;
}

void AddShapesFromMasks(const std::vector<PlaneMask>& planes, const cv::Mat& nonplanar_in,
                        const MaskPolygonOptions& options, Annotation* a) {
  const cv::Size size = nonplanar_in.size();
  const double scale = static_cast<double>(a->image_width) / size.width;
  const size_t first = a->shapes.size();
  cv::Mat covered(size, CV_8U, cv::Scalar(0));
  int group = 0;  // each plane's pieces share a group_id, after any the annotation holds
  for (const AnnotationShape& s : a->shapes) group = std::max(group, s.group_id.value_or(-1) + 1);
  for (const PlaneMask& plane : planes) {
    for (auto& polygon : MaskToPolygons(plane.mask, options.min_plane_pixels, options.min_hole_pixels, scale,
                                        options.epsilon_full_px)) {
      AnnotationShape shape;
      shape.label = kPlaneLabel;
      shape.points = std::move(polygon);
      shape.normal = plane.normal;
      shape.score = plane.score;
      shape.group_id = group;
      // An estimated normal (a detector's) made to face the camera elsewhere may point away at this polygon:
      // turned just past edge-on there, rather than the plane dropped below. A true plane's always faces it.
      if (a->camera) shape.normal = NearestFacingNormal(*shape.normal, PolygonRay(shape.points, *a->camera), 0.01);
      a->shapes.push_back(std::move(shape));
      covered |= RasteriseShape(a->shapes.back(), *a, size);
    }
    ++group;
  }
  const int margin = 2 + static_cast<int>(std::ceil(2 * options.epsilon_full_px / scale));
  cv::dilate(covered, covered, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin + 1, 2 * margin + 1)));
  const cv::Mat nonplanar = (nonplanar_in > 0) & ~covered;
  for (auto& polygon : MaskToPolygons(nonplanar, options.min_nonplane_pixels, options.min_hole_pixels, scale,
                                      options.epsilon_full_px)) {
    AnnotationShape shape;
    shape.label = kNonPlaneLabel;
    shape.points = std::move(polygon);
    a->shapes.push_back(std::move(shape));
  }
  // Anything that still breaks the format's rules (it should not) is dropped rather than written.
  std::vector<bool> drop(a->shapes.size(), false);
  for (const ValidationIssue& issue : Validate(*a)) {
    if (issue.is_error && issue.shape >= static_cast<int>(first)) drop[issue.shape] = true;
  }
  std::vector<AnnotationShape> kept;
  for (size_t i = 0; i < a->shapes.size(); ++i) {
    if (!drop[i]) {
      kept.push_back(std::move(a->shapes[i]));
    } else {
      PDVO_LOG(Debug) << a->image_path << ": dropped shape " << i << " that broke the format's rules";
    }
  }
  a->shapes = std::move(kept);
}

}  // namespace pdvo
