#include "pdvo/vo/map.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pdvo/common/file_io.h"
#include "pdvo/vo/filter.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {
namespace {

// The members on the convex hull of their keyframe pixels, in order around it.
std::vector<int> Hull(const std::vector<PlanePoint>& members) {
  std::vector<cv::Point2f> pixels;
  for (const PlanePoint& m : members) pixels.emplace_back(m.keyframe_pixel.x(), m.keyframe_pixel.y());
  std::vector<int> hull;
  if (!pixels.empty()) cv::convexHull(pixels, hull);
  return hull;
}

}  // namespace

bool PointInWorld(const Filter& filter, int id, Eigen::Vector3d* x) {
  const Filter::Point& p = filter.points().at(id);
  const bool known = p.inverse_depth > 0 &&
                     std::sqrt(filter.covariance()(p.offset, p.offset)) < kMappedRelativeSigma * p.inverse_depth;
  if (!known) return false;
  *x = filter.references().at(p.reference).world_from_cam * (p.ray / p.inverse_depth);
  return true;
}

bool PlaneInWorld(const Filter& filter, int id, const PlaneTrack& t, int min_points, MapPlane* out) {
  if (static_cast<int>(t.members.size()) < min_points) return false;
  const Filter::Plane& plane = filter.planes().at(id);
  const Rigid3d& ref = filter.references().at(plane.reference).world_from_cam;
  out->polygon.clear();
  for (int k : Hull(t.members)) {
    const double rho = plane.plane.InverseDepthAlong(t.members[k].ray);
    if (rho <= 0) return false;
    out->polygon.push_back(ref * (t.members[k].ray / rho));
  }
  out->normal = ref.rotation * plane.plane.normal.normalized();
  return true;
}

double PlaneArea(const PlaneTrack& t) {
  std::vector<cv::Point2f> corners;
  for (int k : Hull(t.members)) corners.emplace_back(t.members[k].keyframe_pixel.x(), t.members[k].keyframe_pixel.y());
  return corners.size() < 3 ? 0.0 : cv::contourArea(corners);
}

void MapRecord::Record(int id, const PlaneTrack& t) {
  if (static_cast<int>(t.members.size()) < min_plane_points_) return;
  PlaneRecord& r = records_[{generation_, id}];
  r.points = std::max(r.points, static_cast<int>(t.members.size()));
  r.area = std::max(r.area, PlaneArea(t));
}

void MapRecord::KeepPoint(const Filter& filter, int id) {
  Eigen::Vector3d x;
  if (PointInWorld(filter, id, &x)) kept_.points.push_back(x);
}

void MapRecord::KeepPlane(const Filter& filter, int id, const PlaneTrack& track) {
  MapPlane plane;
  if (PlaneInWorld(filter, id, track, min_plane_points_, &plane)) kept_.planes.push_back(plane);
}

void MapRecord::KeepAll(const Filter& filter, const Tracks& tracks) {
  for (const auto& [id, t] : tracks.planes) Record(id, t);
  kept_.Append(CurrentMap(filter, tracks, min_plane_points_));
}

MappingStats MapRecord::stats() const {
  MappingStats m;
  for (const auto& [id, r] : records_) {
    ++m.planes;
    m.points_per_plane += r.points;
    m.mean_plane_area += r.area;
  }
  if (m.planes > 0) {
    m.points_per_plane /= m.planes;
    m.mean_plane_area /= m.planes;
  }
  return m;
}

Map CurrentMap(const Filter& filter, const Tracks& tracks, int min_plane_points) {
  Map m;
  Eigen::Vector3d x;
  for (const auto& [id, p] : filter.points()) {
    if (PointInWorld(filter, id, &x)) m.points.push_back(x);
  }
  MapPlane plane;
  for (const auto& [id, t] : tracks.planes) {
    if (PlaneInWorld(filter, id, t, min_plane_points, &plane)) m.planes.push_back(plane);
  }
  return m;
}

void WritePly(const std::string& path, const Map& map, const Trajectory& camera_path) {
  size_t plane_vertices = 0;
  for (const MapPlane& p : map.planes) plane_vertices += p.polygon.size();
  const size_t vertices = map.points.size() + plane_vertices + camera_path.size();
  const size_t edges = camera_path.empty() ? 0 : camera_path.size() - 1;
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment pdvo vo map: points, planes (faces), camera path (edges)\n"
      << "element vertex " << vertices << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "element face " << map.planes.size() << "\nproperty list uchar int vertex_indices\n"
      << "element edge " << edges << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  auto vertex = [&](const Eigen::Vector3d& x, int r, int g, int b) {
    out << x.x() << " " << x.y() << " " << x.z() << " " << r << " " << g << " " << b << "\n";
  };
  for (const Eigen::Vector3d& x : map.points) vertex(x, 200, 200, 200);
  for (const MapPlane& p : map.planes) {
    const Eigen::Vector3d c = 127.5 * (p.normal + Eigen::Vector3d::Ones());  // the usual normal-map colours
    for (const Eigen::Vector3d& x : p.polygon) {
      vertex(x, static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())),
             static_cast<int>(std::lround(c.z())));
    }
  }
  for (const StampedPose& pose : camera_path) vertex(pose.world_from_cam.translation, 255, 0, 0);
  size_t next = map.points.size();
  for (const MapPlane& p : map.planes) {
    out << p.polygon.size();
    for (size_t k = 0; k < p.polygon.size(); ++k) out << " " << next + k;
    out << "\n";
    next += p.polygon.size();
  }
  for (size_t k = 0; k < edges; ++k) out << next + k << " " << next + k + 1 << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace pdvo::vo
