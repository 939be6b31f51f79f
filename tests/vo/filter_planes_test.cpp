// The filter's operations on planes: a plane that becomes a point, a point that joins a plane, a plane moved to
// another reference camera (each against the state before, through Jacobians by central differences), and a
// plane's estimate converging to the truth from a fronto-parallel start.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "filter_support.h"
#include "pdvo/common/errors.h"

namespace pdvo::vo {
namespace {

TEST(Filter, PlaneBecomesAPointOnItsRay) {
  Filter f = BusyFilter();
  const int plane = f.planes().begin()->first;
  const Filter::Plane before = f.planes().at(plane);
  const Eigen::Vector3d ray = kCamera.Ray({150, 110});
  Eigen::Vector2d plane_pixel;
  ASSERT_TRUE(f.PredictPlanePoint(kCamera, plane, ray, &plane_pixel, nullptr));
  const Eigen::MatrixXd p_before = f.covariance();
  const int size_before = f.size();
  // First-order propagation, with the Jacobian of the inverse depth by central differences.
  Eigen::RowVector4d j;
  for (int i = 0; i < 4; ++i) {
    InversePlane a = before.plane, b = before.plane;
    (i < 3 ? a.normal[i] : a.inverse_distance) += 1e-6;
    (i < 3 ? b.normal[i] : b.inverse_distance) -= 1e-6;
    j[i] = (a.InverseDepthAlong(ray) - b.InverseDepthAlong(ray)) / 2e-6;
  }
  const double expected_variance = (j * p_before.block<4, 4>(before.offset, before.offset) * j.transpose())(0, 0);
  const double expected_with_camera = (j * p_before.block<4, 1>(before.offset, 0))(0, 0);

  const int point = f.PlaneToPoint(plane, ray);
  EXPECT_TRUE(f.planes().empty());
  EXPECT_EQ(f.size(), size_before - 3);
  const Filter::Point& p = f.points().at(point);
  EXPECT_NEAR(p.inverse_depth, before.plane.InverseDepthAlong(ray), 1e-15);
  Eigen::Vector2d point_pixel;
  ASSERT_TRUE(f.PredictPoint(kCamera, point, &point_pixel, nullptr));
  EXPECT_LT((point_pixel - plane_pixel).norm(), 1e-9);  // the same place
  EXPECT_NEAR(f.covariance()(p.offset, p.offset), expected_variance, 1e-9 * expected_variance);
  EXPECT_NEAR(f.covariance()(p.offset, 0), expected_with_camera, 1e-9 + 1e-6 * std::abs(expected_with_camera));
  // The camera block is untouched.
  EXPECT_TRUE((f.covariance().topLeftCorner<12, 12>().array() == p_before.topLeftCorner<12, 12>().array()).all());
  EXPECT_GT(MinEigenvalue(f.covariance()), -1e-12);
}

// A point joining a plane: the constraint rho_point = rho_plane(ray) +- sigma fuses the two. Against the scalar
// Kalman solution along the ray (point and plane start uncorrelated), and the whole covariance against the
// update written out with a Jacobian by central differences.
TEST(Filter, PointJoiningAPlaneIsFusedIntoIt) {
  Filter f = BusyFilter();
  const int plane = f.planes().begin()->first;
  const int reference = f.planes().at(plane).reference;
  const Eigen::Vector3d ray = kCamera.Ray({170, 130});
  const double on_plane = f.planes().at(plane).plane.InverseDepthAlong(ray);
  const int point = f.AddPoint(reference, ray, 1.1 * on_plane, 0.2 * on_plane);
  const double sigma = 0.02 * on_plane;

  const auto along_ray = [&](const Filter& g) { return g.planes().at(plane).plane.InverseDepthAlong(ray); };
  const int n = f.size(), point_offset = f.points().at(point).offset;
  const Eigen::RowVectorXd h = NumericJacobian(  // d(rho_point - rho_plane(ray)) / d(error state)
      f, [&](const Filter& g) { return Scalar(g.points().at(point).inverse_depth - along_ray(g)); }, 1e-7);
  const Eigen::MatrixXd p = f.covariance();
  const double s = (h * p * h.transpose())(0, 0) + sigma * sigma;
  Eigen::MatrixXd expected = p - p * h.transpose() * h * p / s;
  std::vector<int> keep;
  for (int i = 0; i < n; ++i) {
    if (i != point_offset) keep.push_back(i);
  }
  expected = Eigen::MatrixXd(expected(keep, keep));
  Eigen::RowVectorXd h_plane = -h;  // d rho_plane(ray) / d(error state), without the point
  h_plane[point_offset] = 0;
  const double plane_variance = (h_plane * p * h_plane.transpose())(0, 0);
  const double point_variance = p(point_offset, point_offset);
  ASSERT_NEAR(point_variance, std::pow(0.2 * on_plane, 2), 1e-15);

  ASSERT_EQ(f.MergePointIntoPlane(point, plane, sigma), UpdateStatus::kOk);
  EXPECT_FALSE(f.points().count(point));
  ASSERT_EQ(f.size(), n - 1);
  const double gain = plane_variance / (plane_variance + point_variance + sigma * sigma);
  EXPECT_GT(gain, 0.1);                                                          // the test says something
  EXPECT_NEAR(along_ray(f), on_plane + gain * 0.1 * on_plane, 1e-3 * on_plane);  // first order: to 0.1%
  Eigen::RowVectorXd h_after(n - 1);
  for (int i = 0, k = 0; i < n; ++i) {
    if (i != point_offset) h_after[k++] = h_plane[i];
  }
  EXPECT_NEAR((h_after * f.covariance() * h_after.transpose())(0, 0), plane_variance * (1 - gain),
              1e-6 * plane_variance);
  EXPECT_LT((f.covariance() - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT(MinEigenvalue(f.covariance()), -1e-12);
  EXPECT_THROW(f.MergePointIntoPlane(point, plane, sigma), InvalidArgument);  // gone
}

// A plane moved to a later (fixed) reference camera: the same plane, and the same uncertainty of what it says
// about any point of it; the first reference goes with its last feature; tracked references are refused.
TEST(Filter, PlaneMovedToAnotherReferenceIsTheSamePlane) {
  CameraState c;
  c.velocity = Eigen::Vector3d(0.8, 0.05, 0.2);
  c.angular_velocity = Eigen::Vector3d(0.05, 0.3, -0.02);
  Filter f(c, SmallCovariance());
  const int r0 = f.AddReference(true);
  const int plane = f.AddPlane(r0, {Eigen::Vector3d(0.3, -0.1, -1.0), 0.2}, 0.2, 0.05);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.5);
  for (int frame = 0; frame < 6; ++frame) {  // correlate the plane with the camera
    f.Predict(1.0 / 30, kNoise);
    std::vector<PointMeasurement> z;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d ray = kCamera.Ray({70.0 + 60 * k, 60.0 + 30 * k});
      Eigen::Vector2d pixel;
      ASSERT_TRUE(f.PredictPlanePoint(kCamera, plane, ray, &pixel, nullptr));
      z.push_back({plane, pixel + Eigen::Vector2d(noise(rng), noise(rng)), 0.5, ray});
    }
    ASSERT_TRUE(f.Update(kCamera, z).ok());
  }
  const int r1 = f.AddReference(true);
  f.AddPoint(r1, kCamera.Ray({100, 100}), 0.3, 0.1);
  f.Predict(1.0 / 30, kNoise);

  // What the moved plane says: the inverse depth along a ray of r1, as a function of the state.
  const Eigen::Vector3d ray = kCamera.Ray({140, 150});
  const auto moved_rho = [&](Filter g) {
    EXPECT_TRUE(g.MovePlane(plane, r1));
    return g.planes().at(plane).plane.InverseDepthAlong(ray);
  };
  const int n = f.size();
  // Its derivative over the state before the move.
  const Eigen::RowVectorXd h = NumericJacobian(
      f, [&](const Filter& g) { return Scalar(moved_rho(g)); }, 1e-7);
  const Eigen::MatrixXd p = f.covariance();
  Eigen::Vector2d pixel_before, pixel_after;
  const Eigen::Vector3d on_plane_r0 =
      f.references().at(r0).world_from_cam.Inverse() * (f.references().at(r1).world_from_cam * (ray / moved_rho(f)));
  ASSERT_TRUE(f.PredictPlanePoint(kCamera, plane, on_plane_r0.normalized(), &pixel_before, nullptr));

  ASSERT_TRUE(f.MovePlane(plane, r1));
  EXPECT_EQ(f.planes().at(plane).reference, r1);
  EXPECT_FALSE(f.references().count(r0));  // its only feature left it
  EXPECT_EQ(f.size(), n - 6);
  ASSERT_TRUE(f.PredictPlanePoint(kCamera, plane, ray, &pixel_after, nullptr));
  EXPECT_LT((pixel_after - pixel_before).norm(), 1e-9);  // the same point, now on a ray of r1
  // The same quantity's derivative over the new state.
  const Eigen::RowVectorXd h_after = NumericJacobian(
      f, [&](const Filter& g) { return Scalar(g.planes().at(plane).plane.InverseDepthAlong(ray)); }, 1e-7);
  const double variance = (h * p * h.transpose())(0, 0);
  EXPECT_GT(variance, 1e-8);
  EXPECT_NEAR((h_after * f.covariance() * h_after.transpose())(0, 0), variance, 1e-6 * variance);
  // Its correlation with the camera, which the updates made.
  const Eigen::RowVectorXd with_camera = h * p.leftCols<12>(),
                           with_camera_after = h_after * f.covariance().leftCols<12>();
  EXPECT_GT(with_camera.cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((with_camera_after - with_camera).cwiseAbs().maxCoeff(), 1e-6 * with_camera.cwiseAbs().maxCoeff());
  EXPECT_GT(MinEigenvalue(f.covariance()), -1e-12);

  // Tracked references: refused, nothing changes.
  Filter g = BusyFilter();
  const int busy_plane = g.planes().begin()->first;
  const Eigen::MatrixXd before = g.covariance();
  EXPECT_FALSE(g.MovePlane(busy_plane, g.references().rbegin()->first));
  EXPECT_EQ(g.covariance(), before);
}

// A facade on the right (normal 50 degrees from the optical axis, 6 m away) seen while moving forwards at a
// known speed: its 30 points are measured with 0.5 px noise. From a fronto-parallel start the plane turns to
// its true orientation and distance.
TEST(Filter, PlaneConvergesToTheTruthFromFrontoParallel) {
  std::mt19937 rng(21);
  std::normal_distribution<double> noise(0, 0.5);
  const double angle = 50 * M_PI / 180, distance = 6;
  const Eigen::Vector3d normal(-std::sin(angle), 0, -std::cos(angle));  // towards the camera
  CameraState truth;
  truth.velocity = Eigen::Vector3d(0, 0, 1);
  Matrix12d p0 = SmallCovariance();
  p0.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * 1e-4;
  Filter f(truth, p0);
  const int r = f.AddReference(false);
  std::vector<Eigen::Vector3d> rays;
  for (int y = 40; y < 220; y += 36) {
    for (int x = 180; x < 310; x += 26) rays.push_back(kCamera.Ray({x, y}));
  }
  const Eigen::Vector3d centre_ray = kCamera.Ray({245, 130});
  const int plane = f.AddPlane(r, {-centre_ray, 0.2}, 0.5, 0.2);
  const double dt = 1.0 / 30;
  for (int frame = 0; frame < 60; ++frame) {
    truth = PredictCamera(truth, dt);
    f.Predict(dt, {0.5, 0.5});
    std::vector<PointMeasurement> z;
    for (const Eigen::Vector3d& m : rays) {
      const Eigen::Vector3d on_plane = m * (-distance / normal.dot(m));
      const Eigen::Vector2d pixel = kCamera.Project(truth.world_from_cam().Inverse() * on_plane);
      z.push_back({plane, pixel + Eigen::Vector2d(noise(rng), noise(rng)), 0.5, m});
    }
    ASSERT_TRUE(f.Update(kCamera, z).ok());
  }
  const InversePlane& estimate = f.planes().at(plane).plane;
  EXPECT_LT(std::acos(std::min(1.0, estimate.normal.normalized().dot(normal))) * 180 / M_PI, 2.0)
      << estimate.normal.normalized().transpose();
  // The distance carries the monocular scale (here from a 1% velocity prior): within 3 of the filter's own
  // standard deviations.
  const int o = f.planes().at(plane).offset;
  const double sigma = std::sqrt(f.covariance()(o + 3, o + 3));
  EXPECT_LT(std::abs(estimate.inverse_distance - 1 / distance), 3 * sigma) << "sigma " << sigma;
  EXPECT_LT(sigma, 0.05 / distance);  // and that is a few percent
}

}  // namespace
}  // namespace pdvo::vo
