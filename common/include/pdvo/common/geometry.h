// Rigid and similarity transforms on Eigen, with the SO(3) / SE(3) exponential and logarithm maps.
//
// Convention: a transform named `b_from_a` maps coordinates in frame a to frame b, so
// point_in_cam = cam_from_world * point_in_world. Quaternions are Hamilton, stored by Eigen as (x, y, z, w)
// and constructed as (w, x, y, z); file formats (TUM) write them x y z w.
// Tangent vectors of SE(3) are ordered (rho, phi): translation part first, rotation part second.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pdvo {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The skew-symmetric matrix [v]x with [v]x * w = v.cross(w).
Eigen::Matrix3d Hat(const Eigen::Vector3d& v);

// SO(3): rotation vector (axis * angle, radians) <-> rotation. Exact for small angles too.
Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& phi);
Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q);

// The angle between two directions (vectors of any non-zero length), in degrees, in [0, 180].
double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// A seen plane faces the camera (normal . ray < 0). `normal` if it does; else the nearest unit normal that does,
// `past_edge_on` beyond edge-on (its cosine with the unit ray is -past_edge_on; 0: exactly edge-on), or -ray when
// `normal` lies along the ray.
Eigen::Vector3d NearestFacingNormal(const Eigen::Vector3d& normal, const Eigen::Vector3d& ray, double past_edge_on = 0);

// The left Jacobian of SO(3) at phi, used by the SE(3) maps.
Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& phi);

// The rotation nearest to `m` in the Frobenius norm (SVD, determinant +1): re-orthonormalises a noisy rotation
// matrix, and of a sum of rotation matrices gives their chordal mean.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);

// A rigid transform x -> rotation * x + translation.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) : rotation(r.normalized()), translation(t) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation * other.rotation, rotation * other.translation + translation);
  }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3d(inv, -(inv * translation));
  }
  // The 3x4 matrix [R | t].
  Eigen::Matrix<double, 3, 4> ToMatrix3x4() const;
  // Builds from [R | t]; R is re-orthonormalised (nearest rotation).
  static Rigid3d FromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m);
};

// SE(3) exponential and logarithm with the (rho, phi) ordering.
Rigid3d ExpSE3(const Vector6d& xi);
Vector6d LogSE3(const Rigid3d& transform);

// A similarity transform x -> scale * rotation * x + translation.
struct Sim3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return scale * (rotation * x) + translation; }
  // Applies the similarity to a pose world_from_cam: positions are scaled, orientations rotated.
  Rigid3d operator*(const Rigid3d& world_from_cam) const {
    return Rigid3d(rotation * world_from_cam.rotation, *this * world_from_cam.translation);
  }
};

// Angle between two rotations, in radians.
double AngularDistance(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace pdvo
