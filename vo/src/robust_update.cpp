#include "pdvo/vo/robust_update.h"

#include <algorithm>

#include "pdvo/common/options.h"

namespace pdvo::vo {
namespace {

// The measurements whose flag is set.
std::vector<PointMeasurement> Select(const std::vector<PointMeasurement>& all, const std::vector<bool>& flags) {
  std::vector<PointMeasurement> out;
  for (size_t i = 0; i < all.size(); ++i) {
    if (flags[i]) out.push_back(all[i]);
  }
  return out;
}

}  // namespace

bool RansacOptions::Check() const {
  PDVO_CHECK_OPTION(hypotheses >= 1 && threshold > 0);
  return true;
}

RobustUpdateResult UpdateRobustly(const Camera& camera, const RansacOptions& o,
                                  const std::vector<PointMeasurement>& all, std::mt19937* rng, Filter* filter) {
  RobustUpdateResult result;
  result.used.assign(all.size(), false);
  if (all.empty()) return result;
  const int hypotheses = std::min<int>(o.hypotheses, static_cast<int>(all.size()));
  std::uniform_int_distribution<size_t> pick(0, all.size() - 1);
  std::vector<bool> best(all.size(), false);
  std::vector<Eigen::Vector2d> predicted;
  std::vector<bool> in_front;
  Eigen::VectorXd step;
  long most = 0;
  for (int k = 0; k < hypotheses; ++k) {
    const PointMeasurement& drawn = all[pick(*rng)];
    if (filter->Step(camera, {drawn}, &step) != UpdateStatus::kOk) continue;
    filter->PredictAfter(camera, all, step, &predicted, &in_front);
    std::vector<bool> agree(all.size(), false);
    for (size_t i = 0; i < all.size(); ++i) {
      agree[i] = in_front[i] && (predicted[i] - all[i].pixel).norm() < o.threshold;
    }
    const long count = std::count(agree.begin(), agree.end(), true);
    if (count > most) {
      most = count;
      best = std::move(agree);
    }
  }
  if (most == 0) return result;
  result.status = filter->Update(camera, Select(all, best)).status;
  if (result.status != UpdateStatus::kOk) return result;
  result.inliers = static_cast<int>(most);
  // Rescue: the rest, gated on their innovation after the inliers' update.
  std::vector<bool> rescued(all.size(), false);
  for (size_t i = 0; i < all.size(); ++i) {
    Eigen::Vector2d pixel;
    MeasurementJacobian jacobian;
    if (best[i] || !filter->PredictMeasurement(camera, all[i], &pixel, &jacobian)) continue;
    Eigen::Matrix2d s = jacobian.Propagate(filter->covariance());
    s.diagonal().array() += all[i].sigma * all[i].sigma;
    const Eigen::Vector2d v = all[i].pixel - pixel;
    rescued[i] = v.dot(s.ldlt().solve(v)) < kRescueGate;
  }
  const std::vector<PointMeasurement> more = Select(all, rescued);
  // A failed rescue leaves the inliers' update in place: only the inliers are used.
  if (!more.empty() && filter->Update(camera, more).ok()) {
    result.rescued = static_cast<int>(more.size());
    for (size_t i = 0; i < all.size(); ++i) result.used[i] = best[i] || rescued[i];
  } else {
    result.used = best;
  }
  return result;
}

}  // namespace pdvo::vo
