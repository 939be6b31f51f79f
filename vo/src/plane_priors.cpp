#include "pdvo/vo/plane_priors.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>

#include "pdvo/common/options.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {

bool PdvoOptions::Check() const {
  PDVO_CHECK_OPTION(delay_frames >= 1 && timeout_seconds > 0 && min_plane_distance >= 0 && min_area >= 0);
  PDVO_CHECK_OPTION(normal_sigma > 0 && new_plane_points >= 1 && region_corners >= 0 && known_inverse_depth > 0);
  PDVO_CHECK_OPTION(min_facing > 0 && min_facing < 1 && max_extend_angle >= 0 && max_extend_angle <= 180);
  return true;
}

namespace {

// The points of plane `id` (track `track`) that keyframe `reference` sees at least `border` px inside: index in
// track.members, pixel and ray (unit) of the keyframe.
struct MemberInKeyframe {
  size_t member = 0;
  Eigen::Vector2d pixel;
  Eigen::Vector3d ray;
};
std::vector<MemberInKeyframe> MembersInKeyframe(const Filter& filter, int plane_id, const PlaneTrack& track,
                                                int reference, const Camera& camera, int border) {
  const Filter::Plane& plane = filter.planes().at(plane_id);
  const Rigid3d keyframe_from_plane_ref = filter.references().at(reference).world_from_cam.Inverse() *
                                          filter.references().at(plane.reference).world_from_cam;
  const cv::Size size(camera.width, camera.height);
  std::vector<MemberInKeyframe> out;
  for (size_t k = 0; k < track.members.size(); ++k) {
    const PlanePoint& m = track.members[k];
    if (plane.reference == reference) {
      if (Inside(m.keyframe_pixel, size, border)) out.push_back({k, m.keyframe_pixel, m.ray});
      continue;
    }
    const double rho = plane.plane.InverseDepthAlong(m.ray);
    if (rho <= 0) continue;
    const Eigen::Vector3d in_keyframe = keyframe_from_plane_ref * Eigen::Vector3d(m.ray / rho);
    if (in_keyframe.z() <= 0) continue;
    const Eigen::Vector2d pixel = camera.Project(in_keyframe);
    if (Inside(pixel, size, border)) out.push_back({k, pixel, in_keyframe.normalized()});
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector2d> PlanarPixelsInKeyframe(const Filter& filter, const Tracks& tracks, int reference,
                                                    const Camera& camera) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& [id, t] : tracks.planes) {
    if (t.out_of_view) continue;
    for (const MemberInKeyframe& m : MembersInKeyframe(filter, id, t, reference, camera, 0)) out.push_back(m.pixel);
  }
  return out;
}

namespace {

bool Valid(const DetectedPlane& p) {
  if (p.polygon.size() < 3 || !p.normal.allFinite() || p.normal.norm() < 1e-9) return false;
  return std::all_of(p.polygon.begin(), p.polygon.end(), [](const Eigen::Vector2d& q) { return q.allFinite(); });
}

// New corners inside `polygon`, at least min_distance from the keyframe's corners, appended to them.
void AddRegionCorners(const std::vector<cv::Point2f>& polygon, int count, const FeatureOptions& features,
                      Keyframe* keyframe) {
  if (count <= 0) return;
  cv::Mat region(keyframe->grey.size(), CV_8U, cv::Scalar(0));
  std::vector<cv::Point> outline;
  for (const cv::Point2f& q : polygon) outline.emplace_back(cvRound(q.x), cvRound(q.y));
  cv::fillPoly(region, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255));
  region &= InsideMask(region.size(), features.border);
  for (const Corner& c : keyframe->corners) {
    cv::circle(region, cv::Point(cvRound(c.pixel.x()), cvRound(c.pixel.y())), static_cast<int>(features.min_distance),
               cv::Scalar(0), cv::FILLED);
  }
  // Within the polygon's bounding box (with the corner detector's window of margin) only: a tenth of the cost.
  const cv::Rect box =
      (cv::boundingRect(outline) + cv::Size(8, 8) - cv::Point(4, 4)) & cv::Rect(cv::Point(), region.size());
  if (box.empty() || cv::countNonZero(region(box)) == 0) return;
  std::vector<cv::Point2f> found;
  cv::goodFeaturesToTrack(keyframe->grey(box), found, count, kCornerQuality, features.min_distance, region(box));
  for (const cv::Point2f& c : found) keyframe->corners.push_back({Eigen::Vector2d(c.x + box.x, c.y + box.y), false});
}

// The plane's inverse distance (keyframe frame) with unit normal n: from the keyframe's points inside the
// polygon, else the nearest one to the seed, else the default inverse depth at the seed (ray `seed_ray`).
double PlaneInverseDistance(const Filter& filter, const Tracks& tracks, int reference,
                            const std::vector<cv::Point2f>& polygon, const Eigen::Vector3d& n,
                            const Eigen::Vector2d& seed, const Eigen::Vector3d& seed_ray, double min_facing,
                            double default_inverse_depth) {
  std::vector<double> inside;
  double nearest_rho = default_inverse_depth, nearest = 1e18;
  for (const auto& [id, track] : tracks.points) {
    const Filter::Point& p = filter.points().at(id);
    if (p.reference != reference || p.inverse_depth <= 0) continue;
    const double facing = n.dot(p.ray);
    if (facing < -min_facing && InsidePolygon(polygon, track.keyframe_pixel))
      inside.push_back(-p.inverse_depth / facing);
    const double d = (track.keyframe_pixel - seed).squaredNorm();
    if (d < nearest) {
      nearest = d;
      nearest_rho = p.inverse_depth;
    }
  }
  if (inside.size() >= 3) {
    std::nth_element(inside.begin(), inside.begin() + inside.size() / 2, inside.end());
    return inside[inside.size() / 2];
  }
  return -nearest_rho / n.dot(seed_ray);
}

// The older plane (another reference camera's) that a detection in keyframe `reference` extends: the one with
// the most points inside the polygon, if at least max_mapped_points and half of those the keyframe sees, and a
// normal within max_extend_angle of the detected one. -1 if none.
int PlaneToExtend(const Filter& filter, const Tracks& tracks, int reference, const std::vector<cv::Point2f>& polygon,
                  const Eigen::Vector3d& normal, const Camera& camera, const PdvoOptions& o) {
  int best = -1, best_inside = 0;
  for (const auto& [id, t] : tracks.planes) {
    const Filter::Plane& plane = filter.planes().at(id);
    if (plane.reference == reference || t.out_of_view) continue;
    const std::vector<MemberInKeyframe> seen = MembersInKeyframe(filter, id, t, reference, camera, 0);
    const int inside = static_cast<int>(std::count_if(
        seen.begin(), seen.end(), [&](const MemberInKeyframe& m) { return InsidePolygon(polygon, m.pixel); }));
    if (inside < o.max_mapped_points || 2 * inside < static_cast<int>(seen.size()) || inside <= best_inside) continue;
    const Eigen::Vector3d seen_normal = filter.PlaneSeenFrom(id, reference).normal.normalized();
    if (seen_normal.dot(normal) < std::cos(o.max_extend_angle * M_PI / 180)) continue;
    best = id;
    best_inside = inside;
  }
  return best;
}

// The plane waiting out of view (PlaneTrack::out_of_view) that a detection in keyframe `reference` with unit
// normal `normal` carries on: the one whose normal, seen from the keyframe, is nearest the detected one, within
// max_extend_angle, and whose front the keyframe sees. -1 if none.
int WaitingPlaneFor(const Filter& filter, const Tracks& tracks, int reference, const Eigen::Vector3d& normal,
                    const PdvoOptions& o) {
  int best = -1;
  double best_cos = std::cos(o.max_extend_angle * M_PI / 180);
  for (const auto& [id, t] : tracks.planes) {
    if (!t.out_of_view) continue;
    const InversePlane seen = filter.PlaneSeenFrom(id, reference);
    const double c = seen.normal.normalized().dot(normal);
    if (seen.inverse_distance > 0 && c >= best_cos) {
      best = id;
      best_cos = c;
    }
  }
  return best;
}

// A detected plane's region in its keyframe: the keyframe's corners inside the polygon (after new ones are looked
// for), from which it grows, and the keyframe's points inside it, tracked since the keyframe: candidates at once.
void TakeRegion(const std::vector<cv::Point2f>& polygon, const DetectedPlane& detected, std::vector<int> region,
                int reference, int frame, const PdvoOptions& o, const Filter& filter, Tracks* tracks,
                std::set<int>* candidates, PlaneTrack* track) {
  track->detected = true;
  track->region_corners = std::move(region);
  track->outline = detected.polygon;
  const int age = frame - tracks->keyframes.at(reference).frame;
  for (const auto& [point, p] : tracks->points) {
    if (filter.points().at(point).reference == reference && !candidates->count(point) &&
        InsidePolygon(polygon, p.keyframe_pixel, o.region_margin)) {
      track->candidates.push_back({point, age});
      candidates->insert(point);
    }
  }
}

std::vector<int> RegionCorners(const std::vector<cv::Point2f>& polygon, const PdvoOptions& o,
                               const FeatureOptions& features, Keyframe* keyframe) {
  AddRegionCorners(polygon, o.region_corners, features, keyframe);
  std::vector<int> region;
  for (size_t i = 0; i < keyframe->corners.size(); ++i) {
    if (InsidePolygon(polygon, keyframe->corners[i].pixel, o.region_margin)) region.push_back(static_cast<int>(i));
  }
  return region;
}

// Plane `id` moves to keyframe `reference` (Filter::MovePlane): the map keeps it as it is (its extent so far),
// its points become rays and pixels of that keyframe (those it does not see at least `border` inside leave it
// and count as moved away), its candidates of the old keyframe stay points, and the keyframe goes if its
// reference camera has. False, and nothing changes, if the plane cannot move, or if the keyframe sees none of
// its points and it is not waiting out of view (a waiting plane moves to be seeded again).
bool MovePlaneToKeyframe(int id, int reference, const Camera& camera, int border, Filter* filter, Tracks* tracks,
                         MapRecord* record, std::set<int>* candidates) {
  PlaneTrack& track = tracks->planes.at(id);
  const std::vector<MemberInKeyframe> seen = MembersInKeyframe(*filter, id, track, reference, camera, border);
  if (seen.empty() && !track.out_of_view) return false;
  const int old_reference = filter->planes().at(id).reference;
  MapPlane so_far;
  const bool mapped = PlaneInWorld(*filter, id, track, record->min_plane_points(), &so_far);
  if (!filter->MovePlane(id, reference)) return false;
  record->Record(id, track);
  if (mapped) record->KeepPlane(so_far);
  track.moved_away += static_cast<int>(track.members.size() - seen.size());
  std::vector<PlanePoint> members;
  for (const MemberInKeyframe& m : seen) members.push_back({m.pixel, m.ray, track.members[m.member].history});
  track.members = std::move(members);
  for (const Candidate& c : track.candidates) candidates->erase(c.point);
  track.candidates.clear();
  if (!filter->references().count(old_reference)) tracks->keyframes.erase(old_reference);
  return true;
}

}  // namespace

SeedingOutcome SeedDetectedPlanes(const std::vector<DetectedPlane>& planes, int reference, int frame,
                                  const Camera& camera, const PdvoOptions& o, const FeatureOptions& features,
                                  double relative_prior_sigma, double default_inverse_depth, Filter* filter,
                                  Tracks* tracks, MapRecord* record) {
  Keyframe& keyframe = tracks->keyframes.at(reference);
  std::vector<Eigen::Vector2d> planar = PlanarPixelsInKeyframe(*filter, *tracks, reference, camera);
  std::set<int> candidates;  // points already waiting to join a plane
  for (const auto& [id, t] : tracks->planes) {
    for (const Candidate& c : t.candidates) candidates.insert(c.point);
  }
  SeedingOutcome out;
  // The valid detections, largest first.
  struct Outline {
    const DetectedPlane* plane;
    std::vector<cv::Point2f> polygon;
    cv::Moments moments;
  };
  std::vector<Outline> outlines;
  for (const DetectedPlane& detected : planes) {
    ++out.detected;
    Outline& q = outlines.emplace_back(Outline{&detected, {}, {}});
    for (const Eigen::Vector2d& v : detected.polygon) q.polygon.emplace_back(v.x(), v.y());
    if (Valid(detected)) q.moments = cv::moments(q.polygon);
    if (std::abs(q.moments.m00) < 1) {
      ++out.invalid;
      outlines.pop_back();
    } else if (std::abs(q.moments.m00) < o.min_area || detected.score < o.min_score) {
      ++out.small;
      outlines.pop_back();
    }
  }
  std::stable_sort(outlines.begin(), outlines.end(), [](const Outline& a, const Outline& b) {
    return std::abs(a.moments.m00) > std::abs(b.moments.m00);
  });
  for (const Outline& outline : outlines) {
    const DetectedPlane& detected = *outline.plane;
    const std::vector<cv::Point2f>& polygon = outline.polygon;
    const cv::Moments& m = outline.moments;
    const Eigen::Vector3d n = detected.normal.normalized();
    if (out.seeded + out.extended >= o.max_planes) {
      ++out.too_many;
      continue;
    }
    // An older plane whose points the polygon holds: it moves to this keyframe and grows in the polygon.
    const int older = PlaneToExtend(*filter, *tracks, reference, polygon, n, camera, o);
    if (older >= 0 &&
        MovePlaneToKeyframe(older, reference, camera, features.border, filter, tracks, record, &candidates)) {
      PlaneTrack& track = tracks->planes.at(older);
      TakeRegion(polygon, detected, RegionCorners(polygon, o, features, &keyframe), reference, frame, o, *filter,
                 tracks, &candidates, &track);
      ++out.extended;
      continue;
    }
    const Eigen::Vector2d centroid(m.m10 / m.m00, m.m01 / m.m00);
    const bool near = std::any_of(planar.begin(), planar.end(), [&](const Eigen::Vector2d& p) {
      return (p - centroid).norm() < o.min_plane_distance;
    });
    if (near) {
      ++out.near_plane;
      continue;
    }
    const long inside = std::count_if(planar.begin(), planar.end(),
                                      [&](const Eigen::Vector2d& p) { return InsidePolygon(polygon, p); });
    if (inside >= o.max_mapped_points) {
      ++out.mapped;
      continue;
    }
    std::vector<int> region = RegionCorners(polygon, o, features, &keyframe);
    Corner* seed = nullptr;
    for (int i : region) {
      Corner& c = keyframe.corners[i];
      if (!c.used && (!seed || (c.pixel - centroid).squaredNorm() < (seed->pixel - centroid).squaredNorm())) seed = &c;
    }
    if (!seed) {
      ++out.no_corner;
      continue;
    }
    const Eigen::Vector3d ray = camera.Ray(seed->pixel);
    if (n.dot(ray) > -o.min_facing) {
      ++out.grazing;
      continue;
    }
    // A plane waiting out of view with this orientation carries on here, from the seed, as a new plane would
    // (its growth starts again: plane_grow_frames to reach min_plane_points in this keyframe).
    int id = WaitingPlaneFor(*filter, *tracks, reference, n, o);
    if (id >= 0 && MovePlaneToKeyframe(id, reference, camera, features.border, filter, tracks, record, &candidates)) {
      tracks->planes.at(id).out_of_view = false;
      tracks->planes.at(id).age = 0;
      ++out.extended;
    } else {
      const double rho_p = PlaneInverseDistance(*filter, *tracks, reference, polygon, n, seed->pixel, ray, o.min_facing,
                                                default_inverse_depth);
      id = filter->AddPlane(reference, {n, rho_p}, o.normal_sigma, relative_prior_sigma * rho_p);
      ++out.seeded;
    }
    seed->used = true;
    PlaneTrack& track = tracks->planes[id];
    track.members.push_back({seed->pixel, ray, {}});
    TakeRegion(polygon, detected, std::move(region), reference, frame, o, *filter, tracks, &candidates, &track);
    planar.push_back(seed->pixel);
  }
  return out;
}

}  // namespace pdvo::vo
