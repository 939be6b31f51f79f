// A plane found in one image, as the odometry takes it: the one type between whatever finds planes (the detector
// of infer/, a folder of annotations, a synthetic street's truth) and the odometry that maps them (vo/).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pdvo {

struct DetectedPlane {
  std::vector<Eigen::Vector2d> polygon;              // the plane's outline, pixels of the image it was found in
  std::vector<Eigen::Vector2d> points;               // its salient points, same pixels (may be empty)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, that image's camera frame, towards the camera
  double score = 1;                                  // confidence in [0, 1]
};

}  // namespace pdvo
