// Statistics of directions on the unit sphere (the detector's normals, the paper's section III): a robust
// weighted mean, and the modes of a weighted set of directions by mean shift with a von Mises-Fisher kernel.
// Directions are unit 3-vectors; angles are in degrees.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pdvo {

// The direction minimising a Cauchy loss of the angles to `directions` with scale `scale_deg`, each weighted by
// `weights` (>= 0): iteratively reweighted means, started from the weighted mean. Zero if the weights sum to
// zero or the mean vanishes (directions that cancel).
Eigen::Vector3d RobustMeanDirection(const std::vector<Eigen::Vector3d>& directions, const std::vector<double>& weights,
                                    double scale_deg);

struct DirectionMode {
  Eigen::Vector3d direction;  // unit
  double support = 0;         // the weight of the directions nearest to it
};
// The modes of the weighted directions: mean shift with the kernel exp((cos(angle) - 1) / bandwidth^2) (cut off
// beyond three bandwidths), started
// from every direction (or, of more than `max_starts`, from as many spread evenly through the list), modes
// within `merge_deg` merged; ordered by support, largest first. Deterministic.
std::vector<DirectionMode> MeanShiftModes(const std::vector<Eigen::Vector3d>& directions,
                                          const std::vector<double>& weights, double bandwidth_deg, double merge_deg,
                                          int max_starts = 32);

}  // namespace pdvo
