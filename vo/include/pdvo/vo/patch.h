// Patch prediction and comparison for the EKF's measurements: a keyframe patch is warped into the current
// view by its plane's homography (a point's by the fronto-parallel plane through it), then compared by
// zero-mean normalised cross-correlation.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace pdvo::vo {

// The (2 half + 1)^2 patch of the current view centred on `centre` (current pixels), predicted from the
// reference image: its pixel centre + d is the reference image's value at H^-1 (centre + d), bilinear.
// `reference` is 8-bit grey; `patch` becomes CV_32F. False (and `patch` untouched) when any sample falls
// outside the reference image or H is singular.
bool WarpPatch(const cv::Mat& reference, const Eigen::Matrix3d& reference_to_current, const Eigen::Vector2d& centre,
               int half, cv::Mat* patch);

// Zero-mean normalised cross-correlation of two patches of the same size (any single-channel depth), in
// [-1, 1]; 0 when either is flat.
double Ncc(const cv::Mat& a, const cv::Mat& b);

}  // namespace pdvo::vo
