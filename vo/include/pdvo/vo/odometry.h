// The visual odometry's per-frame loop (the paper's section IV), over the EKF of filter.h: predict; predict
// each feature's pixel and innovation covariance; warp its keyframe patch into the current view by its
// plane's homography (a point's: fronto-parallel); search by NCC inside the innovation ellipse; refine to
// sub-pixel; reject outliers by 1-point RANSAC; batched updates. Features that leave the view leave the filter; when too few are visible, a
// keyframe is made and new points are initialised at its strongest corners. If tracking fails (no measurement
// for several frames, or a non-finite state) it says so in the statistics and starts again from the last pose.
//
// Planes (mode idpp): at each keyframe, where corners are densest, planes are seeded at a corner, facing the
// camera; each frame every plane takes a candidate point (new_plane_points) from its keyframe's corners near
// its members (at least 12 px apart), each an inverse-depth point of its own until its depth is known: it joins
// the plane if that depth agrees with the plane's (the 3D consistency test), and what it knows is fused into
// the plane (Filter::MergePointIntoPlane); a plane with fewer than 4 points after 10 frames becomes a point
// (one that had reached 4 stays in the record, MappingStats, but not in the map); planes that leave the view
// leave the filter and are kept in the record and the map.
#pragma once

#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "pdvo/common/options.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/vo/filter.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {

struct VoOptions {
  // idpp: points and planes; points: points only (the default, as `pdvo vo` asks for planes with --mode idpp;
  // with fixed reference cameras idpp is the more accurate on synthetic streets, README.md).
  std::string mode = "points";
  int working_width = 320;          // px; frames are resized to this width
  int patch_half = 5;               // patches are (2 half + 1)^2 px
  double search_sigmas = 3;         // search inside this Mahalanobis radius of the prediction
  int max_search_radius = 15;       // px, however uncertain the prediction
  double min_ncc = 0.8;             // a match needs at least this correlation
  double pixel_sigma = 0.5;         // px, measurement noise
  int max_measurements = 200;       // per frame
  int min_features = 20;            // fewer visible: a new keyframe
  int new_features = 25;            // points initialised per keyframe, at most
  double min_distance = 12;         // px between features at initialisation
  int border = 10;                  // px: features nearer the image border leave
  int max_misses = 3;               // consecutive failed searches before a feature leaves
  // A feature also leaves when RANSAC has rejected at least min_rejections of its matches and more than this
  // share of them. On synthetic streets half the matches straddle a depth edge (errors 1 px median, biased);
  // the rest are good to 0.32 px median, hence pixel_sigma and ransac_threshold.
  int min_rejections = 3;
  double max_rejected_share = 0.4;
  int ransac_hypotheses = 30;       // 1-point RANSAC over the matches
  double ransac_threshold = 1.0;    // px: a match agrees with a hypothesis within this distance
  // New points' prior: at the first keyframe this; later that of the converged point nearest in the image,
  // with the same relative uncertainty (monocular: the map's scale is its own).
  double initial_inverse_depth = 0.2;        // 1/m
  double initial_inverse_depth_sigma = 0.2;  // 1/m
  // The start is at rest. With a loose velocity prior as well as loose depths the scale is barely pinned and
  // the first frames can settle on a wrong direction of motion (measured on synthetic streets with exact
  // measurements): the velocity prior is tight and the acceleration noise lets it grow.
  double initial_velocity_sigma = 0.1;       // m/s
  // The angular velocity's standard deviation at each start and at the bootstrap (whose two-view rotation it
  // then keeps). A hand-held or walking camera turns at a few tenths of a radian per second; much looser (it
  // was 4 rad/s) lets the filter trade rotation for translation after a slightly wrong start (seed 69).
  double initial_angular_velocity_sigma = 0.5;  // rad/s
  // The two-view bootstrap (odometry.cpp): frames it may take (0: none), the median parallax it needs, and
  // the velocity's standard deviation after it, as a share of the speed it found.
  int bootstrap_frames = 90;
  double bootstrap_parallax = 1.5;           // degrees
  double bootstrap_velocity_sigma = 0.2;
  // Keyframes' poses as exact once made (Filter::AddReference). Tracked in the state with the camera's
  // uncertainty and correlations, measurement updates move the reference cameras together with the camera
  // (spurious information along directions a monocular camera cannot observe, a known inconsistency of EKF
  // SLAM): on synthetic streets with exact matches the whole map slid forwards at up to twice the camera's
  // estimated speed for hundreds of frames. Fixed, drift enters only when a keyframe is made, as in keyframe
  // VO; the camera's covariance is then relative to its keyframes (README.md: figures for both).
  bool fixed_references = true;
  double linear_acceleration = 0.25;         // m/s^2, process noise
  double angular_acceleration = 4.0;         // rad/s^2, process noise
  int lost_after = 5;               // frames without any measurement before starting again
  // Planes (mode idpp).
  int max_new_planes = 3;           // seeded per keyframe
  double grow_radius = 40;          // px in the keyframe: candidates this near a member; seeds twice apart
  int new_plane_points = 1;         // candidates a plane takes per frame (at most 3 in the paper; see README.md)
  int candidate_frames = 3;         // frames a candidate is tracked, at least, before its 3D test
  // The 3D test: a candidate joins if its inverse depth and its plane's along its ray agree within this many
  // combined standard deviations. With 3, a third of the members of a plane lay on another surface of the
  // synthetic streets (vo_bench's purity); with 2, a fifth.
  double join_gate = 2;
  int plane_grow_frames = 10;       // a plane with fewer than min_plane_points after this becomes a point;
                                    // a candidate not tested by then stays a point
  int min_plane_points = 4;
  double plane_sigma_normal = 0.5;  // prior standard deviation of each normal component (unit normal)
  double planarity = 0.02;          // a joining point's depth off its plane: its relative standard deviation

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("mode", self.mode);
    visit("working_width", self.working_width);
    visit("patch_half", self.patch_half);
    visit("search_sigmas", self.search_sigmas);
    visit("max_search_radius", self.max_search_radius);
    visit("min_ncc", self.min_ncc);
    visit("pixel_sigma", self.pixel_sigma);
    visit("max_measurements", self.max_measurements);
    visit("min_features", self.min_features);
    visit("new_features", self.new_features);
    visit("min_distance", self.min_distance);
    visit("border", self.border);
    visit("max_misses", self.max_misses);
    visit("min_rejections", self.min_rejections);
    visit("max_rejected_share", self.max_rejected_share);
    visit("ransac_hypotheses", self.ransac_hypotheses);
    visit("ransac_threshold", self.ransac_threshold);
    visit("initial_inverse_depth", self.initial_inverse_depth);
    visit("initial_inverse_depth_sigma", self.initial_inverse_depth_sigma);
    visit("initial_velocity_sigma", self.initial_velocity_sigma);
    visit("initial_angular_velocity_sigma", self.initial_angular_velocity_sigma);
    visit("bootstrap_frames", self.bootstrap_frames);
    visit("bootstrap_parallax", self.bootstrap_parallax);
    visit("bootstrap_velocity_sigma", self.bootstrap_velocity_sigma);
    visit("fixed_references", self.fixed_references);
    visit("linear_acceleration", self.linear_acceleration);
    visit("angular_acceleration", self.angular_acceleration);
    visit("lost_after", self.lost_after);
    visit("max_new_planes", self.max_new_planes);
    visit("grow_radius", self.grow_radius);
    visit("new_plane_points", self.new_plane_points);
    visit("candidate_frames", self.candidate_frames);
    visit("join_gate", self.join_gate);
    visit("plane_grow_frames", self.plane_grow_frames);
    visit("min_plane_points", self.min_plane_points);
    visit("plane_sigma_normal", self.plane_sigma_normal);
    visit("planarity", self.planarity);
  }
  bool Check() const;
  bool operator==(const VoOptions&) const = default;
};

struct FrameStats {
  double timestamp = 0;
  double seconds = 0;       // processing time
  int attempted = 0;        // features searched for
  int measurements = 0;     // matched and used in the update
  int points = 0;           // in the filter after the frame
  int planes = 0;
  int plane_points = 0;     // points held by those planes
  int state_size = 0;
  bool keyframe = false;
  bool lost = false;        // tracking failed at this frame and started again
  bool bootstrap = false;   // the filter started again here from the two-view bootstrap
};

// A feature as the last frame saw it: where it was found (or predicted, if the search failed), and where it
// was initialised (for drawing tracks and checking matches against ground truth).
struct Observation {
  Eigen::Vector2d pixel;
  int plane = -1;         // the plane's id, or -1 for a point
  bool matched = false;   // the search found it
  bool used = false;      // the update used the match (RANSAC inlier or rescued)
  Eigen::Vector2d keyframe_pixel{0, 0};
  double keyframe_time = 0;  // the timestamp of the frame it was initialised in
};

// A plane as mapped: its most points and the largest area (convex hull of its points, keyframe pixels).
struct PlaneRecord {
  int points = 0;
  double area = 0;
};
// The paper's Table I: planes made (that reached min_plane_points), mean points per plane, mean plane area.
struct MappingStats {
  int planes = 0;
  double points_per_plane = 0;
  double mean_plane_area = 0;  // px^2, working resolution
};

class Odometry {
 public:
  // `camera`: the pinhole camera of the frames given to Track (undistorted, at the working size).
  Odometry(const Pinhole& camera, const VoOptions& options);
  ~Odometry();

  // One 8-bit grey frame; timestamps must increase.
  FrameStats Track(const cv::Mat& grey, double timestamp);
  // The pose of the last frame.
  Rigid3d world_from_cam() const;
  // The pose of every frame so far. Those of the frames before the two-view bootstrap are revised when it
  // succeeds (VoOptions::bootstrap_frames), so that the whole trajectory has one scale.
  const Trajectory& trajectory() const;
  const Filter& filter() const;
  MappingStats mapping() const;
  // Points and planes mapped so far: those that left the filter and those in it.
  Map map() const;
  // The features searched for in the last frame.
  const std::vector<Observation>& observations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdvo::vo
