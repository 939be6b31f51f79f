// The EKF state: Jacobians against central differences through the filter's own state step, covariance
// bookkeeping when references and points come and go, and estimation against ground truth (a camera moving
// at constant velocity past points at known depths, measured with pixel noise), with its consistency (NEES).
// The operations on planes are in filter_planes_test.cpp.
#include "pdvo/vo/filter.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "filter_support.h"
#include "pdvo/common/errors.h"

namespace pdvo::vo {
namespace {

TEST(Filter, PointJacobianMatchesCentralDifferencesOverTheWholeState) {
  const Filter f = BusyFilter();
  for (const auto& [id, point] : f.points()) {
    Eigen::Vector2d pixel;
    MeasurementJacobian sparse;
    ASSERT_TRUE(f.PredictPoint(kCamera, id, &pixel, &sparse));
    const Eigen::MatrixXd j = sparse.Dense(f.size());
    const Eigen::MatrixXd numeric = NumericJacobian(f, [id = id](const Filter& g) {
      Eigen::Vector2d p;
      EXPECT_TRUE(g.PredictPoint(kCamera, id, &p, nullptr));
      return p;
    });
    EXPECT_LT((j - numeric).cwiseAbs().maxCoeff(), 1e-5) << "point " << id;
  }
}

TEST(Filter, PlanePointJacobianMatchesCentralDifferencesOverTheWholeState) {
  const Filter f = BusyFilter();
  ASSERT_EQ(f.planes().size(), 1u);
  const int id = f.planes().begin()->first;
  for (const Eigen::Vector2d& keyframe_pixel : {Eigen::Vector2d(100, 80), Eigen::Vector2d(220, 170)}) {
    const Eigen::Vector3d ray = kCamera.Ray(keyframe_pixel);
    Eigen::Vector2d pixel;
    MeasurementJacobian sparse;
    ASSERT_TRUE(f.PredictPlanePoint(kCamera, id, ray, &pixel, &sparse));
    const Eigen::MatrixXd j = sparse.Dense(f.size());
    const Eigen::MatrixXd numeric = NumericJacobian(f, [&](const Filter& g) {
      Eigen::Vector2d p;
      EXPECT_TRUE(g.PredictPlanePoint(kCamera, id, ray, &p, nullptr));
      return p;
    });
    EXPECT_LT((j - numeric).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_GT(j.middleCols<4>(f.planes().at(id).offset).norm(), 0);
  }
}

TEST(Filter, ReferenceCopiesTheCameraPoseAndItsUncertainty) {
  CameraState c;
  c.position = Eigen::Vector3d(1, 2, 3);
  Filter f(c, SmallCovariance());
  f.Predict(0.1, kNoise);
  const int r = f.AddReference(false);
  const Filter::Reference& ref = f.references().at(r);
  EXPECT_EQ(ref.offset, 12);
  EXPECT_EQ(ref.world_from_cam.translation, f.camera().position);
  const Eigen::MatrixXd& p = f.covariance();
  EXPECT_TRUE((p.block(12, 12, 6, 6).array() == p.block(0, 0, 6, 6).array()).all());
  EXPECT_TRUE((p.block(12, 0, 6, 12).array() == p.block(0, 0, 6, 12).array()).all());
  EXPECT_LT((f.covariance() - f.covariance().transpose()).cwiseAbs().maxCoeff(), 1e-15);
}

// A fixed reference is exact: no variance, no correlation, and updates through its points move the camera and
// the points but never it.
TEST(Filter, FixedReferenceIsNotMovedByUpdates) {
  CameraState c;
  c.velocity = Eigen::Vector3d(0.5, 0, 1);
  Filter f(c, SmallCovariance());
  f.Predict(0.1, {0.5, 0.5});
  const int r = f.AddReference(true);
  const Rigid3d pose = f.references().at(r).world_from_cam;
  EXPECT_EQ(pose.translation, f.camera().position);
  EXPECT_TRUE(f.covariance().middleRows(12, 6).isZero(0));
  EXPECT_TRUE(f.covariance().middleCols(12, 6).isZero(0));
  std::vector<int> points;
  for (int k = 0; k < 6; ++k) {
    points.push_back(f.AddPoint(r, kCamera.Ray({60.0 + 40 * k, 80.0 + 15 * k}), 0.25, 0.1));
  }
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.5);
  Filter predicted_only = f;
  for (int frame = 0; frame < 10; ++frame) {
    f.Predict(1.0 / 30, {0.5, 0.5});
    predicted_only.Predict(1.0 / 30, {0.5, 0.5});
    std::vector<PointMeasurement> z;
    for (int id : points) {
      Eigen::Vector2d pixel;
      ASSERT_TRUE(f.PredictPoint(kCamera, id, &pixel, nullptr));
      z.push_back({id, pixel + Eigen::Vector2d(2 + noise(rng), noise(rng)), 0.5});  // all shifted 2 px right
    }
    ASSERT_TRUE(f.Update(kCamera, z).ok());
  }
  EXPECT_EQ(f.references().at(r).world_from_cam.translation, pose.translation);
  EXPECT_EQ(f.references().at(r).world_from_cam.rotation.coeffs(), pose.rotation.coeffs());
  EXPECT_TRUE(f.covariance().middleRows(12, 6).isZero(0));
  // The camera took the shift: 2 px at this focal length is 0.41 degrees of rotation (or some translation).
  const double turned = LogSO3(predicted_only.camera().orientation.conjugate() * f.camera().orientation).norm();
  const double moved = (predicted_only.camera().position - f.camera().position).norm();
  EXPECT_TRUE(turned > 0.2 * M_PI / 180 || moved > 0.01) << turned * 180 / M_PI << " deg, " << moved << " m";
  EXPECT_GT(MinEigenvalue(f.covariance()), -1e-12);
}

TEST(Filter, RemovingPointsKeepsTheRestOfTheCovariance) {
  Filter f = BusyFilter();
  f.RemovePlane(f.planes().begin()->first);
  ASSERT_EQ(f.size(), 12 + 6 + 3 + 6 + 2);
  std::map<int, double> variance_before;
  for (const auto& [id, p] : f.points()) variance_before[id] = f.covariance()(p.offset, p.offset);
  const int first_reference = f.references().begin()->first;
  std::vector<int> anchored_first;
  for (const auto& [id, p] : f.points()) {
    if (p.reference == first_reference) anchored_first.push_back(id);
  }
  // Removing the first reference's points one by one: the reference goes with the last.
  for (size_t k = 0; k < anchored_first.size(); ++k) {
    f.RemovePoint(anchored_first[k]);
    EXPECT_EQ(f.references().count(first_reference), k + 1 < anchored_first.size() ? 1u : 0u);
  }
  EXPECT_EQ(f.size(), 12 + 6 + 2);
  EXPECT_EQ(f.references().begin()->second.offset, 12);
  for (const auto& [id, p] : f.points()) EXPECT_EQ(f.covariance()(p.offset, p.offset), variance_before[id]);
  EXPECT_THROW(f.RemovePoint(anchored_first[0]), InvalidArgument);
}

// Removing several points at once leaves the same filter as removing them one by one.
TEST(Filter, RemovingPointsAtOnceEqualsOneByOne) {
  Filter one_by_one = BusyFilter(), at_once = BusyFilter();
  for (Filter* f : {&one_by_one, &at_once}) f->RemovePlane(f->planes().begin()->first);
  std::vector<int> ids;
  for (const auto& [id, p] : at_once.points()) ids.push_back(id);
  ids.erase(ids.begin() + 3);  // all but one of the second reference's: the first reference goes
  for (int id : ids) one_by_one.RemovePoint(id);
  at_once.RemovePoints(ids);
  EXPECT_EQ(at_once.size(), 12 + 6 + 1);
  EXPECT_EQ(at_once.references().size(), 1u);
  EXPECT_EQ(at_once.size(), one_by_one.size());
  EXPECT_EQ(at_once.covariance(), one_by_one.covariance());
  EXPECT_THROW(at_once.RemovePoints({ids[0]}), InvalidArgument);
}

// The sparse Jacobian's products with the covariance equal the dense matrix's, for points and plane points.
TEST(Filter, SparseJacobianProductsEqualTheDenseOnes) {
  const Filter f = BusyFilter();
  const Eigen::MatrixXd& p = f.covariance();
  std::vector<MeasurementJacobian> jacobians;
  Eigen::Vector2d pixel;
  for (const auto& [id, point] : f.points()) {
    ASSERT_TRUE(f.PredictPoint(kCamera, id, &pixel, &jacobians.emplace_back()));
  }
  ASSERT_TRUE(f.PredictPlanePoint(kCamera, f.planes().begin()->first, kCamera.Ray({150, 110}), &pixel,
                                  &jacobians.emplace_back()));
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(f.size(), 3);
  for (const MeasurementJacobian& j : jacobians) {
    const Eigen::MatrixXd dense = j.Dense(f.size());
    EXPECT_EQ((dense.array() != 0).count(), 2 * (12 + j.feature_size));  // pose, reference, feature
    EXPECT_LT((j.CovarianceTimesTranspose(p) - p * dense.transpose()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((j.Propagate(p) - dense * p * dense.transpose()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((j.Times(x) - dense * x).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// The truth: a camera moving at constant velocity (1 m/s sideways and forwards, turning slowly) past points
// 3-12 m away, 30 frames/s; measurements are the true pixels plus Gaussian noise. The filter starts at the
// true pose and velocity (the velocity's prior sets the scale); points start at rho 0.2 +- 0.2.
struct RunResult {
  double position_error = 0;            // m, at the end
  double mean_inverse_depth_error = 0;  // relative
  std::vector<double> nees;             // camera position, per frame
};

RunResult SimulateRun(std::mt19937& rng, double pixel_sigma, double velocity_sigma) {
  std::normal_distribution<double> noise(0, pixel_sigma);
  std::uniform_real_distribution<double> u(0, 1);
  CameraState truth;
  truth.velocity = Eigen::Vector3d(0.7, 0, 0.7);
  truth.angular_velocity = Eigen::Vector3d(0, 0.1, 0);
  Matrix12d p0 = SmallCovariance();
  p0.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * velocity_sigma * velocity_sigma;
  Filter f(truth, p0);
  const int r = f.AddReference(false);
  std::map<int, Eigen::Vector3d> world_point;
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector2d pixel(20 + 280 * u(rng), 20 + 200 * u(rng));
    const Eigen::Vector3d ray = kCamera.Ray(pixel);
    const double depth = 3 + 9 * u(rng);
    world_point[f.AddPoint(r, ray, 0.2, 0.2)] = truth.world_from_cam() * (ray * depth);
  }
  RunResult out;
  const double dt = 1.0 / 30;
  for (int frame = 0; frame < 60; ++frame) {
    truth = PredictCamera(truth, dt);
    f.Predict(dt, {0.5, 0.5});
    std::vector<PointMeasurement> z;
    for (const auto& [id, x] : world_point) {
      const Eigen::Vector3d in_cam = truth.world_from_cam().Inverse() * x;
      z.push_back({id, kCamera.Project(in_cam) + Eigen::Vector2d(noise(rng), noise(rng)), pixel_sigma});
    }
    EXPECT_TRUE(f.Update(kCamera, z).ok());
    const Eigen::Vector3d e = f.camera().position - truth.position;
    out.nees.push_back(e.dot(f.covariance().topLeftCorner<3, 3>().ldlt().solve(e)));
  }
  out.position_error = (f.camera().position - truth.position).norm();
  for (const auto& [id, p] : f.points()) {
    const Rigid3d& ref = f.references().at(p.reference).world_from_cam;
    const double true_rho = 1 / (ref.Inverse() * world_point[id]).norm();
    out.mean_inverse_depth_error += std::abs(p.inverse_depth - true_rho) / true_rho / f.points().size();
  }
  return out;
}

TEST(Filter, EstimatesConvergeToTheTruth) {
  std::mt19937 rng(11);
  const RunResult r = SimulateRun(rng, 0.5, 0.01);
  // Monocular: the scale comes from the velocity prior (1%: 2 cm over the 2 m travelled), so 2.5% of the path.
  EXPECT_LT(r.position_error, 0.05);
  EXPECT_LT(r.mean_inverse_depth_error, 0.05);  // from a prior up to 140% off
}

// Over 25 runs, the mean NEES of the camera position (3 degrees of freedom) at each of the last 30 frames must
// lie within the two-sided 99% band of chi-square(75) / 25 (Bar-Shalom's test), on average over those frames.
TEST(Filter, CameraPositionIsConsistent) {
  std::mt19937 rng(12);
  constexpr int kRuns = 25;
  std::vector<double> mean_nees(60, 0.0);
  for (int run = 0; run < kRuns; ++run) {
    const RunResult r = SimulateRun(rng, 1.0, 0.01);
    for (int k = 0; k < 60; ++k) mean_nees[k] += r.nees[k] / kRuns;
  }
  double average = 0;
  for (int k = 30; k < 60; ++k) average += mean_nees[k] / 30;
  // chi2(75) 0.5% and 99.5% quantiles: 47.2 and 110.3, divided by 25 runs.
  EXPECT_GT(average, 47.2 / kRuns);
  EXPECT_LT(average, 110.3 / kRuns);
  RecordProperty("mean_position_nees", std::to_string(average));
}

TEST(Filter, CovarianceStaysSymmetricPositiveSemidefinite) {
  Filter f = BusyFilter();
  std::mt19937 rng(13);
  std::normal_distribution<double> noise(0, 1);
  for (int frame = 0; frame < 20; ++frame) {
    f.Predict(1.0 / 30, kNoise);
    std::vector<PointMeasurement> z;
    for (const auto& [id, p] : f.points()) {
      Eigen::Vector2d pixel;
      if (f.PredictPoint(kCamera, id, &pixel, nullptr))
        z.push_back({id, pixel + Eigen::Vector2d(noise(rng), noise(rng)), 1});
    }
    ASSERT_TRUE(f.Update(kCamera, z).ok());
    EXPECT_LT((f.covariance() - f.covariance().transpose()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT(MinEigenvalue(f.covariance()), -1e-12);
  }
}

// Step and PredictAfter (1-point RANSAC's hypotheses) give exactly what an update of a copy would: the same step,
// bit for bit, and the same predictions after it; the filter itself is unchanged.
TEST(Filter, StepIsTheUpdateWithoutChangingTheFilter) {
  Filter f = BusyFilter();
  std::vector<PointMeasurement> all;
  for (const auto& [id, p] : f.points()) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(f.PredictPoint(kCamera, id, &pixel, nullptr));
    all.push_back({id, pixel + Eigen::Vector2d(0.7, -0.4), 0.5});
  }
  const Eigen::MatrixXd covariance = f.covariance();
  const CameraState camera = f.camera();
  Eigen::VectorXd step;
  ASSERT_EQ(f.Step(kCamera, {all[0]}, &step), UpdateStatus::kOk);
  EXPECT_EQ(f.covariance(), covariance);
  EXPECT_EQ(f.camera().position, camera.position);
  Filter updated = f;
  ASSERT_TRUE(updated.Update(kCamera, {all[0]}).ok());
  std::vector<Eigen::Vector2d> after;
  std::vector<bool> predicted;
  f.PredictAfter(kCamera, all, step, &after, &predicted);
  for (size_t k = 0; k < all.size(); ++k) {
    Eigen::Vector2d expected;
    ASSERT_TRUE(updated.PredictMeasurement(kCamera, all[k], &expected, nullptr));
    ASSERT_TRUE(predicted[k]);
    EXPECT_EQ(after[k], expected) << k;  // bit for bit
  }
  EXPECT_EQ(updated.camera().position, f.camera().Plus(step.head<12>()).position);
}

// Updates that cannot be made are values, and leave the filter as it was.
TEST(Filter, FailedUpdatesAreValues) {
  Filter f = BusyFilter();
  EXPECT_EQ(f.Update(kCamera, {}).status, UpdateStatus::kNoMeasurements);
  const int point = f.points().begin()->first;
  Eigen::Vector2d pixel;
  ASSERT_TRUE(f.PredictPoint(kCamera, point, &pixel, nullptr));
  const Eigen::MatrixXd before = f.covariance();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(f.Update(kCamera, {{point, Eigen::Vector2d(nan, 1), 0.5}}).status, UpdateStatus::kNonFinite);
  EXPECT_FALSE(f.Update(kCamera, {{point, pixel, nan}}).ok());
  EXPECT_EQ(f.covariance(), before);
  // Nothing uncertain and exact measurements: the innovation covariance is zero, not positive.
  Filter certain(CameraState(), Matrix12d::Zero());
  const int reference = certain.AddReference(true);
  const int exact = certain.AddPoint(reference, Eigen::Vector3d::UnitZ(), 0.2, 1e-200);  // its variance underflows
  Eigen::Vector2d centre;
  ASSERT_TRUE(certain.PredictPoint(kCamera, exact, &centre, nullptr));
  EXPECT_EQ(certain.Update(kCamera, {{exact, centre, 0.0}}).status, UpdateStatus::kNotPositive);
  Eigen::VectorXd step;
  EXPECT_EQ(certain.Step(kCamera, {{exact, centre, 0.0}}, &step), UpdateStatus::kNotPositive);
  // A point behind the camera: moved behind it by a step of the camera.
  Filter behind = f;
  Eigen::VectorXd jump = Eigen::VectorXd::Zero(f.size());
  jump.head<3>() = Eigen::Vector3d(0, 0, 100);
  behind.Apply(jump);
  EXPECT_EQ(behind.Update(kCamera, {{point, pixel, 0.5}}).status, UpdateStatus::kNotInFront);
}

}  // namespace
}  // namespace pdvo::vo
