// The odometry's health check: whether each frame's pose can be trusted (Health), from the evidence the filter has
// and, at keyframes, from the two frames' own geometry. Odometry keeps one HealthCheck per run.
#pragma once

#include <array>
#include <map>
#include <opencv2/core.hpp>
#include <set>
#include <utility>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/geometry.h"
#include "pdvo/vo/filter.h"

namespace pdvo::vo {

// How far a frame's pose can be trusted, from the evidence the filter has (FrameStats::health, HealthCheck):
//   tracked    the update used at least min_inliers matches, at least min_inlier_share of the features searched
//              for, their mean normalised innovation squared (FrameStats::nis) is at most max_nis (the camera
//              moved as the motion model allowed: a jump or a stall of the images does not), the map it
//              measured against was made from trusted poses, and, at a keyframe, its motion since the last one
//              agrees with the two frames' own geometry (max_epipolar_error);
//   uncertain  any of these fails; a keyframe made from a pose with too few inliers carries the doubt into its
//              features: frames whose measurements are mostly of those features are uncertain;
//   lost       tracking failed at this frame (lost_after frames in a row without enough matches, min_inliers and
//              min_inlier_share, or a non-finite state) and started again: a new segment.
// A segment is the frames between two starts: monocular odometry cannot relate one segment's poses to another's
// (scale and pose start afresh), so they are compared with ground truth each on its own (pdvo ate --health).
enum class Health { kTracked, kUncertain, kLost };
constexpr std::array<std::pair<Health, const char*>, 3> OptionNames(Health) {
  return {{{Health::kTracked, "tracked"}, {Health::kUncertain, "uncertain"}, {Health::kLost, "lost"}}};
}
struct HealthOptions {
  int min_inliers = 6;            // matches used in the update
  double min_inlier_share = 0.3;  // of the features searched for
  double max_nis = 2;             // their mean normalised innovation squared (2 expected of a consistent filter)
  // Degrees: at each keyframe, how far the filter's motion since the last keyframe may miss what the two frames
  // show (EpipolarDisagreement), at most.
  double max_epipolar_error = 1;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("min_inliers", self.min_inliers);
    visit("min_inlier_share", self.min_inlier_share);
    visit("max_nis", self.max_nis);
    visit("max_epipolar_error", self.max_epipolar_error);
  }
  bool Check() const;
  bool operator==(const HealthOptions&) const = default;
};

class HealthCheck {
 public:
  // `border`, `min_distance`: the corners of the two-view check (FeatureOptions).
  HealthCheck(const Camera& camera, const HealthOptions& options, int border, double min_distance)
      : camera_(camera), o_(options), border_(border), min_distance_(min_distance) {}

  // A new filter starts at the frame `grey` with the camera at `pose`: it names its references afresh.
  void Restart(const cv::Mat& grey, const Rigid3d& pose);

  // Whether the frame's update is evidence enough for its pose (min_inliers, min_inlier_share of `attempted`);
  // counts the frames in a row without (frames_without_evidence).
  bool Evidence(UpdateStatus update, int measurements, int attempted);
  int frames_without_evidence() const { return frames_without_evidence_; }

  // The frame's health after its update: `evidence` (Evidence), the matches' mean normalised innovation squared,
  // and the reference camera of each measurement used. The filter's `references` tell which doubtful keyframes
  // still have features.
  Health Judge(bool evidence, double nis, const std::vector<int>& used_references,
               const std::map<int, Filter::Reference>& references);

  // At a frame where a keyframe was due (`grey`, the camera at `pose`; `reference`: the keyframe's reference
  // camera, -1 if none was made): true if the filter's motion since the last such frame misses what the two frames
  // show by more than max_epipolar_error (EpipolarDisagreement; false when they cannot tell). The keyframe's
  // features are in doubt if it disagrees or the frame had no `evidence`.
  bool AtKeyframe(const cv::Mat& grey, const Rigid3d& pose, int reference, bool evidence);

 private:
  Camera camera_;
  HealthOptions o_;
  int border_;
  double min_distance_;
  int frames_without_evidence_ = 0;
  std::set<int> doubtful_references_;  // keyframes made from a pose in doubt, while features of theirs remain
  cv::Mat last_keyframe_;              // grey, for the two-view check of the next keyframe
  Rigid3d last_keyframe_pose_;         // its world_from_cam in the filter
};

}  // namespace pdvo::vo
