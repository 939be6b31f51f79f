#include "pdvo/common/geometry.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace pdvo {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

Eigen::Vector3d NearestFacingNormal(const Eigen::Vector3d& normal, const Eigen::Vector3d& ray, double past_edge_on) {
  const Eigen::Vector3d r = ray.normalized();
  const double away = normal.dot(r);
  if (away < 0) return normal;
  const Eigen::Vector3d across = normal - away * r;
  if (across.norm() <= 1e-9) return -r;
  return std::sqrt(1 - past_edge_on * past_edge_on) * across.normalized() - past_edge_on * r;
}

Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const double half = 0.5 * theta;
  // sin(theta/2)/theta, by its Taylor series near zero.
  const double k = theta < 1e-8 ? 0.5 - theta * theta / 48.0 : std::sin(half) / theta;
  Eigen::Quaterniond q(std::cos(half), k * phi.x(), k * phi.y(), k * phi.z());
  return q.normalized();
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0) q.coeffs() *= -1;  // the shorter of the two equivalent rotations
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-8) return 2.0 * v / q.w();  // 2 * atan2(s, w) / s -> 2 / w
  return 2.0 * std::atan2(s, q.w()) / s * v;
}

Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d W = Hat(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1 - std::cos(theta)) / t2 * W +
         (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix<double, 3, 4> Rigid3d::ToMatrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = rotation.toRotationMatrix();
  m.col(3) = translation;
  return m;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) *= -1;
  return u * svd.matrixV().transpose();
}

Rigid3d Rigid3d::FromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m) {
  return Rigid3d(Eigen::Quaterniond(NearestRotation(m.leftCols<3>())), m.col(3));
}

Rigid3d ExpSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  return Rigid3d(ExpSO3(phi), LeftJacobianSO3(phi) * rho);
}

Vector6d LogSE3(const Rigid3d& transform) {
  const Eigen::Vector3d phi = LogSO3(transform.rotation);
  Vector6d xi;
  xi.head<3>() = LeftJacobianSO3(phi).inverse() * transform.translation;
  xi.tail<3>() = phi;
  return xi;
}

double AngularDistance(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return LogSO3(a.conjugate() * b).norm();
}

}  // namespace pdvo
