// Trajectories: timestamped camera poses, read and written in TUM and KITTI formats.
//
// Poses are world_from_cam (the camera's position and orientation in the world), as both formats store them.
// TUM: one line per pose, `t tx ty tz qx qy qz qw`, '#' starts a comment.
// KITTI: one line per pose, the 12 numbers of the 3x4 matrix [R | t] row by row; no timestamps (the pose
// index is used, or a times file with one time per line).
// Reading checks: at least one pose, a finite value in every field, a non-zero quaternion, strictly
// increasing timestamps. Errors name the file and the line.
#pragma once

#include <string>
#include <vector>

#include "pdvo/common/geometry.h"

namespace pdvo {

struct StampedPose {
  double timestamp = 0;  // seconds
  Rigid3d world_from_cam;
};
using Trajectory = std::vector<StampedPose>;

enum class TrajectoryFormat { kTum, kKitti };

// "tum" or "kitti"; throws InvalidArgument otherwise.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);

// Reads a trajectory. For KITTI, `times_path` (optional) gives the timestamps; it must have one line per pose.
Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format, const std::string& times_path = "");
// Reads one time per line (KITTI times.txt); throws on a bad line or non-increasing times.
std::vector<double> ReadTimes(const std::string& path);
// Writes atomically. KITTI drops the timestamps.
void WriteTrajectory(const std::string& path, const Trajectory& trajectory, TrajectoryFormat format);

// Total distance travelled along the positions, in the trajectory's units.
double PathLength(const Trajectory& trajectory);

}  // namespace pdvo
