// From pixel masks to annotation polygons: shared by annotation from depth and the synthetic street.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo {

// Polygons (full-resolution pixel coordinates) of the connected regions of `mask` larger than `min_pixels`:
// holes larger than `min_hole_pixels` are cut out with keyholes, smaller ones filled. `mask` may be at a
// lower resolution than the image; `scale` = image width / mask width. `epsilon_full_px` is the
// Douglas-Peucker tolerance; it is refined where needed so that no polygon crosses itself.
std::vector<std::vector<Eigen::Vector2d>> MaskToPolygons(const cv::Mat& mask, int min_pixels, int min_hole_pixels,
                                                         double scale, double epsilon_full_px);

// A plane's pixels (CV_8U, non-zero on the plane) and its normal in the camera frame, towards the camera.
struct PlaneMask {
  cv::Mat mask;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  std::optional<double> score;  // a detector's confidence, given to the plane's shapes
};

struct MaskPolygonOptions {
  int min_plane_pixels = 0;     // at mask resolution
  int min_nonplane_pixels = 0;  // at mask resolution
  int min_hole_pixels = 0;      // at mask resolution
  double epsilon_full_px = 1.0;
};

// Appends `plane` shapes for the planes and `non-plane` shapes for `nonplanar` (CV_8U) to `annotation`, whose
// image size must be set. Non-planes keep a margin from the planes' polygons, so that no region of one label
// overlaps the other. With the annotation's camera, a plane's normal that points away from the camera at its
// polygon (PolygonRay) is turned to the nearest one that faces it, rather than the plane dropped. A plane's
// polygons share a group_id (LabelMe's: the pieces of one plane), one per plane after those already there. A shape that
// would still break the format's rules is dropped.
void AddShapesFromMasks(const std::vector<PlaneMask>& planes, const cv::Mat& nonplanar,
                        const MaskPolygonOptions& options, Annotation* annotation);

}  // namespace pdvo
