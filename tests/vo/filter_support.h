// What the filter's tests share (filter_test.cpp, filter_planes_test.cpp): a camera, a motion noise, a small
// starting covariance, a filter with two reference cameras, points and a plane, and central differences over
// the whole error state.
#pragma once

#include <Eigen/Eigenvalues>

#include "pdvo/vo/filter.h"

namespace pdvo::vo {

inline const Camera kCamera = Camera::Pinhole(320, 240, 277.0, 277.0, 159.5, 119.5);
inline const MotionNoise kNoise{2.0, 2.0};  // m/s^2, rad/s^2

inline Matrix12d SmallCovariance() {
  Vector12d sigma;
  sigma << Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(0.1),
      Eigen::Vector3d::Constant(0.1);
  return sigma.cwiseAbs2().asDiagonal();
}

inline double MinEigenvalue(const Eigen::MatrixXd& p) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p).eigenvalues().minCoeff();
}

// A filter with two reference cameras and a few points, after some motion.
inline Filter BusyFilter() {
  CameraState c;
  c.velocity = Eigen::Vector3d(0.8, 0.05, 0.2);
  c.angular_velocity = Eigen::Vector3d(0.05, 0.3, -0.02);
  Filter f(c, SmallCovariance());
  const int r0 = f.AddReference(false);
  for (int k = 0; k < 3; ++k) f.AddPoint(r0, kCamera.Ray({80.0 + 60 * k, 100.0 + 10 * k}), 0.2 + 0.1 * k, 0.1);
  for (int k = 0; k < 5; ++k) f.Predict(1.0 / 30, kNoise);
  const int r1 = f.AddReference(false);
  for (int k = 0; k < 2; ++k) f.AddPoint(r1, kCamera.Ray({120.0 + 50 * k, 90.0}), 0.3, 0.2);
  f.AddPlane(r0, {Eigen::Vector3d(0.3, -0.1, -1.0), 0.2}, 0.2, 0.05);
  f.Predict(1.0 / 30, kNoise);
  return f;
}

// A scalar as a 1-vector, for NumericJacobian.
inline Eigen::Matrix<double, 1, 1> Scalar(double value) { return Eigen::Matrix<double, 1, 1>::Constant(value); }

// Central differences of a function of the filter (its value: a fixed-size vector) over the whole error
// state, through Filter::Apply.
template <class Fn>
Eigen::MatrixXd NumericJacobian(const Filter& f, Fn fn, double eps = 1e-6) {
  const auto rows = fn(f).size();
  Eigen::MatrixXd numeric(rows, f.size());
  for (int i = 0; i < f.size(); ++i) {
    Filter a = f, b = f;
    a.Apply(eps * Eigen::VectorXd::Unit(f.size(), i));
    b.Apply(-eps * Eigen::VectorXd::Unit(f.size(), i));
    numeric.col(i) = (fn(a) - fn(b)) / (2 * eps);
  }
  return numeric;
}

}  // namespace pdvo::vo
