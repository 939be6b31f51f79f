// The geometry of the IDPP map (the paper's section IV): points and planes in one inverse-depth form, anchored
// at reference cameras (the keyframe poses at which they were initialised, kept in the filter's state).
//
// A point is its keyframe ray m (a unit vector in the reference camera, fixed) and an inverse depth rho along
// it: point_in_ref = m / rho. A plane is a normal n (3 values, used normalised: n^ = n / |n|, pointing towards
// the reference camera) and an inverse distance rho_p (1 / the distance from the reference camera centre to the
// plane): n^ . point_in_ref + 1 / rho_p = 0. A plane's point is its keyframe ray alone; its inverse depth is
// where the ray meets the plane, rho = -rho_p (n^ . m). A point costs one state value, a plane four.
//
// Measurements are pixels of the current camera, a pdvo::Camera without distortion (the working camera of
// FramePreparer, frames.h). Jacobians are with respect to the error states: a camera's (dp, dtheta) as in
// motion.h (position in the world, rotation perturbed on the right).
#pragma once

#include <Eigen/Core>

#include "pdvo/common/camera.h"
#include "pdvo/common/geometry.h"

namespace pdvo::vo {

using Matrix23d = Eigen::Matrix<double, 2, 3>;
using Matrix26d = Eigen::Matrix<double, 2, 6>;

struct InversePlane {
  Eigen::Vector3d normal;  // towards the reference camera; not necessarily unit
  double inverse_distance = 0;
  // The inverse depth at which the ray m (unit, reference frame) meets the plane; <= 0 if it does not in front.
  double InverseDepthAlong(const Eigen::Vector3d& ray) const;
  // Its derivative with respect to (n, rho_p): rho = -rho_p (n^ . m) with d n^ / d n = (I - n^ n^T) / |n|.
  Eigen::RowVector4d InverseDepthJacobian(const Eigen::Vector3d& ray) const;
  // The same plane in the frame of another camera, given old_from_new (points x_old = old_from_new * x_new):
  // n' = R^T n (its length kept) and rho_p' = 1 / (n^ . t + 1 / rho_p). `jacobian` (4x4): d(n', rho_p') /
  // d(n, rho_p) with the cameras exact. The result's inverse_distance is <= 0 if the new camera is not on the
  // side the normal points to (it would not see the plane's front).
  InversePlane InFrame(const Rigid3d& old_from_new, Eigen::Matrix4d* jacobian = nullptr) const;
};

// Jacobians of a projected pixel.
struct ProjectionJacobians {
  Matrix26d current;              // w.r.t. the current camera's (dp, dtheta)
  Matrix26d reference;            // w.r.t. the reference camera's (dp, dtheta)
  Eigen::Vector2d inverse_depth;  // w.r.t. a point's rho
};

// The pixel at which the current camera sees the point (ray, rho) of the reference camera; nothing (false) if it
// lies behind the current camera. h = R_c^T (rho (p_r - p_c) + R_r m) is the point scaled by rho, which stays
// finite as rho -> 0 (points at infinity).
bool ProjectInverseDepth(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                         const Eigen::Vector3d& ray, double inverse_depth, Eigen::Vector2d* pixel,
                         ProjectionJacobians* jacobians = nullptr);

// The same for a plane's point: its rho comes from the plane; `plane_jacobian` (2x4) is w.r.t. (n, rho_p).
bool ProjectPlanePoint(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                       const InversePlane& plane, const Eigen::Vector3d& ray, Eigen::Vector2d* pixel,
                       ProjectionJacobians* jacobians = nullptr, Eigen::Matrix<double, 2, 4>* plane_jacobian = nullptr);

// The homography taking reference pixels to current pixels for points of the plane:
// H = K (R_cr - rho_p t_cr n^T) K^-1, with (R_cr, t_cr) = current_from_ref.
Eigen::Matrix3d PlaneHomography(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                                const InversePlane& plane);
// A point's patch is taken as fronto-parallel: the plane through it facing its reference camera.
InversePlane FrontoParallel(const Eigen::Vector3d& ray, double inverse_depth);

}  // namespace pdvo::vo
