// The two-view bootstrap. A monocular filter started at rest has to find the speed and the depths together, and
// while its velocity prior holds the speed near zero the map takes a scale that then drifts. So the corners of
// the first frame are tracked (pyramidal Lucas-Kanade) while the filter runs; once an essential matrix between
// the first frame and the current one has enough inliers, seen under a median parallax of at least `parallax`
// degrees, the odometry starts again at the current frame with that motion's mean velocity and the triangulated
// corners' depths as its features' priors, at the scale that puts their median distance at 1 / the prior inverse
// depth; the poses of the frames in between are replaced by those that fit the triangulated corners (PnP).
// Without enough parallax after `frames` frames (a camera that only turns) it gives up and the filter goes on.
// Nearly pure forward motion can give one frame an essential matrix of sideways motion and a turn, which shows
// more parallax than the true one and so passes the test where the true one does not: the motion must also agree
// with the one found a frame before (its direction within kMaxDirectionChange). The rotation is the filter's, not
// the essential matrix's: the filter finds rotation from bearings alone, while two views of a camera that turns
// far more than its baseline shows confound the turn with sideways motion (on streets round a block the essential
// matrix's turn was off by 1.7 degrees on average, up to 7.6, the filter's by 0.55; the filter then held on to the
// wrong turn rate: docs/experiments/2026-12-07-bootstrap-rotation.md). Known weakness (docs): the frame-to-frame
// tracks drift, which adds parallax, so far corners come out too near.
//
// Pixels are those of the working camera (undistorted); the first camera's frame is x right, y down, z forward.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/geometry.h"
#include "pdvo/vo/motion.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {

struct BootstrapOptions {
  int frames = 90;              // frames it may take (0: no bootstrap)
  double parallax = 1.5;        // degrees: the median parallax of the inliers it needs
  double velocity_sigma = 0.2;  // the velocity's standard deviation after it, as a share of the speed it found

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("frames", self.frames);
    visit("parallax", self.parallax);
    visit("velocity_sigma", self.velocity_sigma);
  }
  bool Check() const;
  bool operator==(const BootstrapOptions&) const = default;
};

// Corners the bootstrap tracks from the first frame, and the inliers it needs (also at least half the tracks).
inline constexpr int kBootstrapCorners = 200;
inline constexpr size_t kBootstrapInliers = 30;

// Degrees: how far the direction of motion the bootstrap finds may turn from the previous frame's.
inline constexpr double kMaxDirectionChange = 10;

// The relative motion of two views and the triangulated inliers, in the first view's frame.
struct TwoViewMotion {
  // An essential matrix with at least kBootstrapInliers inliers: first_from_second is set, even if refused.
  bool found = false;
  Rigid3d first_from_second;
  std::vector<int> inliers;             // indices into the correspondences
  std::vector<Eigen::Vector3d> points;  // per inlier, first view's frame, in the scale of `inverse_depth`
};

// The essential matrix between corresponding pixels `first` and `second` (RANSAC, 1 px), its motion and the
// triangulated inliers (in front of both views), scaled so that their median distance from the second view is
// 1 / inverse_depth; false if fewer than kBootstrapInliers (or fewer than half) are inliers, if their median
// parallax is under `parallax_deg`, or if a pure rotation would leave them under half of that (a turn in front of
// a near wall is not a translation). Refused for too few inliers in share or too little parallax, the motion is
// still `found`, with a unit translation. With `given_rotation` (first_from_second's) the essential matrix's
// rotation is replaced by it and only the direction of motion is fitted to the inliers.
bool EstimateTwoView(const Camera& camera, const std::vector<cv::Point2f>& first,
                     const std::vector<cv::Point2f>& second, double parallax_deg, double inverse_depth,
                     TwoViewMotion* motion, const std::optional<Eigen::Quaterniond>& given_rotation = std::nullopt);

// How far the motion `first_from_second` (the filter's between two keyframes; the length of its translation does
// not matter) is from what the frames themselves show, as a check of the filter: corners of `first` (at least
// `border` px inside, `min_distance` px apart) tracked into `second` (8-bit grey; pyramidal Lucas-Kanade), those
// that fit an essential matrix kept, and the median angle (degrees) by which their bearings in `second` miss the
// epipolar planes of the motion (without translation: the rotated bearings of `first`). Nothing when the tracks
// cannot tell: fewer than kBootstrapInliers of them fit (or fewer than half).
std::optional<double> EpipolarDisagreement(const Camera& camera, const cv::Mat& first, const cv::Mat& second,
                                           const Rigid3d& first_from_second, int border, double min_distance);

// What a successful bootstrap gives the odometry.
struct BootstrapStart {
  CameraState camera;               // at the current frame: pose, and the mean velocities since the first
  std::vector<DepthPrior> corners;  // the inliers in the current frame, with their inverse depths
  std::vector<std::pair<size_t, Rigid3d>> revised;  // (index given to Begin + k, world_from_cam) in between
};

class TwoViewBootstrap {
 public:
  // `border`: tracks nearer the image border are dropped; `min_distance` (px) between the first frame's corners;
  // `inverse_depth` (1/m): the scale of the result (the median corner's inverse distance).
  TwoViewBootstrap(const Camera& camera, const BootstrapOptions& options, int border, double min_distance,
                   double inverse_depth);

  // Arms the bootstrap at a first frame (8-bit grey, the camera's size) whose camera is `first` and whose index
  // in the odometry's trajectory is `index`; it stays off if it finds too few corners or options.frames is 0.
  void Begin(const cv::Mat& grey, double timestamp, size_t index, const CameraState& first);
  bool active() const { return active_; }
  // Tracks the corners into the next frame. The start when the two views suffice (the bootstrap is then off);
  // nothing while it waits, or once it has given up (too few tracks left, or more than options.frames frames).
  // `orientation`: the filter's world_from_cam rotation at this frame (the motion's rotation is taken from it).
  std::optional<BootstrapStart> Step(const cv::Mat& grey, double timestamp, const Eigen::Quaterniond& orientation);

 private:
  void Stop();

  Camera camera_;
  BootstrapOptions o_;
  int border_;
  double min_distance_, inverse_depth_;
  bool active_ = false;
  double time_ = 0;                                // of the first frame
  size_t index_ = 0;                               // of the first frame
  CameraState first_;                              // the camera at the first frame
  cv::Mat previous_;                               // the last frame
  std::vector<std::vector<cv::Point2f>> tracks_;   // per frame since the first, the corners still tracked
  std::optional<Eigen::Vector3d> last_direction_;  // of the motion found a frame before (unit, first frame)
};

}  // namespace pdvo::vo
