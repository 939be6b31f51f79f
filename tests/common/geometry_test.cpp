#include "pdvo/common/geometry.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/test/support.h"

namespace pdvo {
namespace {

Eigen::Vector3d RandomVector(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return {n(rng), n(rng), n(rng)};
}

// Known angles between directions, whatever the vectors' lengths; parallel and opposite vectors (where rounding can
// push the cosine past +-1) give 0 and 180, not NaN (to 1e-5 degrees: acos near +-1 turns a rounding of 1e-16 into 1e-8
// rad).
TEST(Geometry, AngleBetweenDirections) {
  EXPECT_NEAR(AngleDeg(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 3, 0)), 90, 1e-12);
  EXPECT_NEAR(AngleDeg(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(1, 1, 0)), 45, 1e-12);
  EXPECT_NEAR(AngleDeg(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, std::sin(0.3), std::cos(0.3))), 0.3 * 180 / M_PI,
              1e-12);
  const Eigen::Vector3d v(0.1, 0.7, -0.3);
  for (double scale : {5.0, 1e-3, 1e6}) {
    EXPECT_NEAR(AngleDeg(v, scale * v), 0, 1e-5) << scale;
    EXPECT_NEAR(AngleDeg(v, -scale * v), 180, 1e-5) << scale;
  }
}

// A normal facing the camera is kept; one pointing away becomes the nearest facing one, edge-on or just past it,
// changed only along the ray.
TEST(Geometry, NearestFacingNormalTurnsOnlyAlongTheRay) {
  const Eigen::Vector3d ray(0.3, -0.1, 1);
  const Eigen::Vector3d facing = Eigen::Vector3d(0.2, 0.1, -1).normalized();
  EXPECT_EQ(NearestFacingNormal(facing, ray, 0.01), facing);
  const Eigen::Vector3d away = Eigen::Vector3d(1, 0.3, 0.4).normalized(), r = ray.normalized();
  for (const double past : {0.0, 0.01, 0.1}) {
    const Eigen::Vector3d n = NearestFacingNormal(away, ray, past);
    EXPECT_NEAR(n.norm(), 1, 1e-12);
    EXPECT_NEAR(n.dot(r), -past, 1e-12);
    EXPECT_LT(AngleDeg(n - n.dot(r) * r, away - away.dot(r) * r), 1e-6);  // the same direction across the ray
  }
  EXPECT_LT((NearestFacingNormal(r, ray) + r).norm(), 1e-12);  // along the ray: turned to face it head-on
}

TEST(Geometry, HatIsTheCrossProduct) {
  std::mt19937 rng(1);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d a = RandomVector(rng, 1), b = RandomVector(rng, 1);
    EXPECT_LT(test::MaxAbsDiff(Hat(a) * b, a.cross(b)), 1e-12);
  }
}

TEST(Geometry, ExpLogSO3RoundTrip) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    // Angles up to just below pi, and tiny ones.
    const Eigen::Vector3d phi = RandomVector(rng, i % 10 == 0 ? 1e-9 : 0.9);
    if (phi.norm() >= M_PI - 1e-6) continue;
    EXPECT_LT(test::MaxAbsDiff(LogSO3(ExpSO3(phi)), phi), 1e-9) << phi.transpose();
  }
}

TEST(Geometry, ExpSO3MatchesAngleAxis) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  const double angle = 1.2;
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  EXPECT_LT(test::MaxAbsDiff(ExpSO3(angle * axis).toRotationMatrix(), expected), 1e-12);
}

TEST(Geometry, ExpLogSE3RoundTrip) {
  std::mt19937 rng(3);
  for (int i = 0; i < 100; ++i) {
    Vector6d xi;
    xi.head<3>() = RandomVector(rng, 2.0);
    xi.tail<3>() = RandomVector(rng, i % 10 == 0 ? 1e-9 : 0.8);
    if (xi.tail<3>().norm() >= M_PI - 1e-6) continue;
    EXPECT_LT(test::MaxAbsDiff(LogSE3(ExpSE3(xi)), xi), 1e-8) << xi.transpose();
  }
}

TEST(Geometry, ExpSE3OfPureTranslationIsThatTranslation) {
  Vector6d xi = Vector6d::Zero();
  xi.head<3>() << 1, 2, 3;
  const Rigid3d t = ExpSE3(xi);
  EXPECT_LT(test::MaxAbsDiff(t.translation, Eigen::Vector3d(1, 2, 3)), 1e-15);
  EXPECT_NEAR(t.rotation.w(), 1.0, 1e-15);
}

TEST(Geometry, RigidCompositionAndInverse) {
  std::mt19937 rng(4);
  for (int i = 0; i < 50; ++i) {
    const Rigid3d a(ExpSO3(RandomVector(rng, 1)), RandomVector(rng, 3));
    const Rigid3d b(ExpSO3(RandomVector(rng, 1)), RandomVector(rng, 3));
    const Eigen::Vector3d x = RandomVector(rng, 5);
    EXPECT_LT(test::MaxAbsDiff((a * b) * x, a * (b * x)), 1e-12);
    EXPECT_LT(test::MaxAbsDiff(a.Inverse() * (a * x), x), 1e-12);
    EXPECT_LT(test::MaxAbsDiff(Rigid3d::FromMatrix3x4(a.ToMatrix3x4()) * x, a * x), 1e-12);
  }
}

// The nearest rotation: a rotation scaled or slightly perturbed comes back, a reflection becomes a proper
// rotation, and a sum of rotations about one axis gives the rotation by their mean angle.
TEST(Geometry, NearestRotation) {
  const Eigen::Matrix3d r = ExpSO3(Eigen::Vector3d(0.3, -0.2, 0.5)).toRotationMatrix();
  EXPECT_LT((NearestRotation(2.5 * r) - r).cwiseAbs().maxCoeff(), 1e-12);
  Eigen::Matrix3d perturbed = r;
  perturbed(0, 1) += 1e-3;
  EXPECT_LT((NearestRotation(perturbed) - r).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_NEAR(NearestRotation(-Eigen::Matrix3d::Identity()).determinant(), 1.0, 1e-12);
  const Eigen::Matrix3d sum =
      ExpSO3(Eigen::Vector3d(0, 0, 0.1)).toRotationMatrix() + ExpSO3(Eigen::Vector3d(0, 0, 0.3)).toRotationMatrix();
  EXPECT_LT((NearestRotation(sum) - ExpSO3(Eigen::Vector3d(0, 0, 0.2)).toRotationMatrix()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(Geometry, AngularDistanceOfAKnownRotation) {
  const Eigen::Quaterniond a = ExpSO3(Eigen::Vector3d(0.1, 0.2, 0.3));
  const Eigen::Quaterniond b = a * ExpSO3(Eigen::Vector3d(0, 0.25, 0));
  EXPECT_NEAR(AngularDistance(a, b), 0.25, 1e-12);
  // q and -q are the same rotation.
  Eigen::Quaterniond neg = a;
  neg.coeffs() *= -1;
  EXPECT_NEAR(AngularDistance(a, neg), 0.0, 1e-9);
}

TEST(Geometry, SimilarityScalesPositions) {
  Sim3d s;
  s.scale = 2.0;
  s.rotation = ExpSO3(Eigen::Vector3d(0, 0, M_PI / 2));
  s.translation = Eigen::Vector3d(1, 0, 0);
  EXPECT_LT(test::MaxAbsDiff(s * Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 2, 0)), 1e-12);
}

}  // namespace
}  // namespace pdvo
