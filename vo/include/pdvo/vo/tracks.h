// Feature bookkeeping for the visual odometry (the paper's section IV): the keyframes (one per reference camera
// of the filter: its image and the corners found in it), and per feature in the filter how its searches have
// fared; which features are in view, and which leave: those out of view, those missed too often, and those whose
// matches the robust update rejected too often. A feature that leaves is removed from the filter, and what it
// mapped is kept (map.h). Pixels are those of the working image (undistorted), at the keyframe or the current
// frame as named.
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/vo/filter.h"

namespace pdvo::vo {

class MapRecord;

struct FeatureOptions {
  int max_measurements = 200;  // features searched for per frame, at most
  int min_features = 60;       // fewer in view: a new keyframe
  int new_features = 80;       // features initialised per keyframe, at most
  double min_distance = 12;    // px between features at initialisation
  int border = 10;             // px: features nearer the image border leave
  int max_misses = 3;          // failed searches in a row before a feature leaves
  // Points whose predictions have left the view wait, out of the measurements, to be measured again if they come
  // back; beyond this many, the oldest leave. 0: a point leaves as it leaves the view. 80 carried the scale
  // further on aliased driving streets, not on supersampled ones nor on KITTI 06; hand-held (TUM fr1) it costs
  // rotation accuracy (docs/odometry.md).
  int max_waiting = 0;
  // A feature also leaves when the robust update has rejected at least min_rejections of its matches and more
  // than max_rejected_share of them (its patch straddles a depth edge or slides on a repetition).
  int min_rejections = 3;
  double max_rejected_share = 0.4;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("max_measurements", self.max_measurements);
    visit("min_features", self.min_features);
    visit("new_features", self.new_features);
    visit("min_distance", self.min_distance);
    visit("border", self.border);
    visit("max_misses", self.max_misses);
    visit("max_waiting", self.max_waiting);
    visit("min_rejections", self.min_rejections);
    visit("max_rejected_share", self.max_rejected_share);
  }
  bool Check() const;
  bool operator==(const FeatureOptions&) const = default;
};

// True if `pixel` is at least `border` px inside an image of `size`.
bool Inside(const Eigen::Vector2d& pixel, const cv::Size& size, int border);
// 255 on the pixels at least `border` px inside, 0 elsewhere (CV_8U): where corners are looked for.
cv::Mat InsideMask(const cv::Size& size, int border);
// Corners are found by goodFeaturesToTrack with this quality level (a share of the strongest corner's score).
inline constexpr double kCornerQuality = 0.01;

// True if `pixel` lies inside `polygon` at least `margin` px from its outline.
bool InsidePolygon(const std::vector<cv::Point2f>& polygon, const Eigen::Vector2d& pixel, double margin = 0);

// A new feature's inverse-depth prior at a pixel of the current frame (1/m, in the map's scale).
struct DepthPrior {
  Eigen::Vector2d pixel;
  double inverse_depth = 0;
};

// A corner of a keyframe (goodFeaturesToTrack, strongest first); used once it has become a feature.
struct Corner {
  Eigen::Vector2d pixel;
  bool used = false;
};
struct Keyframe {
  cv::Mat grey;  // the keyframe's working image: features' patches are warped from it
  double time = 0;
  int frame = -1;  // its index in the frames tracked
  std::vector<Corner> corners;
};

// How a feature's searches have fared.
struct History {
  int misses = 0;    // failed searches in a row
  int matched = 0;   // searches that found a match
  int rejected = 0;  // matches that the robust update rejected
};
struct PointTrack {
  Eigen::Vector2d keyframe_pixel;
  History history;
};
// A plane's point: its keyframe pixel and ray (unit, reference camera frame); its depth is the plane's.
struct PlanePoint {
  Eigen::Vector2d keyframe_pixel;
  Eigen::Vector3d ray;
  History history;
};
// A point of the filter that may join a plane (plane_growing.h).
struct Candidate {
  int point = -1;
  int age = 0;  // frames since it was made
};
struct PlaneTrack {
  std::vector<PlanePoint> members;  // members[0] is the seed
  std::vector<Candidate> candidates;
  int age = 0;  // frames since the plane was made
  // A detected plane (plane_priors.h) grows from the keyframe corners inside its outline only (indices into its
  // keyframe's corners); a blind seed (detected false): from the corners within grow_radius of its members
  // (PlaneGrower, with each kind's options).
  bool detected = false;
  std::vector<int> region_corners;
  std::vector<Eigen::Vector2d> outline;  // a detected plane's polygon, keyframe pixels
  // Points that left it when it moved to a later keyframe that does not see them (plane_priors.h): mapped, they
  // count among its points as the members out of view of a plane that stays do.
  int moved_away = 0;
  // A detected plane none of whose points is in view waits, out of the measurements, for the next detection
  // (plane_priors.h): one whose normal agrees carries it on in its keyframe; else it leaves then.
  bool out_of_view = false;
};

// Planes waiting out of view, at most (the detector being slow, they would otherwise gather).
inline constexpr int kMaxOutOfViewPlanes = 4;

// The features of one filter, by the filter's ids, and the keyframes they come from. Every point and plane of
// the filter has a track here and every reference camera a keyframe; Remove* keeps it so.
struct Tracks {
  std::map<int, Keyframe> keyframes;  // by reference camera id
  std::map<int, PointTrack> points;   // by point id
  std::map<int, PlaneTrack> planes;   // by plane id

  // True if the feature's history says it leaves (max_misses, min_rejections, max_rejected_share).
  static bool Gone(const History& history, const FeatureOptions& options);
  // The predicted pixels of the features in view (points and plane points), at least `border` px inside.
  std::vector<Eigen::Vector2d> Visible(const Filter& filter, const Camera& camera, int border) const;
  int PlanePoints() const;  // points held by the planes

  // Points or a plane leave the filter; what it mapped goes to `record`, and a keyframe whose reference
  // camera has left the filter goes too.
  void RemovePoints(const std::vector<int>& ids, Filter* filter, MapRecord* record);
  void RemovePlane(int id, Filter* filter, MapRecord* record);
  // Points behind the camera leave, and points out of view (`options.border`) beyond options.max_waiting (the
  // oldest first); a plane leaves when none of its points is in view, but a detected plane that has min_plane_points
  // waits out of view (PlaneTrack::out_of_view; at most kMaxOutOfViewPlanes, the oldest leave first).
  void LeaveView(const Camera& camera, const FeatureOptions& options, Filter* filter, MapRecord* record);
  // The planes waiting out of view leave.
  void RemoveOutOfView(Filter* filter, MapRecord* record);
  // Points whose history says they leave (Gone).
  void LeaveRejected(const FeatureOptions& options, Filter* filter, MapRecord* record);
};

}  // namespace pdvo::vo
