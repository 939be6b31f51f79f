// The robust update on generated measurements: a camera that moved, points at known depths measured exactly,
// and planted outliers (matches several pixels off): the outliers are not used, the inliers are, and the update
// moves the camera towards the truth. The same generator state gives the same result.
#include "pdvo/vo/robust_update.h"

#include <gtest/gtest.h>

#include <random>

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277, 277, 159.5, 119.5);

struct Scene {
  Filter filter;
  CameraState truth;
  std::vector<PointMeasurement> measurements;
  std::vector<bool> outlier;
};

// 40 points 3-10 m away, anchored at the first camera (fixed); the camera moved 10 cm sideways and the filter
// predicts it did not move (position uncertain by 10 cm); one in four matches is an outlier.
Scene MakeScene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), depth(3, 10);
  Vector12d sigma;
  sigma << Eigen::Vector3d::Constant(0.1), Eigen::Vector3d::Constant(0.01), Eigen::Vector3d::Constant(0.1),
      Eigen::Vector3d::Constant(0.1);
  Scene s{Filter(CameraState(), Matrix12d(sigma.cwiseAbs2().asDiagonal())), CameraState(), {}, {}};
  // The anchor is the start pose, exact; the camera is then moved by its covariance alone (no step yet).
  const int reference = s.filter.AddReference(true);
  s.truth.position = Eigen::Vector3d(0.1, 0, 0);
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector2d pixel(160 + 130 * u(rng), 120 + 100 * u(rng));
    const Eigen::Vector3d ray = kCamera.Ray(pixel);
    const double rho = ray.z() / depth(rng);
    const int id = s.filter.AddPoint(reference, ray, rho, 1e-4);  // depths known
    const Eigen::Vector3d in_truth = s.truth.world_from_cam().Inverse() * (ray / rho);
    Eigen::Vector2d seen = kCamera.Project(in_truth);
    const bool bad = k % 4 == 3;
    if (bad) seen += Eigen::Vector2d(6 * u(rng) > 0 ? 6 : -6, 5);
    s.measurements.push_back({id, seen, 0.5});
    s.outlier.push_back(bad);
  }
  return s;
}

TEST(RobustUpdate, RejectsPlantedOutliers) {
  Scene s = MakeScene(1);
  std::mt19937 rng(1);
  const RobustUpdateResult r = UpdateRobustly(kCamera, RansacOptions{}, s.measurements, &rng, &s.filter);
  ASSERT_EQ(r.status, UpdateStatus::kOk);
  ASSERT_EQ(r.used.size(), s.measurements.size());
  for (size_t i = 0; i < r.used.size(); ++i) EXPECT_EQ(r.used[i], !s.outlier[i]) << i;
  EXPECT_EQ(r.inliers + r.rescued, 30);
  EXPECT_LT((s.filter.camera().position - s.truth.position).norm(), 0.01);  // from 0.1 m off
}

TEST(RobustUpdate, IsDeterministicAndHandlesNothing) {
  Scene a = MakeScene(2), b = MakeScene(2);
  std::mt19937 rng_a(5), rng_b(5);
  const RobustUpdateResult ra = UpdateRobustly(kCamera, RansacOptions{}, a.measurements, &rng_a, &a.filter);
  const RobustUpdateResult rb = UpdateRobustly(kCamera, RansacOptions{}, b.measurements, &rng_b, &b.filter);
  EXPECT_EQ(ra.used, rb.used);
  EXPECT_EQ(a.filter.camera().position, b.filter.camera().position);
  EXPECT_EQ(a.filter.covariance(), b.filter.covariance());
  const RobustUpdateResult none = UpdateRobustly(kCamera, RansacOptions{}, {}, &rng_a, &a.filter);
  EXPECT_EQ(none.status, UpdateStatus::kNoMeasurements);
  EXPECT_TRUE(none.used.empty());
}

// When no hypothesis brings any match within the threshold (every match far off), nothing is used and the
// filter is left as it was.
TEST(RobustUpdate, UsesNothingWhenNothingAgrees) {
  Scene s = MakeScene(3);
  for (PointMeasurement& z : s.measurements) z.pixel += Eigen::Vector2d(40 * (z.point % 3) - 40, 37 * (z.point % 2));
  RansacOptions options;
  options.threshold = 1e-9;
  std::mt19937 rng(1);
  const Eigen::MatrixXd before = s.filter.covariance();
  const RobustUpdateResult r = UpdateRobustly(kCamera, options, s.measurements, &rng, &s.filter);
  EXPECT_EQ(r.status, UpdateStatus::kNoMeasurements);
  EXPECT_EQ(std::count(r.used.begin(), r.used.end(), true), 0);
  EXPECT_EQ(s.filter.covariance(), before);
}

}  // namespace
}  // namespace pdvo::vo
