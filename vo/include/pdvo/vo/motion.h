// The camera of the EKF (the paper's section IV, after Davison's MonoSLAM): position and orientation in the
// world, linear velocity (world frame) and angular velocity (camera frame), under a constant-velocity model
// driven by random accelerations, whose velocity turns with the camera (constant in the camera frame: a car keeps
// driving forward through a corner, where a velocity constant in the world would carry it straight on). The filter
// works on a 12-D error state
//   (dp, dtheta, dv, dw):  p + dp,  q * Exp(dtheta) (rotation perturbed on the right, in the camera frame),
//                          v + dv,  w + dw.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pdvo/common/geometry.h"

namespace pdvo::vo {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;

// The constant-velocity model's process noise: standard deviations of the random accelerations.
struct MotionNoise {
  double linear_acceleration = 0.25;  // m/s^2
  double angular_acceleration = 4.0;  // rad/s^2
  // Adaptive: while the matches' innovations are larger than the prediction allows (their mean normalised
  // innovation squared over 1 in two frames in a row), the odometry doubles both standard deviations each frame,
  // up to this factor, and shrinks them back (by 1.2 a frame, under 0.3) when the motion calms down. 1: fixed.
  double max_adaptation = 4.0;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("linear_acceleration", self.linear_acceleration);
    visit("angular_acceleration", self.angular_acceleration);
    visit("max_adaptation", self.max_adaptation);
  }
  // The noise with both standard deviations times `factor`.
  MotionNoise Scaled(double factor) const {
    MotionNoise out = *this;
    out.linear_acceleration *= factor;
    out.angular_acceleration *= factor;
    return out;
  }
  bool Check() const;
  bool operator==(const MotionNoise&) const = default;
};

struct CameraState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // camera centre in the world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_cam rotation
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               // world frame, per second
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       // camera frame, rad per second

  Rigid3d world_from_cam() const { return Rigid3d(orientation, position); }
  // The state moved by an error-state step, and the step from `other` to this (inverse of Plus).
  CameraState Plus(const Vector12d& delta) const;
  Vector12d Minus(const CameraState& other) const;
};

// Constant velocity over dt seconds, the velocities taking random impulses V = a dt and W = alpha dt first:
//   p' = p + (v + V) dt,  q' = q Exp((w + W) dt),  v' = q' q^-1 (v + V),  w' = w + W.
// With `f` and `g`, the Jacobians of the error state after the step with respect to the error state before it
// (12x12) and to the impulses (V, W) (12x6), at zero impulse.
CameraState PredictCamera(const CameraState& state, double dt, Matrix12d* f = nullptr,
                          Eigen::Matrix<double, 12, 6>* g = nullptr);

// The process noise of a step: g diag(sigma_a^2 dt^2 I, sigma_alpha^2 dt^2 I) g^T, with accelerations in
// m/s^2 and rad/s^2 (standard deviations).
Matrix12d ProcessNoise(const Eigen::Matrix<double, 12, 6>& g, double dt, double linear_acceleration,
                       double angular_acceleration);

// The right Jacobian of SO(3): Exp(phi + d) ~ Exp(phi) Exp(Jr(phi) d).
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi);

}  // namespace pdvo::vo
