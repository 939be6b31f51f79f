#include "pdvo/vo/motion.h"

#include "pdvo/common/options.h"

namespace pdvo::vo {

bool MotionNoise::Check() const {
  PDVO_CHECK_OPTION(linear_acceleration > 0 && angular_acceleration > 0);
  PDVO_CHECK_OPTION(max_adaptation >= 1);
  return true;
}

CameraState CameraState::Plus(const Vector12d& d) const {
  CameraState s;
  s.position = position + d.segment<3>(0);
  s.orientation = (orientation * ExpSO3(d.segment<3>(3))).normalized();
  s.velocity = velocity + d.segment<3>(6);
  s.angular_velocity = angular_velocity + d.segment<3>(9);
  return s;
}

Vector12d CameraState::Minus(const CameraState& other) const {
  Vector12d d;
  d << position - other.position, LogSO3(other.orientation.conjugate() * orientation), velocity - other.velocity,
      angular_velocity - other.angular_velocity;
  return d;
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi) { return LeftJacobianSO3(-phi); }

CameraState PredictCamera(const CameraState& s, double dt, Matrix12d* f, Eigen::Matrix<double, 12, 6>* g) {
  const Eigen::Vector3d turn = s.angular_velocity * dt;
  const Eigen::Matrix3d step_rotation = ExpSO3(turn).toRotationMatrix();
  const Eigen::Matrix3d r = s.orientation.toRotationMatrix();
  // The velocity turns with the camera: the same in the camera frame before and after the step.
  const Eigen::Matrix3d velocity_turn = r * step_rotation * r.transpose();
  CameraState out = s;
  out.position = s.position + s.velocity * dt;
  out.orientation = (s.orientation * ExpSO3(turn)).normalized();
  out.velocity = velocity_turn * s.velocity;
  const Eigen::Matrix3d jr = RightJacobianSO3(turn);
  const Eigen::Matrix3d eye = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d body_velocity = r.transpose() * s.velocity;
  // The new velocity from the angular velocity: R E Exp(Jr W dt) u ~ R E (u - [u]x Jr W dt).
  const Eigen::Matrix3d velocity_from_turn = -dt * r * step_rotation * Hat(body_velocity) * jr;
  if (f) {
    f->setIdentity();
    f->block<3, 3>(0, 6) = dt * eye;                   // position from velocity
    f->block<3, 3>(3, 3) = step_rotation.transpose();  // an orientation error seen from the new orientation
    f->block<3, 3>(3, 9) = dt * jr;                    // orientation from angular velocity
    f->block<3, 3>(6, 6) = velocity_turn;
    // R Exp(d) E Exp(-d) R^T v ~ R (E u + [d]x E u - E [d]x u): the velocity from the orientation.
    f->block<3, 3>(6, 3) = r * Hat(step_rotation * body_velocity) * (step_rotation - eye);
    f->block<3, 3>(6, 9) = velocity_from_turn;
  }
  if (g) {
    g->setZero();
    g->block<3, 3>(0, 0) = dt * eye;
    g->block<3, 3>(3, 3) = dt * jr;
    g->block<3, 3>(6, 0) = velocity_turn;
    g->block<3, 3>(6, 3) = velocity_from_turn;
    g->block<3, 3>(9, 3) = eye;
  }
  return out;
}

Matrix12d ProcessNoise(const Eigen::Matrix<double, 12, 6>& g, double dt, double linear_acceleration,
                       double angular_acceleration) {
  Eigen::Matrix<double, 6, 1> variances;
  variances << Eigen::Vector3d::Constant(linear_acceleration * linear_acceleration * dt * dt),
      Eigen::Vector3d::Constant(angular_acceleration * angular_acceleration * dt * dt);
  return g * variances.asDiagonal() * g.transpose();
}

}  // namespace pdvo::vo
