#include "pdvo/vo/plane_growing.h"

#include <cmath>

#include "pdvo/common/options.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {

bool PlaneOptions::Check() const {
  PDVO_CHECK_OPTION(max_new_planes >= 0 && grow_radius > 0 && new_plane_points >= 1);
  PDVO_CHECK_OPTION(candidate_frames >= 1 && plane_grow_frames >= 1 && min_plane_points >= 3);
  PDVO_CHECK_OPTION(plane_sigma_normal > 0 && planarity > 0 && join_gate > 0 && known_inverse_depth > 0);
  return true;
}

bool KnownForPlaneTest(const Filter& filter, const Filter::Point& p, double share) {
  const double sigma = std::sqrt(filter.covariance()(p.offset, p.offset));
  return p.inverse_depth > 0 && sigma < share * p.inverse_depth;
}

double InverseDepthVariance(const Filter& filter, const Filter::Plane& plane, const Eigen::Vector3d& ray) {
  const Eigen::RowVector4d j = plane.plane.InverseDepthJacobian(ray);
  return (j * filter.covariance().block<4, 4>(plane.offset, plane.offset) * j.transpose())(0, 0);
}

bool PassesPlaneTest(const Filter& filter, int point, int plane_id, double gate, double* on_plane) {
  const Filter::Point& p = filter.points().at(point);
  const Filter::Plane& plane = filter.planes().at(plane_id);
  if (p.reference != plane.reference) return false;
  const double variance = filter.covariance()(p.offset, p.offset);
  const double rho = plane.plane.InverseDepthAlong(p.ray);
  const double plane_variance = InverseDepthVariance(filter, plane, p.ray);
  if (on_plane) *on_plane = rho;
  return rho > 0 && std::abs(p.inverse_depth - rho) < gate * std::sqrt(variance + plane_variance);
}

PlaneGrower::PlaneGrower(const Camera& camera, const PlaneOptions& planes, const DetectedGrowth& detected,
                         const FeatureOptions& features, double relative_prior_sigma)
    : camera_(camera),
      o_(planes),
      detected_(detected),
      features_(features),
      relative_prior_sigma_(relative_prior_sigma) {}

void PlaneGrower::Grow(Filter* filter, Tracks* tracks, MapRecord* record) const {
  std::vector<int> to_points, empty;
  for (auto& [id, t] : tracks->planes) {
    if (t.out_of_view) continue;  // it waits for the next detection (plane_priors.h)
    ++t.age;
    std::erase_if(t.members, [&](const PlanePoint& m) { return Tracks::Gone(m.history, features_); });
    if (t.members.empty()) {
      empty.push_back(id);
      continue;
    }
    std::vector<Candidate> waiting;
    const double known = t.detected ? detected_.known_inverse_depth : o_.known_inverse_depth;
    for (Candidate& c : t.candidates) {
      if (!filter->points().count(c.point)) continue;  // left the view or was lost
      ++c.age;
      if (!KnownForPlaneTest(*filter, filter->points().at(c.point), known) || c.age < o_.candidate_frames) {
        if (c.age < o_.plane_grow_frames) waiting.push_back(c);
        continue;  // otherwise it stays an ordinary point
      }
      double on_plane = 0;
      if (!PassesPlaneTest(*filter, c.point, id, o_.join_gate, &on_plane)) continue;
      const PointTrack& track = tracks->points.at(c.point);
      const PlanePoint joined{track.keyframe_pixel, filter->points().at(c.point).ray, track.history};
      if (filter->MergePointIntoPlane(c.point, id, o_.planarity * on_plane) != UpdateStatus::kOk) continue;
      tracks->points.erase(c.point);
      t.members.push_back(joined);
    }
    t.candidates = std::move(waiting);
    AddCandidates(id, filter, tracks);
    record->Record(id, t);
    if (t.age >= o_.plane_grow_frames && static_cast<int>(t.members.size()) < o_.min_plane_points) {
      to_points.push_back(id);
    }
  }
  for (int id : empty) tracks->RemovePlane(id, filter, record);
  // A plane that did grow and has lost its members (most left the view) stays in the record.
  for (int id : to_points) {
    const PlanePoint seed = tracks->planes.at(id).members.front();
    tracks->planes.erase(id);
    tracks->points[filter->PlaneToPoint(id, seed.ray)] = {seed.keyframe_pixel, {}};
  }
}

void PlaneGrower::AddCandidates(int id, Filter* filter, Tracks* tracks) const {
  const Filter::Plane& plane = filter->planes().at(id);
  PlaneTrack& t = tracks->planes.at(id);
  std::vector<Corner>& corners = tracks->keyframes.at(plane.reference).corners;
  const int wanted = t.detected ? detected_.new_points : o_.new_plane_points;
  const size_t count = t.detected ? t.region_corners.size() : corners.size();
  int added = 0;
  for (size_t i = 0; i < count && added < wanted; ++i) {
    Corner& corner = corners.at(t.detected ? t.region_corners[i] : i);
    if (corner.used) continue;
    double nearest = 1e9;
    for (const PlanePoint& m : t.members) nearest = std::min(nearest, (m.keyframe_pixel - corner.pixel).norm());
    if ((!t.detected && nearest > o_.grow_radius) || nearest < features_.min_distance) continue;
    const Eigen::Vector3d ray = camera_.Ray(corner.pixel);
    const double rho = plane.plane.InverseDepthAlong(ray);
    if (rho <= 0) continue;
    corner.used = true;
    const int point = filter->AddPoint(plane.reference, ray, rho, relative_prior_sigma_ * rho);
    tracks->points[point] = {corner.pixel, {}};
    t.candidates.push_back({point, 0});
    ++added;
  }
}

}  // namespace pdvo::vo
