// Plane growing (the paper's section IV, IDPP): every frame each plane takes new candidate points from its
// keyframe's corners near its members; a candidate is an inverse-depth point of its own until its depth is
// known, then the 3D consistency test decides: it joins the plane if its inverse depth agrees with where its ray
// meets the plane, and what it knows is fused into the plane (Filter::MergePointIntoPlane); otherwise it stays an
// ordinary point. Members missed or rejected too often leave; a plane that has not reached min_plane_points
// after plane_grow_frames becomes a point (one that had reached it stays in the record, map.h). Pixels are the
// keyframe's (working image); inverse depths are 1/m in the map's scale.
#pragma once

#include "pdvo/common/camera.h"
#include "pdvo/vo/filter.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {

class MapRecord;

struct PlaneOptions {
  int max_new_planes = 3;           // planes seeded per keyframe (mode idpp)
  double grow_radius = 40;          // px in the keyframe: candidates this near a member; idpp seeds twice apart
  int new_plane_points = 1;         // candidates a plane takes per frame (the paper's IDPP: at most 3)
  int candidate_frames = 3;         // frames a candidate is tracked, at least, before its 3D test
  double join_gate = 2;             // the 3D test's gate, in combined standard deviations of the inverse depths
  int plane_grow_frames = 10;       // frames a plane has to reach min_plane_points; a candidate untested by then
                                    // stays a point
  int min_plane_points = 4;         // a plane with fewer is not a plane (not mapped, not counted)
  double plane_sigma_normal = 0.5;  // prior standard deviation of each component of a seeded (unit) normal
  double planarity = 0.02;          // a joining point's distance off its plane, as a share of its inverse depth
  // A candidate takes the 3D test once its inverse depth is known to this share of itself (one standard
  // deviation); a detected plane's candidates by DetectedGrowth::known_inverse_depth instead.
  double known_inverse_depth = 0.25;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("max_new_planes", self.max_new_planes);
    visit("grow_radius", self.grow_radius);
    visit("new_plane_points", self.new_plane_points);
    visit("candidate_frames", self.candidate_frames);
    visit("join_gate", self.join_gate);
    visit("plane_grow_frames", self.plane_grow_frames);
    visit("min_plane_points", self.min_plane_points);
    visit("plane_sigma_normal", self.plane_sigma_normal);
    visit("planarity", self.planarity);
    visit("known_inverse_depth", self.known_inverse_depth);
  }
  bool Check() const;
  bool operator==(const PlaneOptions&) const = default;
};

// True if a point's inverse depth is positive and known to `share` of itself (one standard deviation): well
// enough for the 3D test.
bool KnownForPlaneTest(const Filter& filter, const Filter::Point& point, double share);
// The 3D consistency test of point `point` against plane `plane`: they share a reference camera, the plane meets
// the point's ray in front, and the point's inverse depth and the plane's along the ray agree within `gate`
// standard deviations of their difference (first order in (n, rho_p)). `on_plane` (if given) becomes the
// plane's inverse depth along the ray.
bool PassesPlaneTest(const Filter& filter, int point, int plane, double gate, double* on_plane = nullptr);
// The variance of the inverse depth at which `ray` (unit, reference frame) meets the plane.
double InverseDepthVariance(const Filter& filter, const Filter::Plane& plane, const Eigen::Vector3d& ray);

// How a detected plane (PlaneTrack::detected) grows, from mode pdvo's options (plane_priors.h): candidates a
// frame (pdvo.new_plane_points) and how well a candidate's inverse depth is known before its 3D test
// (pdvo.known_inverse_depth).
struct DetectedGrowth {
  int new_points = 0;
  double known_inverse_depth = 0;
};

class PlaneGrower {
 public:
  // `relative_prior_sigma`: a candidate's inverse-depth prior standard deviation as a share of the prior.
  PlaneGrower(const Camera& camera, const PlaneOptions& planes, const DetectedGrowth& detected,
              const FeatureOptions& features, double relative_prior_sigma);

  // One frame of growth for every plane of `tracks` (after the frame's update): tests the candidates that are
  // old and known enough, adds new candidates, demotes planes that did not grow, records the planes' sizes.
  void Grow(Filter* filter, Tracks* tracks, MapRecord* record) const;

 private:
  // Up to new_plane_points candidates for plane `id` from its keyframe's unused corners within grow_radius of
  // a member (a detected plane: up to DetectedGrowth::new_points, from its region_corners) and at least min_distance
  // from all of them.
  void AddCandidates(int id, Filter* filter, Tracks* tracks) const;

  Camera camera_;
  PlaneOptions o_;
  DetectedGrowth detected_;
  FeatureOptions features_;
  double relative_prior_sigma_;
};

}  // namespace pdvo::vo
