#include "pdvo/vo/map.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pdvo/common/errors.h"
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
  out->plane = id;
  return true;
}

std::vector<Eigen::Vector2d> PlaneHull(const PlaneTrack& t) {
  std::vector<Eigen::Vector2d> hull;
  for (int k : Hull(t.members)) hull.push_back(t.members[k].keyframe_pixel);
  return hull;
}

double PlaneArea(const PlaneTrack& t) {
  std::vector<cv::Point2f> corners;
  for (const Eigen::Vector2d& q : PlaneHull(t)) corners.emplace_back(q.x(), q.y());
  return corners.size() < 3 ? 0.0 : cv::contourArea(corners);
}

void MapRecord::NewFilter() {
  ++generation_;
  kept_points_before_ = kept_.points.size();
  kept_planes_before_ = kept_.planes.size();
}

void MapRecord::DiscardFilter() {
  std::erase_if(records_, [&](const auto& r) { return r.first.first == generation_; });
  kept_.points.resize(kept_points_before_);
  kept_.planes.resize(kept_planes_before_);
}

void MapRecord::Record(int id, const PlaneTrack& t) {
  const int points = static_cast<int>(t.members.size()) + t.moved_away;
  if (points < min_plane_points_) return;
  PlaneRecord& r = records_[{generation_, id}];
  r.points = std::max(r.points, points);
  r.area = std::max(r.area, PlaneArea(t));
}

void MapRecord::KeepPoint(const Filter& filter, int id) {
  Eigen::Vector3d x;
  if (PointInWorld(filter, id, &x)) kept_.points.push_back(x);
}

void MapRecord::KeepPlane(const Filter& filter, int id, const PlaneTrack& track) {
  MapPlane plane;
  if (PlaneInWorld(filter, id, track, min_plane_points_, &plane)) KeepPlane(plane);
}

void MapRecord::KeepPlane(MapPlane plane) {
  plane.filter = generation_;
  kept_.planes.push_back(std::move(plane));
}

void MapRecord::KeepAll(const Filter& filter, const Tracks& tracks) {
  for (const auto& [id, t] : tracks.planes) Record(id, t);
  kept_.Append(CurrentMap(filter, tracks, min_plane_points_, generation_));
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

void MeasurementCurve::Add(int frame, int keyframe, int plane, const Eigen::Vector2d& keyframe_pixel, bool used) {
  Counts& c = planes_[{keyframe, plane}];
  c.members.insert({cvRound(keyframe_pixel.x()), cvRound(keyframe_pixel.y())});
  const int age = frame - keyframe;
  if (!used || age < 0 || age >= frames_) return;
  if (c.used.empty()) c.used.assign(frames_, 0);
  ++c.used[age];
}

std::vector<double> MeasurementCurve::Mean() const {
  std::vector<double> mean(frames_, 0.0);
  int planes = 0;
  for (const auto& [key, c] : planes_) {
    if (c.used.empty() || static_cast<int>(c.members.size()) < min_plane_points_) continue;
    ++planes;
    for (int a = 0; a < frames_; ++a) mean[a] += c.used[a];
  }
  for (double& m : mean) m /= std::max(1, planes);
  return mean;
}

Map CurrentMap(const Filter& filter, const Tracks& tracks, int min_plane_points, int filter_number) {
  Map m;
  Eigen::Vector3d x;
  for (const auto& [id, p] : filter.points()) {
    if (PointInWorld(filter, id, &x)) m.points.push_back(x);
  }
  MapPlane plane;
  for (const auto& [id, t] : tracks.planes) {
    if (PlaneInWorld(filter, id, t, min_plane_points, &plane)) {
      plane.filter = filter_number;
      m.planes.push_back(plane);
    }
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
      << "property int filter\nproperty int plane\n"
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
    out << " " << p.filter << " " << p.plane << "\n";
    next += p.polygon.size();
  }
  for (size_t k = 0; k < edges; ++k) out << next + k << " " << next + k + 1 << "\n";
  WriteFileAtomically(path, out.str());
}

Map ReadPly(const std::string& path, std::vector<Eigen::Vector3d>* camera_path) {
  std::istringstream in(ReadFile(path));
  std::string line, word;
  size_t vertices = 0, faces = 0, edges = 0;
  bool numbered = false;  // faces carry their filter and plane numbers
  PDVO_THROW_CHECK(std::getline(in, line) && line == "ply", FormatError, path << ": not a PLY file");
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream header(line);
    std::string kind;
    size_t count = 0;
    if (header >> word >> kind >> count && word == "element") {
      (kind == "vertex" ? vertices : kind == "face" ? faces : edges) = count;
    } else if (line == "property int plane") {
      numbered = true;
    } else if (line.rfind("format", 0) == 0) {
      PDVO_THROW_CHECK(line == "format ascii 1.0", FormatError, path << ": not an ASCII PLY file");
    }
  }
  PDVO_THROW_CHECK(in, FormatError, path << ": no end_header");
  struct Vertex {
    Eigen::Vector3d x;
    Eigen::Vector3i rgb;
  };
  std::vector<Vertex> v(vertices);
  for (Vertex& p : v) {
    PDVO_THROW_CHECK(in >> p.x.x() >> p.x.y() >> p.x.z() >> p.rgb.x() >> p.rgb.y() >> p.rgb.z() && p.x.allFinite(),
                     FormatError, path << ": a vertex is malformed or missing (" << vertices << " declared)");
  }
  Map map;
  std::vector<bool> in_face(vertices, false);
  for (size_t f = 0; f < faces; ++f) {
    size_t n = 0;
    PDVO_THROW_CHECK(in >> n && n >= 3, FormatError, path << ": face " << f << " is malformed");
    MapPlane& plane = map.planes.emplace_back();
    for (size_t k = 0; k < n; ++k) {
      size_t i = 0;
      PDVO_THROW_CHECK(in >> i && i < vertices, FormatError, path << ": face " << f << " is malformed");
      plane.polygon.push_back(v[i].x);
      in_face[i] = true;
      if (k == 0) plane.normal = (v[i].rgb.cast<double>() / 127.5 - Eigen::Vector3d::Ones()).normalized();
    }
    PDVO_THROW_CHECK(!numbered || in >> plane.filter >> plane.plane, FormatError,
                     path << ": face " << f << " is malformed");
  }
  // The camera path comes last: the vertices of its edges, or a single red one.
  size_t cameras = edges > 0 ? edges + 1 : 0;
  if (edges == 0 && vertices > 0 && !in_face.back() && v.back().rgb == Eigen::Vector3i(255, 0, 0)) cameras = 1;
  PDVO_THROW_CHECK(cameras <= vertices, FormatError, path << ": more path edges than vertices");
  camera_path->clear();
  for (size_t i = vertices - cameras; i < vertices; ++i) camera_path->push_back(v[i].x);
  for (size_t i = 0; i < vertices - cameras; ++i) {
    if (!in_face[i]) map.points.push_back(v[i].x);
  }
  return map;
}

}  // namespace pdvo::vo
