#include "pdvo/vo/tracks.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/options.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {

bool FeatureOptions::Check() const {
  PDVO_CHECK_OPTION(max_measurements >= 1 && min_features >= 1 && new_features >= 1 && min_distance >= 1);
  PDVO_CHECK_OPTION(max_waiting >= 0);
  PDVO_CHECK_OPTION(border >= 1 && max_misses >= 1 && min_rejections >= 1 && max_rejected_share >= 0);
  return true;
}

bool Inside(const Eigen::Vector2d& p, const cv::Size& size, int border) {
  return p.x() >= border && p.y() >= border && p.x() < size.width - border && p.y() < size.height - border;
}

bool InsidePolygon(const std::vector<cv::Point2f>& polygon, const Eigen::Vector2d& p, double margin) {
  return cv::pointPolygonTest(polygon, cv::Point2f(p.x(), p.y()), margin > 0) >= margin;
}

cv::Mat InsideMask(const cv::Size& size, int border) {
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  mask(cv::Rect(border, border, size.width - 2 * border, size.height - 2 * border)).setTo(255);
  return mask;
}

bool Tracks::Gone(const History& r, const FeatureOptions& o) {
  return r.misses > o.max_misses || (r.rejected >= o.min_rejections && r.rejected > o.max_rejected_share * r.matched);
}

std::vector<Eigen::Vector2d> Tracks::Visible(const Filter& filter, const Camera& camera, int border) const {
  const cv::Size size(camera.width, camera.height);
  std::vector<Eigen::Vector2d> out;
  Eigen::Vector2d pixel;
  for (const auto& [id, p] : filter.points()) {
    if (filter.PredictPoint(camera, id, &pixel, nullptr) && Inside(pixel, size, border)) out.push_back(pixel);
  }
  for (const auto& [id, t] : planes) {
    for (const PlanePoint& m : t.members) {
      if (filter.PredictPlanePoint(camera, id, m.ray, &pixel, nullptr) && Inside(pixel, size, border)) {
        out.push_back(pixel);
      }
    }
  }
  return out;
}

int Tracks::PlanePoints() const {
  int n = 0;
  for (const auto& [id, t] : planes) n += static_cast<int>(t.members.size());
  return n;
}

void Tracks::RemovePoints(const std::vector<int>& ids, Filter* filter, MapRecord* record) {
  std::vector<int> references;
  for (int id : ids) {
    record->KeepPoint(*filter, id);
    references.push_back(filter->points().at(id).reference);
  }
  filter->RemovePoints(ids);
  for (int id : ids) points.erase(id);
  for (int reference : references) {
    if (!filter->references().count(reference)) keyframes.erase(reference);
  }
}

void Tracks::RemovePlane(int id, Filter* filter, MapRecord* record) {
  record->KeepPlane(*filter, id, planes.at(id));
  const int reference = filter->planes().at(id).reference;
  filter->RemovePlane(id);
  planes.erase(id);
  if (!filter->references().count(reference)) keyframes.erase(reference);
}

void Tracks::LeaveView(const Camera& camera, const FeatureOptions& options, Filter* filter, MapRecord* record) {
  const cv::Size size(camera.width, camera.height);
  const int border = options.border;
  Eigen::Vector2d pixel;
  std::vector<int> gone, waiting_points, waiting_planes;
  for (const auto& [id, p] : filter->points()) {
    if (!filter->PredictPoint(camera, id, &pixel, nullptr)) {
      gone.push_back(id);
    } else if (!Inside(pixel, size, border)) {
      waiting_points.push_back(id);
    }
  }
  // Beyond max_waiting, the oldest points (ids grow with time) leave first.
  for (size_t k = 0; k + options.max_waiting < waiting_points.size(); ++k) gone.push_back(waiting_points[k]);
  RemovePoints(gone, filter, record);
  gone.clear();
  for (auto& [id, t] : planes) {
    const bool any = std::any_of(t.members.begin(), t.members.end(), [&, id = id](const PlanePoint& m) {
      return filter->PredictPlanePoint(camera, id, m.ray, &pixel, nullptr) && Inside(pixel, size, border);
    });
    if (!any && !t.out_of_view) record->Record(id, t);  // as it leaves, or as it starts to wait (then unchanged)
    t.out_of_view =
        !any && t.detected && static_cast<int>(t.members.size()) + t.moved_away >= record->min_plane_points();
    if (t.out_of_view) {
      waiting_planes.push_back(id);
    } else if (!any) {
      gone.push_back(id);
    }
  }
  // Beyond kMaxOutOfViewPlanes, the oldest planes (ids grow with time) leave first.
  for (size_t k = 0; k + kMaxOutOfViewPlanes < waiting_planes.size(); ++k) gone.push_back(waiting_planes[k]);
  for (int id : gone) RemovePlane(id, filter, record);
}

void Tracks::RemoveOutOfView(Filter* filter, MapRecord* record) {
  std::vector<int> gone;
  for (const auto& [id, t] : planes) {
    if (t.out_of_view) gone.push_back(id);
  }
  for (int id : gone) RemovePlane(id, filter, record);
}

void Tracks::LeaveRejected(const FeatureOptions& options, Filter* filter, MapRecord* record) {
  std::vector<int> bad;
  for (const auto& [id, t] : points) {
    if (Gone(t.history, options)) bad.push_back(id);
  }
  RemovePoints(bad, filter, record);
}

}  // namespace pdvo::vo
