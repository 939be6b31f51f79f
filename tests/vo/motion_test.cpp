// The constant-velocity camera: the error-state Jacobians against central differences on the manifold, the
// manifold operations, and the motion itself against its closed form.
#include "pdvo/vo/motion.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <vector>

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

// At constant rates the velocity keeps its direction in the camera frame, so a camera driving forward while it
// turns about its vertical axis runs round a circle: each step a chord of |v| dt, turning by w dt, the vertices
// of a regular polygon of circumradius |v| dt / (2 sin(w dt / 2)).
TEST(Motion, ConstantRatesDriveACircle) {
  std::mt19937 rng(3);
  CameraState s = RandomState(rng);
  const Eigen::Matrix3d r0 = s.orientation.toRotationMatrix();
  s.velocity = r0 * Eigen::Vector3d(0.3, 0, 10);    // forward, drifting sideways: m/s, camera frame
  s.angular_velocity = Eigen::Vector3d(0, 0.5, 0);  // rad/s about the camera's vertical axis
  const CameraState start = s;
  const double dt = 0.1;
  const int steps = 40;
  std::vector<Eigen::Vector3d> positions{s.position};
  for (int k = 0; k < steps; ++k) {
    s = PredictCamera(s, dt);
    positions.push_back(s.position);
  }
  EXPECT_LT(AngularDistance(s.orientation, start.orientation * ExpSO3(steps * dt * start.angular_velocity)), 1e-10);
  EXPECT_LT((s.orientation.conjugate() * s.velocity - start.orientation.conjugate() * start.velocity).norm(), 1e-10);
  EXPECT_EQ(s.angular_velocity, start.angular_velocity);
  // The circle's centre: the point equidistant from the first three positions, in their plane.
  const double chord = start.velocity.norm() * dt, turn = start.angular_velocity.norm() * dt;
  const double radius = chord / (2 * std::sin(turn / 2));
  const Eigen::Vector3d a = positions[0], b = positions[1], c = positions[2];
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const Eigen::Vector3d centre =
      a + ((c - a).squaredNorm() * normal.cross(b - a) + (b - a).squaredNorm() * (c - a).cross(normal)) /
              (2 * normal.squaredNorm());
  for (const Eigen::Vector3d& p : positions) {
    EXPECT_NEAR((p - centre).norm(), radius, 1e-9 * radius);
    EXPECT_NEAR((p - a).dot(normal.normalized()), 0, 1e-9 * radius);  // in one plane, the camera's horizontal
  }
  EXPECT_NEAR(std::abs(normal.normalized().dot(start.orientation * Eigen::Vector3d::UnitY())), 1, 1e-12);
}

TEST(Motion, ProcessNoiseIsSymmetricPositiveSemidefiniteAndScales) {
  std::mt19937 rng(4);
  Eigen::Matrix<double, 12, 6> g;
  CameraState at_rest = RandomState(rng);
  at_rest.velocity.setZero();  // else the angular noise turns the velocity too
  PredictCamera(at_rest, 0.05, nullptr, &g);
  const Matrix12d q = ProcessNoise(g, 0.05, 2.0, 3.0);
  EXPECT_LT((q - q.transpose()).cwiseAbs().maxCoeff(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Matrix12d> eigen(q);
  EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-15);
  EXPECT_NEAR(q(6, 6), 2.0 * 2.0 * 0.05 * 0.05, 1e-15);  // the velocity takes a dt of acceleration noise
  EXPECT_NEAR(q(9, 9), 3.0 * 3.0 * 0.05 * 0.05, 1e-15);
}

}  // namespace
}  // namespace pdvo::vo
