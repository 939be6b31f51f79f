// Rasterising annotations to label / shape / normal masks, and drawing them over their image.
//
// Masks may be made at any size: points are scaled so that pixel centres map to pixel centres. Where shapes
// overlap, the later shape in the file wins. Unknown labels are skipped.
#pragma once

#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo {

enum MaskLabel : uint8_t { kMaskUnknown = 0, kMaskPlane = 1, kMaskNonPlane = 2 };

struct AnnotationMasks {
  cv::Mat label;        // CV_8U, MaskLabel per pixel
  cv::Mat shape_index;  // CV_32S, index of the covering shape, -1 where none
  cv::Mat normal;       // CV_32FC3, the unit normal of the covering plane, 0 where none
};

// Masks at `size` (the annotation's image size if empty).
AnnotationMasks Rasterise(const Annotation& annotation, cv::Size size = {});
// CV_8U mask (255 inside) of one shape at `size`, for an image of the annotation's size.
cv::Mat RasteriseShape(const AnnotationShape& shape, const Annotation& annotation, cv::Size size = {});

// Pairs (i, j) of a plane and a non-plane whose interiors overlap (shared edges do not count).
std::vector<std::pair<int, int>> FindLabelConflicts(const Annotation& annotation);

// Colour (BGR) of a unit normal: x, y, z in [-1, 1] map to red, green, blue in [0, 255].
cv::Scalar NormalColour(const Eigen::Vector3d& normal);

struct OverlayOptions {
  int max_width = 1280;  // pixels; larger images are scaled down
  double alpha = 0.5;    // tint opacity
  bool legend = true;    // a panel on the right explaining colours
};

// The image with planes tinted by their normal (an arrow at each plane's centre shows it), non-planes
// hatched, unknown pixels untouched, and a legend. `image` is 8-bit grey or BGR of the annotation's size.
cv::Mat DrawOverlay(const cv::Mat& image, const Annotation& annotation, const OverlayOptions& options = {});

}  // namespace pdvo
