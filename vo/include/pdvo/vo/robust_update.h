// The robust EKF update (1-point RANSAC, Civera et al. 2010, as in the paper's section IV): each hypothesis is
// the state after an update with one measurement, drawn at random; the hypothesis that brings most of the other
// measurements within `threshold` px of their match gives the inliers, which update the filter; then every other
// measurement whose innovation after that update lies inside the 99% gate of its covariance is used too (the
// rescue). Hypotheses move only the state's mean (Filter::Step), never a copy of the covariance.
#pragma once

#include <random>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/vo/filter.h"

namespace pdvo::vo {

struct RansacOptions {
  int hypotheses = 30;   // drawn per frame (at most one per measurement)
  double threshold = 1;  // px: a match agrees with a hypothesis within this distance of its prediction

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("hypotheses", self.hypotheses);
    visit("threshold", self.threshold);
  }
  bool Check() const;
  bool operator==(const RansacOptions&) const = default;
};

// The rescue's gate on a measurement's normalised innovation squared: chi-square with 2 degrees of freedom, 99%.
inline constexpr double kRescueGate = 9.21;

struct RobustUpdateResult {
  std::vector<bool> used;  // per measurement: it updated the filter (an inlier, or rescued)
  int inliers = 0;         // of the best hypothesis
  int rescued = 0;
  // The inliers' update; kNoMeasurements also when no hypothesis had an inlier. When not kOk, the filter is as
  // it was and no measurement is used.
  UpdateStatus status = UpdateStatus::kNoMeasurements;
};

// Updates `filter` robustly with `measurements` (their features must be in the filter); `rng` draws the
// hypotheses (the same generator state and input give the same result).
RobustUpdateResult UpdateRobustly(const Camera& camera, const RansacOptions& options,
                                  const std::vector<PointMeasurement>& measurements, std::mt19937* rng, Filter* filter);

}  // namespace pdvo::vo
