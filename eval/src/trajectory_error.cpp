#include "pdvo/eval/trajectory_error.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "pdvo/common/errors.h"

namespace pdvo {

Alignment ParseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSE3;
  if (name == "sim3") return Alignment::kSim3;
  PDVO_THROW(InvalidArgument, "unknown alignment '" << name << "' (use none, se3 or sim3)");
}

std::vector<std::pair<size_t, size_t>> AssociateByTime(const Trajectory& gt, const Trajectory& est, double max_dt) {
  struct Candidate {
    double dt;
    size_t g, e;
  };
  std::vector<Candidate> candidates;
  for (size_t e = 0; e < est.size(); ++e) {
    const double t = est[e].timestamp;
    const auto it =
        std::lower_bound(gt.begin(), gt.end(), t, [](const StampedPose& p, double time) { return p.timestamp < time; });
    const size_t hi = static_cast<size_t>(it - gt.begin());
    // Both neighbours, so that a pose taken by a closer pair still leaves its second choice.
    for (size_t g : {hi == 0 ? hi : hi - 1, hi}) {
      if (g >= gt.size()) continue;
      const double dt = std::abs(gt[g].timestamp - t);
      if (dt <= max_dt) candidates.push_back({dt, g, e});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.dt < b.dt; });
  std::vector<bool> gt_used(gt.size(), false), est_used(est.size(), false);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (gt_used[c.g] || est_used[c.e]) continue;
    gt_used[c.g] = est_used[c.e] = true;
    pairs.emplace_back(c.g, c.e);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  return pairs;
}

Sim3d AlignPoints(const std::vector<Eigen::Vector3d>& source, const std::vector<Eigen::Vector3d>& target,
                  bool with_scale) {
  PDVO_THROW_CHECK(source.size() == target.size() && source.size() >= 3, InvalidArgument,
                   "alignment needs at least 3 matched positions, got " << source.size());
  Eigen::Matrix3Xd src(3, source.size()), dst(3, target.size());
  for (size_t i = 0; i < source.size(); ++i) {
    src.col(static_cast<Eigen::Index>(i)) = source[i];
    dst.col(static_cast<Eigen::Index>(i)) = target[i];
  }
  const Eigen::Vector3d mean = src.rowwise().mean();
  const double spread = (src.colwise() - mean).squaredNorm() / static_cast<double>(source.size());
  PDVO_THROW_CHECK(spread > 1e-18, InvalidArgument,
                   "alignment: the estimated positions do not move, so no rotation or scale can be found");
  const Eigen::Matrix4d t = Eigen::umeyama(src, dst, with_scale);
  Sim3d sim;
  sim.scale = t.block<3, 1>(0, 0).norm();
  sim.rotation = Eigen::Quaterniond(t.block<3, 3>(0, 0) / sim.scale).normalized();
  sim.translation = t.block<3, 1>(0, 3);
  return sim;
}

ErrorStats ComputeStats(const std::vector<double>& errors) {
  ErrorStats s;
  if (errors.empty()) return s;
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const double n = static_cast<double>(errors.size());
  double sum = 0, sq = 0;
  for (double e : errors) {
    sum += e;
    sq += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sq / n);
  s.std = std::sqrt(std::max(0.0, sq / n - s.mean * s.mean));
  s.min = sorted.front();
  s.max = sorted.back();
  const size_t m = sorted.size();
  s.median = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
  return s;
}

AteResult ComputeAte(const Trajectory& gt, const Trajectory& est, Alignment alignment, double max_dt) {
  PDVO_THROW_CHECK(!gt.empty() && !est.empty(), InvalidArgument, "ATE: a trajectory is empty");
  const auto pairs = AssociateByTime(gt, est, max_dt);
  const size_t needed = alignment == Alignment::kNone ? 1 : 3;
  PDVO_THROW_CHECK(pairs.size() >= needed, InvalidArgument,
                   "ATE: only " << pairs.size() << " poses associate within " << max_dt
                                << " s; are the timestamps in the same clock? (try --max-dt)");
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& [g, e] : pairs) {
    src.push_back(est[e].world_from_cam.translation);
    dst.push_back(gt[g].world_from_cam.translation);
  }
  AteResult r;
  r.matched = pairs.size();
  if (alignment != Alignment::kNone) r.gt_from_estimate = AlignPoints(src, dst, alignment == Alignment::kSim3);
  // Orientations are compared after the rotation that best aligns them (the chordal mean of gt * est^-1), not
  // the positions' rotation: along a nearly straight path the positions hardly fix the rotation about it.
  Eigen::Quaterniond orientation_alignment = Eigen::Quaterniond::Identity();
  if (alignment != Alignment::kNone) {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (const auto& [g, e] : pairs) {
      sum += gt[g].world_from_cam.rotation.toRotationMatrix() *
             est[e].world_from_cam.rotation.toRotationMatrix().transpose();
    }
    orientation_alignment = Eigen::Quaterniond(NearestRotation(sum));
  }
  std::vector<double> trans, rot;
  for (const auto& [g, e] : pairs) {
    const Rigid3d aligned = r.gt_from_estimate * est[e].world_from_cam;
    trans.push_back((aligned.translation - gt[g].world_from_cam.translation).norm());
    rot.push_back(
        AngularDistance(orientation_alignment * est[e].world_from_cam.rotation, gt[g].world_from_cam.rotation) * 180.0 /
        M_PI);
  }
  r.translation = ComputeStats(trans);
  r.rotation_deg = ComputeStats(rot);
  return r;
}

RpeResult ComputeRpe(const Trajectory& gt, const Trajectory& est, double max_dt, double delta, RpeUnit unit,
                     double scale) {
  PDVO_THROW_CHECK(delta > 0, InvalidArgument, "RPE: delta must be positive, got " << delta);
  const auto pairs = AssociateByTime(gt, est, max_dt);
  RpeResult r;
  r.delta = delta;
  r.unit = unit;
  std::vector<double> trans, rot;
  for (size_t i = 0; i < pairs.size(); ++i) {
    size_t j = i;
    if (unit == RpeUnit::kFrames) {
      j = i + static_cast<size_t>(std::lround(delta));
    } else {
      const double t0 = est[pairs[i].second].timestamp;
      while (j < pairs.size() && est[pairs[j].second].timestamp - t0 < delta) ++j;
    }
    if (j >= pairs.size()) break;
    const Rigid3d gt_motion = gt[pairs[i].first].world_from_cam.Inverse() * gt[pairs[j].first].world_from_cam;
    Rigid3d est_motion = est[pairs[i].second].world_from_cam.Inverse() * est[pairs[j].second].world_from_cam;
    est_motion.translation *= scale;
    const Rigid3d error = gt_motion.Inverse() * est_motion;
    trans.push_back(error.translation.norm());
    rot.push_back(LogSO3(error.rotation).norm() * 180.0 / M_PI);
  }
  r.pairs = trans.size();
  r.translation = ComputeStats(trans);
  r.rotation_deg = ComputeStats(rot);
  return r;
}

namespace {
nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std}, {"min", s.min}, {"max", s.max}};
}
}  // namespace

nlohmann::json ToJson(const AteResult& a) {
  const Eigen::Quaterniond& q = a.gt_from_estimate.rotation;
  const Eigen::Vector3d& t = a.gt_from_estimate.translation;
  return {{"matched", a.matched},
          {"scale", a.gt_from_estimate.scale},
          {"alignment",
           {{"scale", a.gt_from_estimate.scale},
            {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
            {"translation", {t.x(), t.y(), t.z()}}}},
          {"translation", StatsJson(a.translation)},
          {"rotation_deg", StatsJson(a.rotation_deg)}};
}

nlohmann::json ToJson(const RpeResult& r) {
  return {{"pairs", r.pairs},
          {"delta", r.delta},
          {"unit", r.unit == RpeUnit::kFrames ? "frames" : "seconds"},
          {"translation", StatsJson(r.translation)},
          {"rotation_deg", StatsJson(r.rotation_deg)}};
}

}  // namespace pdvo
