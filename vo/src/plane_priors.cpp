#include "pdvo/vo/plane_priors.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>

#include "pdvo/common/options.h"

namespace pdvo::vo {

bool PdvoOptions::Check() const {
  PDVO_CHECK_OPTION(delay_frames >= 1 && timeout_seconds > 0 && min_plane_distance >= 0 && min_area >= 0);
  PDVO_CHECK_OPTION(normal_sigma > 0 && new_plane_points >= 1 && region_corners >= 0);
  PDVO_CHECK_OPTION(min_facing > 0 && min_facing < 1);
  return true;
}

std::vector<Eigen::Vector2d> PlanarPixelsInKeyframe(const Filter& filter, const Tracks& tracks, int reference,
                                                    const Camera& camera) {
  const Rigid3d keyframe_from_world = filter.references().at(reference).world_from_cam.Inverse();
  std::vector<Eigen::Vector2d> out;
  for (const auto& [id, t] : tracks.planes) {
    const Filter::Plane& plane = filter.planes().at(id);
    const Rigid3d& world_from_plane_ref = filter.references().at(plane.reference).world_from_cam;
    for (const PlanePoint& m : t.members) {
      if (plane.reference == reference) {
        out.push_back(m.keyframe_pixel);
        continue;
      }
      const double rho = plane.plane.InverseDepthAlong(m.ray);
      if (rho <= 0) continue;
      const Eigen::Vector3d in_keyframe = keyframe_from_world * (world_from_plane_ref * Eigen::Vector3d(m.ray / rho));
      if (in_keyframe.z() <= 0) continue;
      const Eigen::Vector2d pixel = camera.Project(in_keyframe);
      if (Inside(pixel, cv::Size(camera.width, camera.height), 0)) out.push_back(pixel);
    }
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

}  // namespace

SeedingOutcome SeedDetectedPlanes(const std::vector<DetectedPlane>& planes, int reference, int frame,
                                  const Camera& camera, const PdvoOptions& o, const FeatureOptions& features,
                                  double relative_prior_sigma, double default_inverse_depth, Filter* filter,
                                  Tracks* tracks) {
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
    if (out.seeded >= o.max_planes) {
      ++out.too_many;
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
    AddRegionCorners(polygon, o.region_corners, features, &keyframe);
    std::vector<int> region;  // the keyframe's corners inside the polygon
    Corner* seed = nullptr;
    for (size_t i = 0; i < keyframe.corners.size(); ++i) {
      Corner& c = keyframe.corners[i];
      if (!InsidePolygon(polygon, c.pixel, o.region_margin)) continue;
      region.push_back(static_cast<int>(i));
      if (!c.used && (!seed || (c.pixel - centroid).squaredNorm() < (seed->pixel - centroid).squaredNorm())) seed = &c;
    }
    if (!seed) {
      ++out.no_corner;
      continue;
    }
    const Eigen::Vector3d n = detected.normal.normalized();
    const Eigen::Vector3d ray = camera.Ray(seed->pixel);
    if (n.dot(ray) > -o.min_facing) {
      ++out.grazing;
      continue;
    }
    const double rho_p = PlaneInverseDistance(*filter, *tracks, reference, polygon, n, seed->pixel, ray, o.min_facing,
                                              default_inverse_depth);
    seed->used = true;
    const int id = filter->AddPlane(reference, {n, rho_p}, o.normal_sigma, relative_prior_sigma * rho_p);
    PlaneTrack& track = tracks->planes[id];
    track.members.push_back({seed->pixel, ray, {}});
    track.detected = true;
    track.region_corners = std::move(region);
    track.outline = detected.polygon;
    track.new_points = o.new_plane_points;
    // The keyframe's points inside the polygon have been tracked since the keyframe: candidates at once.
    for (const auto& [point, p] : tracks->points) {
      if (filter->points().at(point).reference == reference && !candidates.count(point) &&
          InsidePolygon(polygon, p.keyframe_pixel, o.region_margin)) {
        track.candidates.push_back({point, frame - keyframe.frame});
        candidates.insert(point);
      }
    }
    planar.push_back(seed->pixel);
    ++out.seeded;
  }
  return out;
}

}  // namespace pdvo::vo
