// Plane growing's parts on known depths: the 3D consistency test accepts a point on the plane and refuses one a
// metre behind it, or one of another reference camera; a grown frame lets a known candidate on the plane join
// (fused into the plane, its point leaving the filter) and one off it stay a point; a candidate waits until its
// depth is known to the plane's share (stricter for a detected plane); a plane that does not grow
// becomes a point. The IDPP seeder seeds where corners are densest, apart, facing the camera.
#include "pdvo/vo/plane_growing.h"

#include <gtest/gtest.h>

#include "pdvo/vo/map.h"
#include "pdvo/vo/plane_seeder.h"

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277, 277, 159.5, 119.5);

// A wall 5 m ahead facing the camera (reference 0), a plane on it, and points on its rays.
struct Wall {
  Filter filter{CameraState(), Matrix12d::Identity() * 1e-8};
  int reference = -1, plane = -1;
  Wall() {
    reference = filter.AddReference(true);
    plane = filter.AddPlane(reference, {Eigen::Vector3d(0, 0, -1), 0.2}, 0.01, 0.002);
  }
  // A point at `depth` (m, along z) seen at `pixel`, its inverse depth known to `relative_sigma`.
  int Point(const Eigen::Vector2d& pixel, double depth, double relative_sigma) {
    const Eigen::Vector3d ray = kCamera.Ray(pixel);
    const double rho = ray.z() / depth;
    return filter.AddPoint(reference, ray, rho, relative_sigma * rho);
  }
};

TEST(PlaneGrowing, TheThreeDTestOnKnownDepths) {
  Wall w;
  const int on = w.Point({200, 100}, 5.0, 0.05), behind = w.Point({120, 140}, 6.0, 0.05);
  double on_plane = 0;
  EXPECT_TRUE(PassesPlaneTest(w.filter, on, w.plane, 2, &on_plane));
  EXPECT_NEAR(on_plane, w.filter.points().at(on).inverse_depth, 1e-12);
  EXPECT_FALSE(PassesPlaneTest(w.filter, behind, w.plane, 2));
  EXPECT_TRUE(PassesPlaneTest(w.filter, behind, w.plane, 100));  // a gate wide enough takes it
  // A point of another reference camera is never tested against the plane.
  const int other = w.filter.AddReference(true);
  const int elsewhere = w.filter.AddPoint(other, kCamera.Ray({200, 100}), 0.2, 0.01);
  EXPECT_FALSE(PassesPlaneTest(w.filter, elsewhere, w.plane, 100));
  EXPECT_TRUE(KnownForPlaneTest(w.filter, w.filter.points().at(on), 0.25));
  EXPECT_FALSE(KnownForPlaneTest(w.filter, w.filter.points().at(on), 0.04));  // known to 5%
  EXPECT_FALSE(KnownForPlaneTest(w.filter, w.filter.points().at(w.Point({60, 60}, 5.0, 0.5)), 0.25));
}

TEST(PlaneGrowing, CandidatesJoinOrStayPoints) {
  Wall w;
  PlaneOptions options;
  options.candidate_frames = 1;
  options.new_plane_points = 2;
  const FeatureOptions features;
  const PlaneGrower grower(kCamera, options, {}, features, 1.0);
  Tracks tracks;
  MapRecord record(options.min_plane_points);
  Keyframe& keyframe = tracks.keyframes[w.reference];
  keyframe.grey = cv::Mat(240, 320, CV_8U, cv::Scalar(0));
  const Eigen::Vector2d seed(160, 120);
  tracks.planes[w.plane].members.push_back({seed, kCamera.Ray(seed), {}});
  const int on = w.Point({180, 120}, 5.0, 0.02), off = w.Point({160, 145}, 7.0, 0.02);
  tracks.points[on] = {{180, 120}, {}};
  tracks.points[off] = {{160, 145}, {}};
  tracks.planes[w.plane].candidates = {{on, 0}, {off, 0}};
  // Corners for new candidates: one within grow_radius, one too near the seed, one too far.
  keyframe.corners = {{{190, 100}, false}, {{163, 121}, false}, {{300, 20}, false}};
  const int points_before = static_cast<int>(w.filter.points().size());
  grower.Grow(&w.filter, &tracks, &record);
  const PlaneTrack& t = tracks.planes.at(w.plane);
  ASSERT_EQ(t.members.size(), 2u);  // the seed and the point on the wall
  EXPECT_EQ(t.members[1].keyframe_pixel, Eigen::Vector2d(180, 120));
  EXPECT_FALSE(w.filter.points().count(on));
  EXPECT_FALSE(tracks.points.count(on));
  EXPECT_TRUE(w.filter.points().count(off));  // off the wall: an ordinary point
  // One new candidate, at the corner within reach, with the plane's depth as its prior.
  ASSERT_EQ(t.candidates.size(), 1u);
  EXPECT_TRUE(keyframe.corners[0].used);
  EXPECT_FALSE(keyframe.corners[1].used);
  EXPECT_FALSE(keyframe.corners[2].used);
  const Filter::Point& candidate = w.filter.points().at(t.candidates[0].point);
  EXPECT_NEAR(candidate.inverse_depth, w.filter.planes().at(w.plane).plane.InverseDepthAlong(candidate.ray), 1e-12);
  EXPECT_EQ(static_cast<int>(w.filter.points().size()), points_before);  // one joined, one candidate added
  // Without growing to min_plane_points within plane_grow_frames, the plane becomes a point at its seed.
  for (int k = 1; k < options.plane_grow_frames; ++k) grower.Grow(&w.filter, &tracks, &record);
  EXPECT_TRUE(tracks.planes.empty());
  EXPECT_TRUE(w.filter.planes().empty());
  EXPECT_EQ(record.stats().planes, 0);  // it never had min_plane_points
}

// A candidate takes the 3D test only once its inverse depth is known to the plane's share: a blind seed's
// (planes.known_inverse_depth, 0.25), or a detected plane's own (pdvo.known_inverse_depth).
TEST(PlaneGrowing, CandidatesWaitUntilTheirDepthIsKnownToThePlanesShare) {
  for (const bool detected : {false, true}) {
    Wall w;
    PlaneOptions options;
    options.candidate_frames = 1;
    const FeatureOptions features;
    const PlaneGrower grower(kCamera, options, {.new_points = 1, .known_inverse_depth = 0.12}, features, 1.0);
    Tracks tracks;
    MapRecord record(options.min_plane_points);
    tracks.keyframes[w.reference].grey = cv::Mat(240, 320, CV_8U, cv::Scalar(0));
    PlaneTrack& t = tracks.planes[w.plane];
    const Eigen::Vector2d seed(160, 120);
    t.members.push_back({seed, kCamera.Ray(seed), {}});
    t.detected = detected;
    // On the wall, known to 20%: enough for a blind seed, not for the detected plane.
    const int on = w.Point({180, 120}, 5.0, 0.2);
    tracks.points[on] = {{180, 120}, {}};
    t.candidates = {{on, 0}};
    grower.Grow(&w.filter, &tracks, &record);
    EXPECT_EQ(tracks.planes.at(w.plane).members.size(), detected ? 1u : 2u) << "detected " << detected;
    EXPECT_EQ(tracks.planes.at(w.plane).candidates.size(), detected ? 1u : 0u) << "detected " << detected;
  }
}

TEST(PlaneSeeder, SeedsWhereCornersAreDensest) {
  Keyframe keyframe;
  // A dense cluster of 9 corners around (80, 80), a sparser one of 6 around (242, 156), a lone corner.
  for (int i = 0; i < 9; ++i) keyframe.corners.push_back({{70.0 + 10 * (i % 3), 70.0 + 10 * (i / 3)}, false});
  for (int i = 0; i < 6; ++i) keyframe.corners.push_back({{230.0 + 12 * (i % 3), 150.0 + 12 * (i / 3)}, false});
  keyframe.corners.push_back({{300, 30}, false});
  PlaneOptions options;
  DensestCornersSeeder seeder(options);
  const std::vector<PlaneSeed> seeds = seeder.Seed(keyframe, kCamera);
  ASSERT_EQ(seeds.size(), 2u);    // the lone corner has too few neighbours
  EXPECT_LT(seeds[0].corner, 9);  // in the dense cluster (every corner of it has the other 8 within reach)
  EXPECT_GE(seeds[1].corner, 9);  // then the sparser one, more than twice grow_radius away
  EXPECT_LT(seeds[1].corner, 15);
  for (const PlaneSeed& s : seeds) {
    const Eigen::Vector3d ray = kCamera.Ray(keyframe.corners[s.corner].pixel);
    EXPECT_NEAR(s.normal.dot(ray), -1, 1e-12);  // facing the camera along the ray
    EXPECT_EQ(s.sigma_normal, options.plane_sigma_normal);
  }
  options.max_new_planes = 1;
  EXPECT_EQ(DensestCornersSeeder(options).Seed(keyframe, kCamera).size(), 1u);
  EXPECT_EQ(MakePlaneSeeder(PlaneMode::kPoints, options), nullptr);
  EXPECT_NE(MakePlaneSeeder(PlaneMode::kIdpp, options), nullptr);
}

}  // namespace
}  // namespace pdvo::vo
