#include "pdvo/eval/trajectory_error.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

// A walk along a curve with changing orientation, at 30 Hz.
Trajectory Curve(int n, double t0 = 100.0) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const double s = i / 30.0;
    t.push_back({t0 + s, Rigid3d(ExpSO3(Eigen::Vector3d(0.1 * std::sin(s), 0.3 * s, 0.05 * std::cos(2 * s))),
                                 Eigen::Vector3d(2 * std::sin(0.5 * s), 0.3 * std::sin(1.3 * s), 1.4 * s))});
  }
  return t;
}

Sim3d SomeSimilarity(double scale) {
  Sim3d s;
  s.scale = scale;
  s.rotation = ExpSO3(Eigen::Vector3d(0.3, -1.1, 0.7));
  s.translation = Eigen::Vector3d(5, -2, 0.5);
  return s;
}

Trajectory Transformed(const Trajectory& t, const Sim3d& s) {
  Trajectory out = t;
  for (StampedPose& p : out) p.world_from_cam = s * p.world_from_cam;
  return out;
}

TEST(Ate, SimilarityCopyHasZeroErrorAndTheRightScale) {
  const Trajectory gt = Curve(300);
  // The estimate is the ground truth seen in another frame, at 0.37 of its size.
  const Sim3d est_from_gt = SomeSimilarity(0.37);
  const AteResult r = ComputeAte(gt, Transformed(gt, est_from_gt), Alignment::kSim3, 0.001);
  EXPECT_EQ(r.matched, 300u);
  EXPECT_LT(r.translation.rmse, 1e-9);
  EXPECT_LT(r.translation.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-6);
  EXPECT_NEAR(r.gt_from_estimate.scale, 1 / 0.37, 1e-9);
  // SE(3) alignment cannot undo the scale, so the error stays.
  EXPECT_GT(ComputeAte(gt, Transformed(gt, est_from_gt), Alignment::kSE3, 0.001).translation.rmse, 0.5);
  // A rigid copy is exact under SE(3) too.
  const AteResult rigid = ComputeAte(gt, Transformed(gt, SomeSimilarity(1.0)), Alignment::kSE3, 0.001);
  EXPECT_LT(rigid.translation.rmse, 1e-9);
  EXPECT_NEAR(rigid.gt_from_estimate.scale, 1.0, 1e-12);
}

TEST(Ate, NoiseOfKnownSizeGivesItsRmse) {
  const Trajectory gt = Curve(3000);
  Trajectory est = gt;
  std::mt19937 rng(11);
  const double sigma = 0.05;  // per axis, metres
  std::normal_distribution<double> noise(0, sigma);
  for (StampedPose& p : est) p.world_from_cam.translation += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  // Isotropic noise of sigma per axis has an RMS length of sigma * sqrt(3); with 3000 samples the estimate is
  // within about 1% (its relative standard deviation is 1 / sqrt(2 * 3 * 3000)).
  const double expected = sigma * std::sqrt(3.0);
  EXPECT_NEAR(ComputeAte(gt, est, Alignment::kNone, 0.001).translation.rmse, expected, 0.03 * expected);
  EXPECT_NEAR(ComputeAte(gt, est, Alignment::kSE3, 0.001).translation.rmse, expected, 0.03 * expected);
}

// Along a straight path the positions barely fix the rotation about it, so orientations are compared after
// their own alignment: a copy whose positions wobble by a millimetre still has exact orientations.
TEST(Ate, OrientationsAreAlignedOnTheirOwnOnAStraightPath) {
  Trajectory gt;
  for (int i = 0; i < 200; ++i) {
    const double s = i / 30.0;
    gt.push_back({s, Rigid3d(ExpSO3(Eigen::Vector3d(0.05 * std::sin(3 * s), 0.1 * std::cos(s), 0.02 * s)),
                             Eigen::Vector3d(0, 0, 1.4 * s))});
  }
  const Sim3d est_from_gt = SomeSimilarity(0.5);
  Trajectory est = Transformed(gt, est_from_gt);
  std::mt19937 rng(13);
  std::normal_distribution<double> noise(0, 0.001);
  for (StampedPose& p : est) p.world_from_cam.translation += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const AteResult r = ComputeAte(gt, est, Alignment::kSim3, 0.001);
  // The positions' alignment is off about the path by degrees...
  EXPECT_GT(AngularDistance(r.gt_from_estimate.rotation, est_from_gt.rotation.conjugate()) * 180 / M_PI, 1.0);
  // ...the orientations' is exact.
  EXPECT_LT(r.rotation_deg.max, 1e-6);
  // A known rotation error of 2 degrees on every pose is measured as such (the alignment cannot undo what is
  // not common to all poses: here half the poses are off one way, half the other).
  for (size_t i = 0; i < est.size(); ++i) {
    const double sign = i % 2 ? 1 : -1;
    est[i].world_from_cam.rotation =
        est[i].world_from_cam.rotation * ExpSO3(Eigen::Vector3d(0, sign * 2 * M_PI / 180, 0));
  }
  EXPECT_NEAR(ComputeAte(gt, est, Alignment::kSim3, 0.001).rotation_deg.median, 2.0, 0.05);
}

TEST(Ate, AssociationRespectsMaxDtAndUsesEachPoseOnce) {
  const Trajectory gt = Curve(10);  // 30 Hz
  Trajectory est;
  auto at = [&](double t) { est.push_back({t, gt[0].world_from_cam}); };
  at(gt[0].timestamp + 0.003);  // -> gt 0
  at(gt[2].timestamp + 0.003);  // -> gt 2, the closer of two estimates that want it
  at(gt[2].timestamp + 0.008);  // gt 2 is taken; gt 3 is 25 ms away, beyond max_dt: no pair
  at(gt[9].timestamp + 0.5);    // after the ground truth ends: no pair
  const auto pairs = AssociateByTime(gt, est, 0.01);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0], (std::pair<size_t, size_t>{0, 0}));
  EXPECT_EQ(pairs[1], (std::pair<size_t, size_t>{2, 1}));
  // With a wider window the third estimate takes gt 3.
  const auto wide = AssociateByTime(gt, est, 0.03);
  ASSERT_EQ(wide.size(), 3u);
  EXPECT_EQ(wide[2], (std::pair<size_t, size_t>{3, 2}));
}

TEST(Ate, ErrorsForTooFewPosesEmptyInputAndStillEstimates) {
  const Trajectory gt = Curve(20);
  Trajectory shifted = gt;
  for (StampedPose& p : shifted) p.timestamp += 10;
  EXPECT_THROW(ComputeAte(gt, shifted, Alignment::kSim3, 0.02), InvalidArgument);
  EXPECT_THROW(ComputeAte(gt, {}, Alignment::kSim3, 0.02), InvalidArgument);
  Trajectory still = gt;
  for (StampedPose& p : still) p.world_from_cam.translation.setZero();
  EXPECT_THROW(ComputeAte(gt, still, Alignment::kSim3, 0.02), InvalidArgument);
  EXPECT_THROW(ParseAlignment("affine"), InvalidArgument);
}

TEST(AlignPoints, RecoversAKnownSimilarity) {
  std::mt19937 rng(12);
  std::normal_distribution<double> g(0, 1);
  const Sim3d truth = SomeSimilarity(2.5);
  std::vector<Eigen::Vector3d> src, dst;
  for (int i = 0; i < 20; ++i) {
    src.emplace_back(g(rng), g(rng), g(rng));
    dst.push_back(truth * src.back());
  }
  const Sim3d found = AlignPoints(src, dst, true);
  EXPECT_NEAR(found.scale, 2.5, 1e-12);
  EXPECT_LT(AngularDistance(found.rotation, truth.rotation), 1e-12);
  EXPECT_LT((found.translation - truth.translation).norm(), 1e-12);
  EXPECT_THROW(AlignPoints({src[0], src[1]}, {dst[0], dst[1]}, true), InvalidArgument);
}

TEST(Rpe, ZeroForAScaledCopyAndTheStepForAKnownDrift) {
  const Trajectory gt = Curve(100);
  const Sim3d s = SomeSimilarity(0.5);
  const RpeResult r = ComputeRpe(gt, Transformed(gt, s), 0.001, 1, RpeUnit::kFrames, 1 / 0.5);
  EXPECT_EQ(r.pairs, 99u);
  EXPECT_LT(r.translation.max, 1e-9);
  EXPECT_LT(r.rotation_deg.max, 1e-6);
  // Each estimated position drifts 1 cm further along the world's x axis than the last: every 1-frame step is
  // 1 cm off, every 10-frame step 10 cm, whatever the camera's rotation.
  Trajectory drift = gt;
  for (size_t i = 0; i < drift.size(); ++i) drift[i].world_from_cam.translation.x() += 0.01 * i;
  EXPECT_NEAR(ComputeRpe(gt, drift, 0.001, 1, RpeUnit::kFrames, 1.0).translation.rmse, 0.01, 1e-9);
  EXPECT_NEAR(ComputeRpe(gt, drift, 0.001, 10, RpeUnit::kFrames, 1.0).translation.median, 0.10, 1e-9);
  // One second at 30 Hz is 30 frames.
  const RpeResult by_time = ComputeRpe(gt, drift, 0.001, 1.0, RpeUnit::kSeconds, 1.0);
  EXPECT_EQ(by_time.pairs, 70u);
  EXPECT_NEAR(by_time.translation.median, 0.30, 1e-6);
}

TEST(ErrorStats, KnownValues) {
  const ErrorStats s = ComputeStats({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4));
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.min, 1);
}

}  // namespace
}  // namespace pdvo
