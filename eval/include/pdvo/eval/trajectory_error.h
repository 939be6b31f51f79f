// Trajectory accuracy: absolute trajectory error (ATE) after alignment, and relative pose error (RPE).
//
// Estimated poses are associated with ground-truth poses by timestamp: each pair is at most `max_dt` apart
// and no pose is used twice (greedily, closest pairs first). The estimate is then aligned to the ground truth
// by Umeyama's method on the positions (Eigen::umeyama): a rigid motion (se3), a similarity (sim3, for
// monocular estimates whose scale is unknown) or nothing (none). ATE is the distance between aligned
// positions; its rotation part, the angle between orientations after the rotation that best aligns the
// orientations (with se3 or sim3; along a nearly straight path the positions alone leave the rotation about it
// to their wobble); RPE compares the motion between two poses `delta` frames or seconds apart, after scaling the
// estimate by the alignment's scale.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pdvo/common/geometry.h"
#include "pdvo/common/trajectory.h"

namespace pdvo {

enum class Alignment { kNone, kSE3, kSim3 };
// "none", "se3" or "sim3"; throws InvalidArgument otherwise.
Alignment ParseAlignment(const std::string& name);

// Pairs (ground-truth index, estimate index), in the estimate's order.
std::vector<std::pair<size_t, size_t>> AssociateByTime(const Trajectory& ground_truth, const Trajectory& estimate,
                                                       double max_dt);

// The similarity that maps `source` points onto `target` points in the least-squares sense (scale fixed to 1
// unless `with_scale`). Throws InvalidArgument for fewer than 3 points or points that do not spread.
Sim3d AlignPoints(const std::vector<Eigen::Vector3d>& source, const std::vector<Eigen::Vector3d>& target,
                  bool with_scale);

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
};
ErrorStats ComputeStats(const std::vector<double>& errors);

struct AteResult {
  size_t matched = 0;       // associated pose pairs
  Sim3d gt_from_estimate;   // the alignment applied to the estimate
  ErrorStats translation;   // metres (ground-truth units)
  ErrorStats rotation_deg;  // orientation error after the orientations' own alignment, degrees
};

// Throws InvalidArgument if fewer than 3 poses associate (1 for "none").
AteResult ComputeAte(const Trajectory& ground_truth, const Trajectory& estimate, Alignment alignment, double max_dt);

enum class RpeUnit { kFrames, kSeconds };
struct RpeResult {
  size_t pairs = 0;
  double delta = 1;
  RpeUnit unit = RpeUnit::kFrames;
  ErrorStats translation;   // ground-truth units
  ErrorStats rotation_deg;  // degrees
};

// RPE over associated poses `delta` apart (frames of the associated sequence, or seconds). The estimate's
// translations are multiplied by `scale` (the ATE alignment's scale for monocular runs).
RpeResult ComputeRpe(const Trajectory& ground_truth, const Trajectory& estimate, double max_dt, double delta,
                     RpeUnit unit, double scale);

nlohmann::json ToJson(const AteResult& ate);
nlohmann::json ToJson(const RpeResult& rpe);

}  // namespace pdvo
