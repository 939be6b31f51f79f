// Detections as annotations (the project's format, ../shared/ANNOTATIONS.md) and as the odometry's planes.
#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/mask_polygons.h"
#include "pdvo/infer/detector.h"  // Detections

namespace pdvo {

Annotation Detections::ToAnnotation(const std::string& image_path, int width, int height,
                                    const std::optional<Camera>& camera) const {
  Annotation a;
  a.image_path = image_path;
  a.image_width = width;
  a.image_height = height;
  if (camera) a.camera = camera->Undistorted();
  std::vector<PlaneMask> planes;
  cv::Mat nonplanar(image_size, CV_8U, cv::Scalar(0));
  for (const DetectedSegment& s : segments) {
    if (s.planar) {
      planes.push_back({s.mask, s.normal, s.score});
    } else {
      nonplanar |= s.mask;
    }
  }
  MaskPolygonOptions polygons;
  polygons.min_plane_pixels = polygons.min_nonplane_pixels = 64;  // working px
  polygons.min_hole_pixels = 32;
  polygons.epsilon_full_px = 1.5 * width / std::max(1, image_size.width);
  AddShapesFromMasks(planes, nonplanar, polygons, &a);
  return a;
}

std::vector<DetectedPlane> Detections::Planes(int width, int height) const {
  std::vector<DetectedPlane> planes = DetectedPlanes(ToAnnotation("", width, height), width);
  const double to_image = static_cast<double>(width) / std::max(1, image_size.width);
  for (DetectedPlane& p : planes) {
    std::vector<cv::Point2f> contour;
    for (const Eigen::Vector2d& q : p.polygon) contour.emplace_back(q.x(), q.y());
    for (size_t i = 0; i < points.size(); ++i) {
      const cv::Point2f q(points[i].x * to_image, points[i].y * to_image);
      if (plane_label[i] == 1 && cv::pointPolygonTest(contour, q, false) >= 0) p.points.emplace_back(q.x, q.y);
    }
  }
  return planes;
}

}  // namespace pdvo
