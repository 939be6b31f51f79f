// What the visual odometry mapped: points whose inverse depth was known to 30% and planes (as the polygon of
// their points, in the world), kept when they leave the filter; and writing it with the camera path as PLY.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pdvo/common/trajectory.h"

namespace pdvo::vo {

struct MapPlane {
  std::vector<Eigen::Vector3d> polygon;  // world, in order around the plane's points' convex hull
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // world, unit
};

struct Map {
  std::vector<Eigen::Vector3d> points;  // world
  std::vector<MapPlane> planes;

  void Append(const Map& other) {
    points.insert(points.end(), other.points.begin(), other.points.end());
    planes.insert(planes.end(), other.planes.begin(), other.planes.end());
  }
};

// ASCII PLY: vertices (x y z and an RGB colour: points grey, plane corners coloured by their normal, camera
// positions red), one face per plane polygon, and one edge per step of the camera path. Written atomically.
void WritePly(const std::string& path, const Map& map, const Trajectory& camera_path);

}  // namespace pdvo::vo
