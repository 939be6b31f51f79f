// Detected planes as priors, on a wall of known depth: a detection is seeded at the corner nearest its centroid
// with the detected normal as its prior and the inverse distance its keyframe's points say; the paper's 30 px
// rule, the small, mapped, grazing and invalid cases are refused and counted; the plane grows only from corners
// inside its polygon, at most new_plane_points a frame; a detection reaches an older keyframe than the newest;
// a later detection extends an older plane in view, or carries on one that waits out of view.
#include "pdvo/vo/plane_priors.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pdvo/vo/map.h"
#include "pdvo/vo/plane_growing.h"

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277, 277, 159.5, 119.5);

// A keyframe (reference camera at the origin) looking at a textured wall 5 m ahead, its corners found, and
// points of the filter at some of them at the wall's inverse depth.
struct Scene {
  Filter filter{CameraState(), Matrix12d::Identity() * 1e-8};
  Tracks tracks;
  int reference = -1;
  FeatureOptions features;
  PdvoOptions options;
  MapRecord record{4};

  Scene() {
    reference = filter.AddReference(true);
    Keyframe& k = tracks.keyframes[reference];
    k.frame = 10;
    k.grey = cv::Mat(240, 320, CV_8U);
    cv::RNG rng(7);
    rng.fill(k.grey, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(k.grey, k.grey, cv::Size(5, 5), 1.5);
    std::vector<cv::Point2f> found;
    cv::goodFeaturesToTrack(k.grey, found, 100, kCornerQuality, features.min_distance, InsideMask(k.grey.size(), 10));
    for (const cv::Point2f& c : found) k.corners.push_back({Eigen::Vector2d(c.x, c.y), false});
  }
  // A point at the wall (5 m) at the keyframe's corner `i`.
  int PointAt(int i) {
    Corner& c = tracks.keyframes.at(reference).corners.at(i);
    c.used = true;
    const Eigen::Vector3d ray = kCamera.Ray(c.pixel);
    const int id = filter.AddPoint(reference, ray, ray.z() / 5.0, 0.01);
    tracks.points[id] = {c.pixel, {}};
    return id;
  }
  SeedingOutcome Seed(const std::vector<DetectedPlane>& planes, int frame = 14) {
    return SeedDetectedPlanes(planes, reference, frame, kCamera, options, features, 1.0, 0.2, &filter, &tracks,
                              &record);
  }
};

DetectedPlane Box(double x0, double y0, double x1, double y1, const Eigen::Vector3d& normal) {
  DetectedPlane p;
  p.polygon = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  p.normal = normal;
  return p;
}

const Eigen::Vector3d kFacing(0, 0, -1);  // the wall's normal, towards the camera

TEST(PlanePriors, SeedsAtTheCornerNearestTheCentroidWithTheDetectedNormal) {
  Scene s;
  for (int i = 0; i < 30; ++i) s.PointAt(i);  // the strongest corners are points already
  const Eigen::Vector3d tilted = Eigen::Vector3d(0.2, -0.1, -1).normalized();
  const DetectedPlane wall = Box(60, 40, 260, 200, Eigen::Vector3d(0.4, -0.2, -2));  // not unit: normalised
  const std::vector<cv::Point2f> outline = {{60, 40}, {260, 40}, {260, 200}, {60, 200}};
  const SeedingOutcome o = s.Seed({wall});
  EXPECT_EQ(o.detected, 1);
  ASSERT_EQ(o.seeded, 1);
  ASSERT_EQ(s.filter.planes().size(), 1u);
  const auto& [id, plane] = *s.filter.planes().begin();
  EXPECT_EQ(plane.reference, s.reference);
  EXPECT_LT((plane.plane.normal - tilted).norm(), 1e-12);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(s.filter.covariance()(plane.offset + k, plane.offset + k),
                s.options.normal_sigma * s.options.normal_sigma, 1e-12);
  }
  // Seeded at the unused corner inside the polygon nearest its centroid (160, 120).
  const PlaneTrack& track = s.tracks.planes.at(id);
  double nearest = 1e9;
  for (const Corner& c : s.tracks.keyframes.at(s.reference).corners) {
    if (InsidePolygon(outline, c.pixel, s.options.region_margin) && c.pixel != track.members[0].keyframe_pixel) {
      if (!c.used) nearest = std::min(nearest, (c.pixel - Eigen::Vector2d(160, 120)).norm());
    }
  }
  EXPECT_LE((track.members[0].keyframe_pixel - Eigen::Vector2d(160, 120)).norm(), nearest);
  // The keyframe's points inside the polygon are its first candidates, of the keyframe's age.
  int inside = 0;
  for (const auto& [point, t] : s.tracks.points) inside += InsidePolygon(outline, t.keyframe_pixel, 8);
  EXPECT_EQ(static_cast<int>(track.candidates.size()), inside);
  for (const Candidate& c : track.candidates) EXPECT_EQ(c.age, 4);
  // Its inverse distance: the median of what the points on the wall say with the detected normal,
  // rho_p = -rho / (n . m).
  std::vector<double> says;
  for (const auto& [point, p] : s.filter.points()) {
    if (InsidePolygon(outline, s.tracks.points.at(point).keyframe_pixel))
      says.push_back(-p.inverse_depth / tilted.dot(p.ray));
  }
  std::sort(says.begin(), says.end());
  ASSERT_GE(says.size(), 3u);
  EXPECT_NEAR(plane.plane.inverse_distance, says[says.size() / 2], 1e-12);
}

TEST(PlanePriors, WithoutPointsTheInverseDistanceComesFromThePrior) {
  Scene s;
  ASSERT_EQ(s.Seed({Box(60, 40, 260, 200, kFacing)}).seeded, 1);
  const Filter::Plane& plane = s.filter.planes().begin()->second;
  const Eigen::Vector3d ray = s.tracks.planes.begin()->second.members[0].ray;
  EXPECT_NEAR(plane.plane.InverseDepthAlong(ray), 0.2, 1e-12);  // the default inverse depth at the seed
}

TEST(PlanePriors, TheThirtyPixelRule) {
  for (const double offset : {29.0, 31.0}) {
    Scene s;
    // A plane of the keyframe with a member `offset` px from the detection's centroid (160, 120).
    const int id = s.filter.AddPlane(s.reference, {kFacing, 0.2}, 0.1, 0.01);
    const Eigen::Vector2d pixel(160 + offset, 120);
    s.tracks.planes[id].members.push_back({pixel, kCamera.Ray(pixel), {}});
    const SeedingOutcome o = s.Seed({Box(100, 60, 220, 180, kFacing)});
    EXPECT_EQ(o.near_plane, offset < 30 ? 1 : 0) << offset;
    EXPECT_EQ(o.seeded, offset < 30 ? 0 : 1) << offset;
  }
}

TEST(PlanePriors, PlanarPointsOfAnotherKeyframeCountWhereTheKeyframeSeesThem) {
  Scene s;
  // A newer keyframe 1 m to the right holds a plane on the same wall; its member at its own pixel (160, 120)
  // is where the older keyframe sees the wall point 1 m right of its centre.
  CameraState moved;
  moved.position = Eigen::Vector3d(1, 0, 0);
  Filter& f = s.filter;
  f.Apply([&] {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(f.size());
    d.head<3>() = moved.position;
    return d;
  }());
  const int newer = f.AddReference(true);
  const int id = f.AddPlane(newer, {kFacing, 0.2}, 0.1, 0.01);
  s.tracks.planes[id].members.push_back({{160, 120}, kCamera.Ray({160, 120}), {}});
  const std::vector<Eigen::Vector2d> seen = PlanarPixelsInKeyframe(f, s.tracks, s.reference, kCamera);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_LT((seen[0] - Eigen::Vector2d(160 + 277 / 5.0, 120)).norm(), 1e-6);
  // A detection of the older keyframe centred there is refused; the same one elsewhere is seeded in the older
  // keyframe, not the newer one.
  EXPECT_EQ(s.Seed({Box(160, 60, 270, 180, kFacing)}).near_plane, 1);
  EXPECT_EQ(s.Seed({Box(20, 60, 130, 180, kFacing)}).seeded, 1);
  int in_older = 0;
  for (const auto& [pid, p] : f.planes()) in_older += p.reference == s.reference;
  EXPECT_EQ(in_older, 1);
}

TEST(PlanePriors, RefusedDetectionsAreCounted) {
  Scene s;
  DetectedPlane invalid = Box(60, 40, 260, 200, kFacing);
  invalid.normal = Eigen::Vector3d(NAN, 0, -1);
  DetectedPlane line = Box(60, 40, 260, 200, kFacing);
  line.polygon.resize(2);
  const Eigen::Vector3d edge_on = Eigen::Vector3d(1, 0, -0.05).normalized();  // along the rays
  const SeedingOutcome o = s.Seed(
      {invalid, line, Box(10, 10, 40, 40, kFacing), Box(60, 40, 260, 200, edge_on), Box(60, 40, 260, 200, -kFacing)});
  EXPECT_EQ(o.detected, 5);
  EXPECT_EQ(o.invalid, 2);
  EXPECT_EQ(o.small, 1);    // 900 px^2 < min_area
  EXPECT_EQ(o.grazing, 2);  // edge-on, and facing away
  EXPECT_EQ(o.seeded, 0);
  EXPECT_TRUE(s.filter.planes().empty());
  // A second detection of a wall that is mapped already (planar points inside its polygon) is refused.
  ASSERT_EQ(s.Seed({Box(60, 40, 260, 200, kFacing)}).seeded, 1);
  PlaneTrack& t = s.tracks.planes.begin()->second;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(70, 50), Eigen::Vector2d(100, 50), Eigen::Vector2d(70, 190)}) {
    t.members.push_back({p, kCamera.Ray(p), {}});
  }
  EXPECT_EQ(s.Seed({Box(50, 30, 130, 210, kFacing)}).mapped, 1);  // centroid (90, 120): 70 px from each
}

TEST(PlanePriors, GrowthStaysInsideThePolygon) {
  Scene s;
  ASSERT_EQ(s.Seed({Box(40, 40, 150, 200, kFacing)}).seeded, 1);
  const std::vector<cv::Point2f> outline = {{40, 40}, {150, 40}, {150, 200}, {40, 200}};
  const int id = s.tracks.planes.begin()->first;
  PlaneOptions planes;
  const PlaneGrower grower(kCamera, planes, s.options.Growth(), s.features, 1.0);
  MapRecord record(planes.min_plane_points);
  size_t before = s.filter.points().size();
  for (int frame = 0; frame < 3; ++frame) {
    grower.Grow(&s.filter, &s.tracks, &record);
    const size_t added = s.filter.points().size() - before;
    EXPECT_LE(static_cast<int>(added), s.options.new_plane_points);
    before = s.filter.points().size();
  }
  const PlaneTrack& track = s.tracks.planes.at(id);
  ASSERT_FALSE(track.candidates.empty());
  for (const Candidate& c : track.candidates) {
    const Eigen::Vector2d& p = s.tracks.points.at(c.point).keyframe_pixel;
    EXPECT_TRUE(InsidePolygon(outline, p, s.options.region_margin)) << p.transpose();
  }
  // Corners outside the polygon were left for points.
  int outside_used = 0;
  for (const Corner& c : s.tracks.keyframes.at(s.reference).corners) {
    outside_used += c.used && !InsidePolygon(outline, c.pixel);
  }
  EXPECT_EQ(outside_used, 0);
}

// A wall plane of the first keyframe, with members across it; the camera then moves `metres` right (by default 1
// m: the later keyframe's detection holds most of the members it sees) and makes a second keyframe (its own image
// and corners).
struct MovedScene : Scene {
  int plane = -1, later = -1;
  explicit MovedScene(double metres = 1) {
    EXPECT_EQ(Seed({Box(20, 20, 300, 220, kFacing)}).seeded, 1);
    plane = tracks.planes.begin()->first;
    PlaneTrack& t = tracks.planes.at(plane);
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(30, 40), Eigen::Vector2d(90, 200), Eigen::Vector2d(200, 60),
                                     Eigen::Vector2d(250, 180), Eigen::Vector2d(280, 120)}) {
      t.members.push_back({p, kCamera.Ray(p), {}});
    }
    t.candidates.clear();
    Eigen::VectorXd step = Eigen::VectorXd::Zero(filter.size());
    step.head<3>() = Eigen::Vector3d(metres, 0, 0);
    filter.Apply(step);
    tracks.LeaveView(kCamera, features, &filter, &record);
    later = filter.AddReference(true);
    Keyframe& k = tracks.keyframes[later];
    k.frame = 40;
    k.grey = tracks.keyframes.at(reference).grey.clone();
    for (const Corner& c : tracks.keyframes.at(reference).corners) k.corners.push_back({c.pixel, false});
  }
  SeedingOutcome SeedLater(const std::vector<DetectedPlane>& planes) {
    return SeedDetectedPlanes(planes, later, 44, kCamera, options, features, 1.0, 0.2, &filter, &tracks, &record);
  }
};

TEST(PlanePriors, ADetectionHoldingAnOlderPlaneExtendsIt) {
  MovedScene s;
  const size_t members_before = s.tracks.planes.at(s.plane).members.size();
  const InversePlane before = s.filter.planes().at(s.plane).plane;
  const double shift = 277 * before.inverse_distance;  // px: the later keyframe sees the wall this far left
  // The member at x 30 leaves its view.
  const SeedingOutcome o = s.SeedLater({Box(40, 20, 300, 220, kFacing)});
  EXPECT_EQ(o.extended, 1);
  EXPECT_EQ(o.seeded, 0);
  ASSERT_EQ(s.filter.planes().size(), 1u);  // no new plane
  const Filter::Plane& moved = s.filter.planes().at(s.plane);
  EXPECT_EQ(moved.reference, s.later);
  EXPECT_FALSE(s.filter.references().count(s.reference));  // the first keyframe had nothing else
  EXPECT_FALSE(s.tracks.keyframes.count(s.reference));
  // The same wall, as far from the later camera (it moved along it).
  EXPECT_LT((moved.plane.normal.normalized() - kFacing).norm(), 1e-9);
  EXPECT_NEAR(moved.plane.inverse_distance, before.inverse_distance, 1e-12);
  const PlaneTrack& t = s.tracks.planes.at(s.plane);
  EXPECT_EQ(t.members.size() + t.moved_away, members_before);
  EXPECT_EQ(t.moved_away, 1);
  for (const PlanePoint& m : t.members) {
    EXPECT_LT((kCamera.Ray(m.keyframe_pixel) - m.ray).norm(), 1e-9);  // rays and pixels of the later keyframe
    EXPECT_GE(m.keyframe_pixel.x(), s.features.border);
  }
  EXPECT_TRUE(std::any_of(t.members.begin(), t.members.end(), [&](const PlanePoint& m) {
    return (m.keyframe_pixel - Eigen::Vector2d(250 - shift, 180)).norm() < 1e-6;
  }));
  // It grows in the new polygon, from the later keyframe's corners; the map keeps what it was before it moved.
  EXPECT_TRUE(t.detected);
  ASSERT_FALSE(t.region_corners.empty());
  const std::vector<cv::Point2f> outline = {{40, 20}, {300, 20}, {300, 220}, {40, 220}};
  for (int i : t.region_corners) {
    EXPECT_TRUE(InsidePolygon(outline, s.tracks.keyframes.at(s.later).corners.at(i).pixel, s.options.region_margin));
  }
  EXPECT_EQ(s.record.kept().planes.size(), 1u);
  EXPECT_EQ(s.record.stats().points_per_plane, static_cast<double>(members_before));
}

TEST(PlanePriors, AnOlderPlaneIsNotExtendedByADetectionThatDisagrees) {
  MovedScene s;
  const Eigen::Vector3d turned = Eigen::Vector3d(std::sin(0.7), 0, -std::cos(0.7));  // 40 degrees off
  EXPECT_EQ(s.SeedLater({Box(40, 20, 300, 220, turned)}).extended, 0);
  EXPECT_EQ(s.filter.planes().at(s.plane).reference, s.reference);
  // Nor one that holds too few of the points the later keyframe sees: 2 of 5 (fewer than max_mapped_points).
  MovedScene t;
  EXPECT_EQ(t.SeedLater({Box(140, 20, 300, 140, kFacing)}).extended, 0);
  EXPECT_EQ(t.filter.planes().at(t.plane).reference, t.reference);
  // A fourth member inside that outline: 3 of 6 (half) extends the plane; one more outside, 3 of 7, does not.
  for (const bool outside : {false, true}) {
    MovedScene u;
    std::vector<PlanePoint>& members = u.tracks.planes.at(u.plane).members;
    const Eigen::Vector2d in(260, 50), out(120, 210);  // the later keyframe sees them 55 px further left
    members.push_back({in, kCamera.Ray(in), {}});
    if (outside) members.push_back({out, kCamera.Ray(out), {}});
    EXPECT_EQ(u.SeedLater({Box(140, 20, 300, 140, kFacing)}).extended, outside ? 0 : 1) << outside;
  }
}

// The camera moves 6 m along the wall from the first keyframe, where none of the plane's members is in view: the
// plane waits, and a later keyframe is made there.
struct PassedScene : MovedScene {
  PassedScene() : MovedScene(6) { EXPECT_TRUE(tracks.planes.at(plane).out_of_view); }
};

TEST(PlanePriors, APlaneOutOfViewIsCarriedOnByTheNextDetectionOfItsOrientation) {
  PassedScene s;
  PlaneTrack& waiting = s.tracks.planes.at(s.plane);
  const int age = waiting.age;
  const PlaneOptions planes;
  PlaneGrower(kCamera, planes, s.options.Growth(), s.features, 1.0).Grow(&s.filter, &s.tracks, &s.record);
  EXPECT_EQ(s.tracks.planes.at(s.plane).age, age);  // a waiting plane does not grow (nor age)
  const InversePlane before = s.filter.planes().at(s.plane).plane;
  const SeedingOutcome o = s.SeedLater({Box(60, 40, 260, 200, kFacing)});
  EXPECT_EQ(o.extended, 1);
  EXPECT_EQ(o.seeded, 0);
  ASSERT_EQ(s.filter.planes().size(), 1u);
  const Filter::Plane& moved = s.filter.planes().at(s.plane);
  EXPECT_EQ(moved.reference, s.later);
  EXPECT_NEAR(moved.plane.inverse_distance, before.inverse_distance, 1e-12);  // the same wall, as far
  const PlaneTrack& t = s.tracks.planes.at(s.plane);
  EXPECT_FALSE(t.out_of_view);
  EXPECT_EQ(t.age, 0);
  ASSERT_EQ(t.members.size(), 1u);  // the seed of the later keyframe; the six earlier ones moved away
  EXPECT_EQ(t.moved_away, 6);
  const std::vector<cv::Point2f> outline = {{60, 40}, {260, 40}, {260, 200}, {60, 200}};
  EXPECT_TRUE(InsidePolygon(outline, t.members[0].keyframe_pixel, s.options.region_margin));
  EXPECT_FALSE(t.region_corners.empty());
  ASSERT_EQ(s.record.kept().planes.size(), 1u);  // what it mapped before, kept
  EXPECT_EQ(s.record.stats().planes, 1);         // one plane, not two
  // In the map, its polygon before and its polygon now are numbered as one plane.
  const Map now = CurrentMap(s.filter, s.tracks, 1, s.record.filter_number());
  ASSERT_EQ(now.planes.size(), 1u);
  EXPECT_EQ(s.record.kept().planes[0].plane, s.plane);
  EXPECT_EQ(now.planes[0].plane, s.plane);
  EXPECT_EQ(s.record.kept().planes[0].filter, now.planes[0].filter);
}

TEST(PlanePriors, APlaneOutOfViewIsNotCarriedOnByAnotherOrientation) {
  PassedScene s;
  const Eigen::Vector3d turned = Eigen::Vector3d(std::sin(0.35), 0, -std::cos(0.35));  // 20 degrees off
  const SeedingOutcome o = s.SeedLater({Box(60, 40, 260, 200, turned)});
  EXPECT_EQ(o.extended, 0);
  EXPECT_EQ(o.seeded, 1);
  EXPECT_EQ(s.filter.planes().at(s.plane).reference, s.reference);
  EXPECT_TRUE(s.tracks.planes.at(s.plane).out_of_view);
  s.tracks.RemoveOutOfView(&s.filter, &s.record);  // as the odometry does after each detection
  EXPECT_FALSE(s.filter.planes().count(s.plane));
  EXPECT_EQ(s.filter.planes().size(), 1u);
}

}  // namespace
}  // namespace pdvo::vo
