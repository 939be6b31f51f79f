#include "pdvo/infer/sphere.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

constexpr double kDegree = M_PI / 180;
constexpr int kIterations = 50;
constexpr double kConverged = 1e-7;  // change of the direction (radians) at which an iteration stops

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)); }

void CheckInput(const std::vector<Eigen::Vector3d>& directions, const std::vector<double>& weights, double scale) {
  PDVO_THROW_CHECK(directions.size() == weights.size() && scale > 0, InvalidArgument,
                   "directions: " << directions.size() << " directions with " << weights.size()
                                  << " weights, or a scale that is not positive");
  for (size_t i = 0; i < weights.size(); ++i) {
    PDVO_THROW_CHECK(weights[i] >= 0 && std::isfinite(weights[i]) && directions[i].allFinite(), InvalidArgument,
                     "directions: a bad weight or direction at " << i);
  }
}

}  // namespace

Eigen::Vector3d RobustMeanDirection(const std::vector<Eigen::Vector3d>& d, const std::vector<double>& w,
                                    double scale_deg) {
  CheckInput(d, w, scale_deg);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < d.size(); ++i) sum += w[i] * d[i];
  if (sum.norm() < 1e-12) return Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = sum.normalized();
  const double scale = scale_deg * kDegree;
  for (int k = 0; k < kIterations; ++k) {
    sum.setZero();
    for (size_t i = 0; i < d.size(); ++i) {
      const double r = Angle(mean, d[i]) / scale;
      sum += w[i] / (1 + r * r) * d[i];
    }
    if (sum.norm() < 1e-12) break;
    const Eigen::Vector3d next = sum.normalized();
    const double change = Angle(next, mean);
    mean = next;
    if (change < kConverged) break;
  }
  return mean;
}

std::vector<DirectionMode> MeanShiftModes(const std::vector<Eigen::Vector3d>& d, const std::vector<double>& w,
                                          double bandwidth_deg, double merge_deg, int max_starts) {
  CheckInput(d, w, bandwidth_deg);
  PDVO_THROW_CHECK(max_starts >= 1, InvalidArgument, "mean shift: max_starts must be positive");
  const double kappa = 1 / std::pow(bandwidth_deg * kDegree, 2);
  // The kernel is cut off beyond three bandwidths (where it is below 1.2% of its peak).
  const double cutoff = std::cos(std::min(M_PI, 3 * bandwidth_deg * kDegree));
  // Equal directions are summed once, with their weights added (the detector's points share their cell's normal).
  std::vector<Eigen::Vector3d> unique;
  std::vector<double> unique_weight;
  std::map<std::tuple<double, double, double>, size_t> index;
  for (size_t i = 0; i < d.size(); ++i) {
    const auto [at, fresh] = index.emplace(std::make_tuple(d[i].x(), d[i].y(), d[i].z()), unique.size());
    if (fresh) {
      unique.push_back(d[i]);
      unique_weight.push_back(0);
    }
    unique_weight[at->second] += w[i];
  }
  std::vector<Eigen::Vector3d> modes;
  std::vector<size_t> started;  // a start equal to an earlier one ends where it did
  const size_t step = std::max<size_t>(1, (d.size() + max_starts - 1) / max_starts);
  for (size_t s = 0; s < d.size(); s += step) {
    if (w[s] <= 0) continue;
    const size_t u = index.at(std::make_tuple(d[s].x(), d[s].y(), d[s].z()));
    if (std::find(started.begin(), started.end(), u) != started.end()) continue;
    started.push_back(u);
    Eigen::Vector3d m = d[s].normalized();
    for (int k = 0; k < kIterations; ++k) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < unique.size(); ++i) {
        const double c = m.dot(unique[i]);
        if (c > cutoff) sum += unique_weight[i] * std::exp(kappa * (c - 1)) * unique[i];
      }
      if (sum.norm() < 1e-300) break;
      const Eigen::Vector3d next = sum.normalized();
      const double change = Angle(next, m);
      m = next;
      if (change < kConverged) break;
    }
    const bool known = std::any_of(modes.begin(), modes.end(),
                                   [&](const Eigen::Vector3d& q) { return Angle(q, m) < merge_deg * kDegree; });
    if (!known) modes.push_back(m);
  }
  std::vector<DirectionMode> out;
  for (const Eigen::Vector3d& m : modes) out.push_back({m, 0});
  for (size_t i = 0; i < d.size(); ++i) {
    if (out.empty()) break;
    size_t nearest = 0;
    for (size_t k = 1; k < out.size(); ++k) {
      if (out[k].direction.dot(d[i]) > out[nearest].direction.dot(d[i])) nearest = k;
    }
    out[nearest].support += w[i];
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const DirectionMode& a, const DirectionMode& b) { return a.support > b.support; });
  return out;
}

}  // namespace pdvo
