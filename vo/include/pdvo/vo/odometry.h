// The visual odometry's per-frame loop (the paper's section IV), over the EKF of filter.h. Per frame: predict
// (motion.h); features out of view leave (tracks.h); each feature's keyframe patch is warped into the current
// view by its plane's homography and searched for by NCC inside its innovation ellipse (patch.h); the matches
// update the filter through 1-point RANSAC (robust_update.h); features missed or rejected too often leave;
// planes grow (plane_growing.h). When too few features are in view, a keyframe is made: a plane seeder picks
// where planes start (plane_seeder.h: none in mode points, where corners are densest in mode idpp) and new points
// start at its strongest other corners. In mode pdvo a detector looks for planes in keyframes in the background
// (detection_worker.h) and its planes, when they arrive, are seeded in their keyframe (plane_priors.h); no other
// planes are made. The first frames also run the two-view bootstrap (bootstrap.h). If
// tracking fails (no measurement for lost_after frames, or a non-finite state) the frame says so and the
// odometry starts again from the last pose. What left the filter is kept in the map (map.h).
//
// Frames are 8-bit grey images of the working camera (undistorted, at the working size): FramePreparer
// (frames.h) makes them from a camera's images. The world is the first camera's frame; metres are the map's own
// (monocular: the scale is arbitrary).
#pragma once

#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/vo/bootstrap.h"
#include "pdvo/vo/detection_worker.h"
#include "pdvo/vo/filter.h"
#include "pdvo/vo/health.h"
#include "pdvo/vo/map.h"
#include "pdvo/vo/patch.h"
#include "pdvo/vo/plane_growing.h"
#include "pdvo/vo/plane_priors.h"
#include "pdvo/vo/plane_seeder.h"
#include "pdvo/vo/robust_update.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {

// The priors of what the filter starts with.
struct PriorOptions {
  // A new point's inverse depth at the first keyframe (later: that of the mapped point nearest in the image),
  // and its standard deviation as the same share of every prior.
  double inverse_depth = 0.2;           // 1/m
  double inverse_depth_sigma = 0.2;     // 1/m
  double velocity_sigma = 0.1;          // m/s: the velocity's at each start (at rest)
  double angular_velocity_sigma = 0.5;  // rad/s: the angular velocity's at each start and after the bootstrap

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("inverse_depth", self.inverse_depth);
    visit("inverse_depth_sigma", self.inverse_depth_sigma);
    visit("velocity_sigma", self.velocity_sigma);
    visit("angular_velocity_sigma", self.angular_velocity_sigma);
  }
  bool Check() const;
  bool operator==(const PriorOptions&) const = default;
};

// Every option of the odometry; vo/config/default.yaml lists them with their defaults.
struct VoOptions {
  PlaneMode mode = PlaneMode::kPoints;  // where planes come from (plane_seeder.h)
  int working_width = 320;              // px: frames are resized to this width (FramePreparer; 0: the camera's own)
  // Keyframes' poses are taken as exact once made (Filter::AddReference): updates do not move the map with the
  // camera, and the camera's covariance is relative to its keyframes. Off: reference cameras stay in the state.
  bool fixed_references = true;
  int lost_after = 5;  // frames in a row without enough matches (HealthOptions) before starting again
  FeatureOptions features;
  SearchOptions search;
  RansacOptions ransac;
  PriorOptions prior;
  BootstrapOptions bootstrap;
  MotionNoise motion;
  PlaneOptions planes;
  PdvoOptions pdvo;  // mode pdvo: the detector's schedule and how its planes are seeded
  HealthOptions health;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("mode", self.mode);
    visit("working_width", self.working_width);
    visit("fixed_references", self.fixed_references);
    visit("lost_after", self.lost_after);
    visit("features", self.features);
    visit("search", self.search);
    visit("ransac", self.ransac);
    visit("prior", self.prior);
    visit("bootstrap", self.bootstrap);
    visit("motion", self.motion);
    visit("planes", self.planes);
    visit("pdvo", self.pdvo);
    visit("health", self.health);
  }
  bool Check() const;
  bool operator==(const VoOptions&) const = default;
};

// A keyframe's detections as they reached the odometry (mode pdvo).
struct DetectionEvent {
  DetectionResult result;      // with the planes as detected
  bool keyframe_gone = false;  // its reference camera had left the filter: dropped
  SeedingOutcome seeding;
};

struct FrameStats {
  double timestamp = 0;
  double seconds = 0;                // processing time, without detector_wait_seconds
  double detector_wait_seconds = 0;  // mode pdvo, deterministic schedule: time spent waiting for the detector
  int attempted = 0;                 // features searched for
  int measurements = 0;              // matched and used in the update
  // Their mean normalised innovation squared against the frame's prediction (2 expected; the search gates at
  // search_sigmas^2).
  double nis = 0;
  int points = 0;  // in the filter after the frame
  int planes = 0;
  int plane_points = 0;        // points held by those planes
  int plane_measurements = 0;  // measurements of plane points used in the update
  int state_size = 0;
  bool keyframe = false;
  bool lost = false;  // tracking failed at this frame and started again (health kLost)
  Health health = Health::kTracked;
  int segment = 0;         // starts so far (health above): frames of one segment share a frame of reference
  bool bootstrap = false;  // the filter started again here from the two-view bootstrap
  // The frame's update: kOk, kNoMeasurements (nothing matched, or no hypothesis had an inlier), or a failure
  // (the update was skipped and the filter left as predicted).
  UpdateStatus update = UpdateStatus::kNoMeasurements;
  std::vector<DetectionEvent> detections;  // mode pdvo: those that arrived at this frame
};

// A feature as the last frame saw it: where it was found (or predicted, if the search failed), and where it
// was initialised (for drawing tracks and checking matches against ground truth).
struct Observation {
  Eigen::Vector2d pixel;
  int plane = -1;        // the plane's id, or -1 for a point
  bool matched = false;  // the search found it
  bool used = false;     // the update used the match (RANSAC inlier or rescued)
  Eigen::Vector2d keyframe_pixel{0, 0};
  double keyframe_time = 0;  // the timestamp of the frame it was initialised in
};

class Odometry {
 public:
  // `camera`: the working camera (no distortion) of the frames given to Track; throws InvalidArgument for a
  // camera with distortion or invalid options. `seeder` overrides where planes come from (default: the mode's).
  // `detector`: mode pdvo's source of planes (required in that mode, refused in the others), run on keyframes
  // in a thread of its own (detection_worker.h).
  Odometry(const Camera& camera, const VoOptions& options, std::unique_ptr<PlaneSeeder> seeder = nullptr,
           PlaneDetector detector = {});
  ~Odometry();

  // One 8-bit grey frame of the camera's size; timestamps (s) must increase. `colour` (optional, CV_8UC3 of the
  // same size): the same frame in colour, for the detector. Throws InvalidArgument for a frame of another size
  // or type or a timestamp that does not increase; a failure of tracking is a value.
  FrameStats Track(const cv::Mat& grey, double timestamp, const cv::Mat& colour = cv::Mat());
  // The pose of the last frame.
  Rigid3d world_from_cam() const;
  // The pose of every frame so far. Those of the frames before the two-view bootstrap are revised when it
  // succeeds, so that the whole trajectory has one scale.
  const Trajectory& trajectory() const;
  const Filter& filter() const;
  MappingStats mapping() const;
  // Points and planes mapped so far: those that left the filter and those in it.
  Map map() const;
  // The features searched for in the last frame.
  const std::vector<Observation>& observations() const;
  // The planes in the filter as seen from the last frame's pose (pixels): the region their points span (the
  // convex hull of their keyframe pixels, carried through the plane) and, for detected planes, the detected
  // polygon likewise. Vertices behind either camera are left out.
  struct PlaneOutline {
    int id = -1;
    std::vector<Eigen::Vector2d> region, detected;
  };
  std::vector<PlaneOutline> plane_outlines() const;
  // Mode pdvo: keyframes not detected (a newer one replaced them while the detector was busy), detections
  // given up (deterministic timeout), and detections whose detector threw.
  struct DetectionCounts {
    int skipped = 0, timed_out = 0, failed = 0;
  };
  DetectionCounts detection_counts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdvo::vo
