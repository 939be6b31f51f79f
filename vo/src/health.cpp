#include "pdvo/vo/health.h"

#include "pdvo/common/options.h"
#include "pdvo/vo/bootstrap.h"

namespace pdvo::vo {

bool HealthOptions::Check() const {
  PDVO_CHECK_OPTION(min_inliers >= 0 && min_inlier_share >= 0 && min_inlier_share <= 1 && max_nis > 0);
  PDVO_CHECK_OPTION(max_epipolar_error > 0);
  return true;
}

void HealthCheck::Restart(const cv::Mat& grey, const Rigid3d& pose) {
  frames_without_evidence_ = 0;
  doubtful_references_.clear();
  last_keyframe_ = grey.clone();
  last_keyframe_pose_ = pose;
}

bool HealthCheck::Evidence(UpdateStatus update, int measurements, int attempted) {
  const bool evidence =
      update == UpdateStatus::kOk && measurements >= o_.min_inliers && measurements >= o_.min_inlier_share * attempted;
  frames_without_evidence_ = evidence ? 0 : frames_without_evidence_ + 1;
  return evidence;
}

Health HealthCheck::Judge(bool evidence, double nis, const std::vector<int>& used_references,
                          const std::map<int, Filter::Reference>& references) {
  std::erase_if(doubtful_references_, [&](int r) { return !references.contains(r); });
  // Mostly measured against features of doubtful keyframes: a map that is itself in doubt.
  const auto doubtful = std::count_if(used_references.begin(), used_references.end(),
                                      [&](int r) { return doubtful_references_.contains(r); });
  const bool from_doubt = 2 * doubtful > static_cast<long>(used_references.size());
  return evidence && nis <= o_.max_nis && !from_doubt ? Health::kTracked : Health::kUncertain;
}

bool HealthCheck::AtKeyframe(const cv::Mat& grey, const Rigid3d& pose, int reference, bool evidence) {
  std::optional<double> error;
  if (!last_keyframe_.empty()) {
    error = EpipolarDisagreement(camera_, last_keyframe_, grey, last_keyframe_pose_.Inverse() * pose, border_,
                                 min_distance_);
  }
  last_keyframe_ = grey.clone();
  last_keyframe_pose_ = pose;
  const bool disagrees = error && *error > o_.max_epipolar_error;
  if (reference >= 0 && (disagrees || !evidence)) doubtful_references_.insert(reference);
  return disagrees;
}

}  // namespace pdvo::vo
