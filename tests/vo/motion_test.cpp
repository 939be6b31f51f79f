// The constant-velocity camera: the error-state Jacobians against central differences on the manifold, the
// manifold operations, and the motion itself against its closed form.
#include "pdvo/vo/motion.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

namespace pdvo::vo {
namespace {

CameraState RandomState(std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  auto v = [&]() { return Eigen::Vector3d(g(rng), g(rng), g(rng)); };
  CameraState s;
  s.position = v();
  s.orientation = ExpSO3(v());
  s.velocity = v();
  s.angular_velocity = 2 * v();  // up to a few rad/s: the step rotation is far from the identity
  return s;
}

TEST(Motion, PlusAndMinusAreInverse) {
  std::mt19937 rng(1);
  std::normal_distribution<double> g(0, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    const CameraState s = RandomState(rng);
    const Vector12d d = Vector12d::NullaryExpr([&]() { return g(rng); });
    EXPECT_LT((s.Plus(d).Minus(s) - d).norm(), 1e-12);
    EXPECT_LT(s.Plus(Vector12d::Zero()).Minus(s).norm(), 1e-15);
  }
}

TEST(Motion, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(2);
  const double dt = 0.1, eps = 1e-6;
  for (int trial = 0; trial < 10; ++trial) {
    const CameraState s = RandomState(rng);
    Matrix12d f;
    Eigen::Matrix<double, 12, 6> g;
    const CameraState predicted = PredictCamera(s, dt, &f, &g);
    Matrix12d numeric;
    for (int i = 0; i < 12; ++i) {
      const Vector12d e = eps * Vector12d::Unit(i);
      numeric.col(i) =
          (PredictCamera(s.Plus(e), dt).Minus(predicted) - PredictCamera(s.Plus(-e), dt).Minus(predicted)) / (2 * eps);
    }
    EXPECT_LT((f - numeric).cwiseAbs().maxCoeff(), 1e-7) << "analytic\n" << f << "\nnumeric\n" << numeric;
    // Impulses (V, W) act as changes of the velocities before the step.
    for (int i = 0; i < 6; ++i) {
      CameraState plus = s, minus = s;
      (i < 3 ? plus.velocity : plus.angular_velocity)[i % 3] += eps;
      (i < 3 ? minus.velocity : minus.angular_velocity)[i % 3] -= eps;
      const Vector12d column =
          (PredictCamera(plus, dt).Minus(predicted) - PredictCamera(minus, dt).Minus(predicted)) / (2 * eps);
      EXPECT_LT((g.col(i) - column).cwiseAbs().maxCoeff(), 1e-7) << "impulse " << i;
    }
  }
}

TEST(Motion, ConstantVelocityFollowsTheClosedForm) {
  std::mt19937 rng(3);
  CameraState s = RandomState(rng);
  const CameraState start = s;
  const double dt = 1.0 / 30;
  for (int k = 0; k < 30; ++k) s = PredictCamera(s, dt);
  EXPECT_LT((s.position - (start.position + start.velocity)).norm(), 1e-12);
  EXPECT_LT(AngularDistance(s.orientation, start.orientation * ExpSO3(start.angular_velocity)), 1e-10);
  EXPECT_EQ(s.velocity, start.velocity);
  EXPECT_EQ(s.angular_velocity, start.angular_velocity);
}

TEST(Motion, ProcessNoiseIsSymmetricPositiveSemidefiniteAndScales) {
  std::mt19937 rng(4);
  Eigen::Matrix<double, 12, 6> g;
  PredictCamera(RandomState(rng), 0.05, nullptr, &g);
  const Matrix12d q = ProcessNoise(g, 0.05, 2.0, 3.0);
  EXPECT_LT((q - q.transpose()).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Matrix12d> eigen(q);
  EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-15);
  EXPECT_NEAR(q(6, 6), 2.0 * 2.0 * 0.05 * 0.05, 1e-15);  // the velocity takes a dt of acceleration noise
  EXPECT_NEAR(q(9, 9), 3.0 * 3.0 * 0.05 * 0.05, 1e-15);
}

}  // namespace
}  // namespace pdvo::vo
