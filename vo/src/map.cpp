#include "pdvo/vo/map.h"

#include <cmath>
#include <sstream>

#include "pdvo/common/file_io.h"

namespace pdvo::vo {

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
