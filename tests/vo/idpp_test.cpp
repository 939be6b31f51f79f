// IDPP geometry: inverse depth to 3D and back, planes' points on their planes, projections against direct 3D
// computation, analytic Jacobians against central differences, and plane homographies against projections.
#include "pdvo/vo/idpp.h"

#include <gtest/gtest.h>

#include <random>

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277.1, 280.4, 159.5, 119.5);

Eigen::Vector3d RandomVector(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> g(0, sigma);
  return {g(rng), g(rng), g(rng)};
}

// A reference camera and a current one a little further along, both looking down +z of the world.
struct Scene {
  Rigid3d world_from_ref, world_from_current;
};

Scene RandomScene(std::mt19937& rng) {
  Scene s;
  s.world_from_ref = Rigid3d(ExpSO3(RandomVector(rng, 0.1)), RandomVector(rng, 0.5));
  s.world_from_current = Rigid3d(s.world_from_ref.rotation * ExpSO3(RandomVector(rng, 0.1)),
                                 s.world_from_ref.translation + RandomVector(rng, 0.3));
  return s;
}

Rigid3d Perturb(const Rigid3d& pose, const Eigen::Matrix<double, 6, 1>& d) {
  return Rigid3d(pose.rotation * ExpSO3(d.tail<3>()), pose.translation + d.head<3>());
}

Eigen::Vector2d Pixel(const Scene& s, const Eigen::Vector3d& ray, double rho) {
  Eigen::Vector2d p;
  EXPECT_TRUE(ProjectInverseDepth(kCamera, s.world_from_current, s.world_from_ref, ray, rho, &p));
  return p;
}

TEST(Idpp, InverseDepthToPixelAndBack) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Scene s = RandomScene(rng);
    const Eigen::Vector2d keyframe_pixel(40 + trial * 11, 30 + trial * 8);
    const Eigen::Vector3d ray = kCamera.Ray(keyframe_pixel);
    EXPECT_NEAR(ray.norm(), 1, 1e-15);
    EXPECT_LT((kCamera.Project(ray) - keyframe_pixel).norm(), 1e-10);  // the ray is the keyframe pixel's
    const double rho = 0.2 + 0.05 * trial;
    // The same pixel as the 3D point m / rho taken to the world and into the current camera.
    const Eigen::Vector3d point_in_world = s.world_from_ref * (ray / rho);
    const Eigen::Vector3d point_in_current = s.world_from_current.Inverse() * point_in_world;
    EXPECT_LT((Pixel(s, ray, rho) - kCamera.Project(point_in_current)).norm(), 1e-9);
    // And back: the point's depth along the ray is 1 / rho.
    const Eigen::Vector3d in_ref = s.world_from_ref.Inverse() * point_in_world;
    EXPECT_NEAR(1 / in_ref.norm(), rho, 1e-12);
    EXPECT_LT((in_ref.normalized() - ray).norm(), 1e-12);
  }
}

TEST(Idpp, PointAtInfinityMovesWithRotationOnly) {
  std::mt19937 rng(2);
  const Scene s = RandomScene(rng);
  const Eigen::Vector3d ray = kCamera.Ray({100, 80});
  const Eigen::Vector3d direction_in_current =
      s.world_from_current.rotation.conjugate() * (s.world_from_ref.rotation * ray);
  EXPECT_LT((Pixel(s, ray, 0.0) - kCamera.Project(direction_in_current)).norm(), 1e-9);
}

TEST(Idpp, BehindTheCameraIsNotProjected) {
  Scene s;
  s.world_from_current = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 5));  // past the point
  Eigen::Vector2d pixel(-1, -1);
  EXPECT_FALSE(
      ProjectInverseDepth(kCamera, s.world_from_current, s.world_from_ref, Eigen::Vector3d(0, 0, 1), 0.5, &pixel));
  EXPECT_EQ(pixel, Eigen::Vector2d(-1, -1));
}

TEST(Idpp, PointJacobiansMatchCentralDifferences) {
  std::mt19937 rng(3);
  const double eps = 1e-6;
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = RandomScene(rng);
    const Eigen::Vector3d ray = kCamera.Ray({60.0 + 20 * trial, 50.0 + 13 * trial});
    const double rho = 0.3 + 0.1 * trial;
    Eigen::Vector2d pixel;
    ProjectionJacobians j;
    ASSERT_TRUE(ProjectInverseDepth(kCamera, s.world_from_current, s.world_from_ref, ray, rho, &pixel, &j));
    Matrix26d current, reference;
    for (int i = 0; i < 6; ++i) {
      const Eigen::Matrix<double, 6, 1> e = eps * Eigen::Matrix<double, 6, 1>::Unit(i);
      Scene a = s, b = s;
      a.world_from_current = Perturb(s.world_from_current, e);
      b.world_from_current = Perturb(s.world_from_current, -e);
      current.col(i) = (Pixel(a, ray, rho) - Pixel(b, ray, rho)) / (2 * eps);
      a = s, b = s;
      a.world_from_ref = Perturb(s.world_from_ref, e);
      b.world_from_ref = Perturb(s.world_from_ref, -e);
      reference.col(i) = (Pixel(a, ray, rho) - Pixel(b, ray, rho)) / (2 * eps);
    }
    const Eigen::Vector2d by_rho = (Pixel(s, ray, rho + eps) - Pixel(s, ray, rho - eps)) / (2 * eps);
    // Pixels are ~100s; central differences at 1e-6 are good to ~1e-6 of a pixel per unit.
    EXPECT_LT((j.current - current).cwiseAbs().maxCoeff(), 1e-5) << j.current << "\n" << current;
    EXPECT_LT((j.reference - reference).cwiseAbs().maxCoeff(), 1e-5) << j.reference << "\n" << reference;
    EXPECT_LT((j.inverse_depth - by_rho).cwiseAbs().maxCoeff(), 1e-5);
  }
}

// A plane in front of the reference camera, tilted, at about 4 m.
InversePlane TiltedPlane() { return {Eigen::Vector3d(0.3, -0.2, -1.1), 0.25}; }

TEST(Idpp, PlanePointsLieOnTheirPlane) {
  const InversePlane plane = TiltedPlane();
  const Eigen::Vector3d unit = plane.normal.normalized();
  for (int y = 10; y < 240; y += 40) {
    for (int x = 10; x < 320; x += 50) {
      const Eigen::Vector3d ray = kCamera.Ray({x, y});
      const double rho = plane.InverseDepthAlong(ray);
      ASSERT_GT(rho, 0);
      const Eigen::Vector3d point = ray / rho;
      EXPECT_NEAR(unit.dot(point) + 1 / plane.inverse_distance, 0, 1e-12);
    }
  }
  // The plane's distance is 1 / rho_p: the ray along the normal meets it there.
  EXPECT_NEAR(1 / plane.InverseDepthAlong(-unit), 4.0, 1e-12);
}

// A plane carried into another camera's frame: the same points satisfy it, its Jacobian is the derivative, and a
// camera behind the plane gets no plane.
TEST(Idpp, PlaneInAnotherFrameIsTheSamePlane) {
  std::mt19937 rng(7);
  const InversePlane plane = TiltedPlane();
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = RandomScene(rng);
    const Rigid3d ref_from_current = s.world_from_ref.Inverse() * s.world_from_current;
    Eigen::Matrix4d j;
    const InversePlane moved = plane.InFrame(ref_from_current, &j);
    ASSERT_GT(moved.inverse_distance, 0);
    EXPECT_NEAR(moved.normal.norm(), plane.normal.norm(), 1e-12);
    for (int y = 20; y < 240; y += 70) {
      for (int x = 20; x < 320; x += 90) {
        const Eigen::Vector3d ray = kCamera.Ray({x, y});
        const Eigen::Vector3d in_current = ref_from_current.Inverse() * (ray / plane.InverseDepthAlong(ray));
        EXPECT_NEAR(moved.normal.normalized().dot(in_current) + 1 / moved.inverse_distance, 0, 1e-9);
        // and a ray of the new camera meets it where the old plane has that point
        EXPECT_NEAR(1 / moved.InverseDepthAlong(in_current.normalized()), in_current.norm(), 1e-9);
      }
    }
    const double eps = 1e-6;
    Eigen::Matrix4d numeric;
    for (int i = 0; i < 4; ++i) {
      InversePlane a = plane, b = plane;
      (i < 3 ? a.normal[i] : a.inverse_distance) += eps;
      (i < 3 ? b.normal[i] : b.inverse_distance) -= eps;
      const InversePlane ma = a.InFrame(ref_from_current), mb = b.InFrame(ref_from_current);
      numeric.col(i) << (ma.normal - mb.normal) / (2 * eps), (ma.inverse_distance - mb.inverse_distance) / (2 * eps);
    }
    EXPECT_LT((j - numeric).cwiseAbs().maxCoeff(), 1e-6) << j << "\n" << numeric;
  }
  // A camera 5 m along the normal's opposite, through the plane (4 m away): behind it.
  const Rigid3d through(Eigen::Quaterniond::Identity(), -5 * plane.normal.normalized());
  EXPECT_LE(plane.InFrame(through).inverse_distance, 0);
}

TEST(Idpp, PlaneJacobianMatchesCentralDifferences) {
  std::mt19937 rng(4);
  const double eps = 1e-6;
  const Scene s = RandomScene(rng);
  const InversePlane plane = TiltedPlane();
  const Eigen::Vector3d ray = kCamera.Ray({200, 70});
  Eigen::Vector2d pixel;
  ProjectionJacobians j;
  Eigen::Matrix<double, 2, 4> jp;
  ASSERT_TRUE(ProjectPlanePoint(kCamera, s.world_from_current, s.world_from_ref, plane, ray, &pixel, &j, &jp));
  auto project = [&](const InversePlane& p) {
    Eigen::Vector2d out;
    EXPECT_TRUE(ProjectPlanePoint(kCamera, s.world_from_current, s.world_from_ref, p, ray, &out));
    return out;
  };
  Eigen::Matrix<double, 2, 4> numeric;
  for (int i = 0; i < 4; ++i) {
    InversePlane a = plane, b = plane;
    if (i < 3) {
      a.normal[i] += eps;
      b.normal[i] -= eps;
    } else {
      a.inverse_distance += eps;
      b.inverse_distance -= eps;
    }
    numeric.col(i) = (project(a) - project(b)) / (2 * eps);
  }
  EXPECT_LT((jp - numeric).cwiseAbs().maxCoeff(), 1e-5) << jp << "\n" << numeric;
  // Scaling the normal does not move the plane.
  EXPECT_LT(std::abs((jp.leftCols<3>() * plane.normal).norm()), 1e-9);
}

TEST(Idpp, HomographyMapsKeyframePixelsOfPlanePointsToTheirProjections) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const Scene s = RandomScene(rng);
    const InversePlane plane = TiltedPlane();
    const Eigen::Matrix3d h = PlaneHomography(kCamera, s.world_from_current, s.world_from_ref, plane);
    for (int y = 20; y < 240; y += 50) {
      for (int x = 20; x < 320; x += 70) {
        const Eigen::Vector2d keyframe_pixel(x, y);
        Eigen::Vector2d projected;
        ASSERT_TRUE(ProjectPlanePoint(kCamera, s.world_from_current, s.world_from_ref, plane,
                                      kCamera.Ray(keyframe_pixel), &projected));
        EXPECT_LT(((h * keyframe_pixel.homogeneous()).hnormalized() - projected).norm(), 1e-9);
      }
    }
    // A point's fronto-parallel plane maps the point's own keyframe pixel to its projection.
    const Eigen::Vector2d u(123, 77);
    const double rho = 0.4;
    const Eigen::Matrix3d hp =
        PlaneHomography(kCamera, s.world_from_current, s.world_from_ref, FrontoParallel(kCamera.Ray(u), rho));
    EXPECT_LT(((hp * u.homogeneous()).hnormalized() - Pixel(s, kCamera.Ray(u), rho)).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace pdvo::vo
