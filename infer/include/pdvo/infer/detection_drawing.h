// Pictures of the plane detector at work.
#pragma once

#include <opencv2/core.hpp>

#include "pdvo/annotations/annotation.h"
#include "pdvo/infer/detector.h"

namespace pdvo {

// The stages side by side, as the paper's Fig. 3, at the detector's working size: the image; the windows' mean
// plane probability over the image; each point's planarity (red 0 to green 1) and normal (coloured as pdvo show
// colours normals); MRF 1 and 2 (non-planar points white, planar ones coloured by their orientation); the final
// planes and non-planes (`annotation`: the detections as Detections::ToAnnotation gives them for `image`).
cv::Mat DrawDetectionStages(const cv::Mat& image, const Detections& detections, const Annotation& annotation);

}  // namespace pdvo
