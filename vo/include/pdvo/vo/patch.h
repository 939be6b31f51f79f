// Patch measurement for the EKF (the paper's section IV): a keyframe patch is warped into the current view by
// its plane's homography (a point's by the fronto-parallel plane through it), then searched for by zero-mean
// normalised cross-correlation inside the ellipse of the prediction's innovation covariance, and the best
// score is refined to sub-pixel. Pixels are those of the undistorted working image, (0, 0) the centre of the
// top-left pixel.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace pdvo::vo {

struct SearchOptions {
  int patch_half = 5;          // px: patches are (2 patch_half + 1)^2 px
  double search_sigmas = 3;    // search inside this Mahalanobis radius of the prediction
  int max_search_radius = 15;  // px, however uncertain the prediction
  double min_ncc = 0.8;        // a match needs at least this correlation
  double pixel_sigma = 0.5;    // px: a match's measurement noise (standard deviation)

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("patch_half", self.patch_half);
    visit("search_sigmas", self.search_sigmas);
    visit("max_search_radius", self.max_search_radius);
    visit("min_ncc", self.min_ncc);
    visit("pixel_sigma", self.pixel_sigma);
  }
  bool Check() const;
  bool operator==(const SearchOptions&) const = default;
};

// The (2 half + 1)^2 patch of the current view centred on `centre` (current pixels), predicted from the
// reference image: its pixel centre + d is the reference image's value at H^-1 (centre + d), bilinear.
// `reference` is 8-bit grey; `patch` becomes CV_32F. False (and `patch` untouched) when any sample falls
// outside the reference image or H is singular.
bool WarpPatch(const cv::Mat& reference, const Eigen::Matrix3d& reference_to_current, const Eigen::Vector2d& centre,
               int half, cv::Mat* patch);

// Zero-mean normalised cross-correlation of two patches of the same size (any single-channel depth), in
// [-1, 1]; 0 when either is flat.
double Ncc(const cv::Mat& a, const cv::Mat& b);

// Searches 8-bit grey `image` for `patch` (CV_32F, (2 patch_half + 1)^2, e.g. from WarpPatch): the pixel
// inside the ellipse d^T S^-1 d <= search_sigmas^2 around `predicted` (also within max_search_radius px on
// each axis) whose NCC is highest, refined per axis by a parabola through the scores of its neighbours
// (at most half a pixel). `innovation` is S (px^2), the covariance of the predicted pixel plus the pixel noise.
// Only the positions inside the ellipse are scored, by direct sums (the same scores as OpenCV's matchTemplate
// with TM_CCOEFF_NORMED, to float rounding; on the streets 62-65 of a window's 133-145 positions). False if no score
// in the ellipse reaches min_ncc, the patch is flat, or the search window leaves no room for the patch.
bool SearchPatch(const cv::Mat& image, const cv::Mat& patch, const Eigen::Vector2d& predicted,
                 const Eigen::Matrix2d& innovation, const SearchOptions& options, Eigen::Vector2d* found);

}  // namespace pdvo::vo
