// Detected planes as priors (the paper's section V, PDVO). The planes a detector found in a keyframe
// (detection_worker.h) arrive some frames later; each becomes a planar feature of that keyframe's reference
// camera unless it is small (min_area), a planar point visible in the keyframe lies within min_plane_distance of
// its centroid (the paper), or its polygon already holds max_mapped_points such points. It is seeded at the
// keyframe corner nearest its centroid inside its polygon, with the detected normal as the normal's prior
// (normal_sigma per component) and an inverse distance from the keyframe's points inside the polygon (the
// median of what their inverse depths say, given the normal; the nearest point's if fewer than three; the
// odometry's prior if none). Its candidates are the keyframe's points inside the polygon (tracked since the
// keyframe) and new corners found inside it, at least region_margin from the outline; it takes up to
// new_plane_points of them a frame, each through the 3D consistency test (plane_growing.h) once its inverse
// depth is known to known_inverse_depth.
// A detection whose polygon holds most of the points of one older plane (anchored at an earlier keyframe) that
// the keyframe sees, with a normal that agrees, extends that plane instead: the plane moves to the keyframe
// (Filter::MovePlane; its points become the keyframe's rays and pixels) and grows in the polygon as a new one
// would. A surface that stays in view is then one plane however many keyframes see it, as one map plane should
// be, not a new plane per keyframe. A detected plane whose points have all left the view (the road, passed by)
// waits out of the measurements until the next detection (Tracks::LeaveView): a detection that would be seeded,
// with a normal within max_extend_angle of the waiting plane's, carries that plane on instead (moved to the
// keyframe, seeded and grown there as a new plane would be); waiting planes that no detection carried on leave
// then (the odometry calls Tracks::RemoveOutOfView after each detection). Pixels are the keyframe's working image.
#pragma once

#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/detected_plane.h"
#include "pdvo/vo/detection_worker.h"
#include "pdvo/vo/filter.h"
#include "pdvo/vo/plane_growing.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {

struct PdvoOptions {
  DetectionSchedule schedule = DetectionSchedule::kDeterministic;
  // Deterministic: frames from the start of a detection to the use of its planes. The shipped detector takes
  // about 70 ms a 320x240 image (docs/detector.md): 3 frames at 30 Hz.
  int delay_frames = 3;
  double timeout_seconds = 10;     // deterministic: the longest wait for a detection, then go on without it
  double min_plane_distance = 30;  // px in the keyframe (the paper)
  double min_area = 1500;          // px^2 in the keyframe: smaller detections are not used
  double min_score = 0;            // detections of a lower score are not used
  int max_planes = 10;             // planes seeded per keyframe, at most: the largest detections first
  // A detection whose polygon holds this many planar points visible in the keyframe is mapped already: if most
  // of one older plane's points the keyframe sees are inside, with a normal within max_extend_angle (degrees)
  // of the detected one, that plane is extended (moved to the keyframe, to grow in the polygon); else dropped.
  int max_mapped_points = 3;
  double max_extend_angle = 10;
  // The prior standard deviation of each component of a detected (unit) normal (about 2 degrees a component; the
  // shipped model's matched planes are a median 3 degrees off on held-out streets, more on real images:
  // docs/detector.md; measured against 0.05 and 0.15 in docs/experiments/2026-12-05-waiting-points.md).
  double normal_sigma = 0.03;
  int new_plane_points = 10;  // candidates a detected plane takes a frame (the paper)
  // A candidate of a detected plane takes the 3D test once its inverse depth is known to this share of itself
  // (IDPP's blind seeds: planes.known_inverse_depth, 0.25). Stricter, because the detected outline lets in
  // points of whatever stands in front of the plane: docs/experiments/2026-12-05-pdvo-speed-and-planes.md.
  double known_inverse_depth = 0.12;
  int region_corners = 60;  // new corners looked for inside each detected polygon, at most
  // px: a plane's points are taken at least this far inside its polygon (corners cluster on the outlines, where
  // surfaces meet, and a detected outline is a few pixels off).
  double region_margin = 8;
  // A detection is used only if its normal and the seed's ray make an angle whose cosine is at least this
  // (seen nearly edge-on, the plane's depth along the ray is ill-defined).
  double min_facing = 0.2;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("schedule", self.schedule);
    visit("delay_frames", self.delay_frames);
    visit("timeout_seconds", self.timeout_seconds);
    visit("min_plane_distance", self.min_plane_distance);
    visit("min_area", self.min_area);
    visit("min_score", self.min_score);
    visit("max_planes", self.max_planes);
    visit("max_mapped_points", self.max_mapped_points);
    visit("max_extend_angle", self.max_extend_angle);
    visit("normal_sigma", self.normal_sigma);
    visit("new_plane_points", self.new_plane_points);
    visit("known_inverse_depth", self.known_inverse_depth);
    visit("region_corners", self.region_corners);
    visit("region_margin", self.region_margin);
    visit("min_facing", self.min_facing);
  }
  bool Check() const;
  bool operator==(const PdvoOptions&) const = default;
  // How the planes seeded here grow (PlaneGrower).
  DetectedGrowth Growth() const { return {new_plane_points, known_inverse_depth}; }
};

// What became of one keyframe's detected planes.
struct SeedingOutcome {
  int detected = 0;
  int seeded = 0;
  int extended = 0;    // an older plane moved here and grows in the polygon: its points are inside it, or it
                       // waited out of view with this orientation
  int small = 0;       // polygon smaller than min_area, or score below min_score
  int too_many = 0;    // max_planes were seeded already (from larger detections)
  int near_plane = 0;  // centroid within min_plane_distance of a planar point visible in the keyframe
  int mapped = 0;      // max_mapped_points or more visible planar points inside the polygon
  int no_corner = 0;   // no unused keyframe corner inside the polygon
  int grazing = 0;     // normal and seed ray nearly perpendicular, or the normal faces away
  int invalid = 0;     // fewer than 3 polygon points, a degenerate polygon, or a normal that is not finite
};

// The planar points of `tracks` as keyframe `reference` of `filter` sees them (pixels; inside the image).
std::vector<Eigen::Vector2d> PlanarPixelsInKeyframe(const Filter& filter, const Tracks& tracks, int reference,
                                                    const Camera& camera);

// Seeds the planes detected in keyframe `reference` (which must be in `filter` and `tracks`) at frame `frame`,
// as the header says. `relative_prior_sigma`: an inverse distance's prior standard deviation as a share of it;
// `default_inverse_depth`: the prior where the keyframe has no point. Adds planes to `filter` and `tracks`, and
// corners to the keyframe; a plane that moves leaves what it mapped so far in `record`.
SeedingOutcome SeedDetectedPlanes(const std::vector<DetectedPlane>& planes, int reference, int frame,
                                  const Camera& camera, const PdvoOptions& options, const FeatureOptions& features,
                                  double relative_prior_sigma, double default_inverse_depth, Filter* filter,
                                  Tracks* tracks, MapRecord* record);

}  // namespace pdvo::vo
