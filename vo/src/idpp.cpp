#include "pdvo/vo/idpp.h"

#include <opencv2/core/eigen.hpp>

namespace pdvo::vo {

double InversePlane::InverseDepthAlong(const Eigen::Vector3d& ray) const {
  return -inverse_distance * normal.normalized().dot(ray);
}

Eigen::RowVector4d InversePlane::InverseDepthJacobian(const Eigen::Vector3d& ray) const {
  const double norm = normal.norm();
  const Eigen::Vector3d unit = normal / norm;
  Eigen::RowVector4d j;
  j << -inverse_distance * ray.transpose() * (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / norm,
      -unit.dot(ray);
  return j;
}

InversePlane InversePlane::InFrame(const Rigid3d& old_from_new, Eigen::Matrix4d* jacobian) const {
  const Eigen::Matrix3d r = old_from_new.rotation.toRotationMatrix();
  const Eigen::Vector3d& t = old_from_new.translation;
  const double norm = normal.norm();
  const Eigen::Vector3d unit = normal / norm;
  const double distance = unit.dot(t) + 1 / inverse_distance;  // from the new camera's centre
  InversePlane out{r.transpose() * normal, distance > 0 ? 1 / distance : 0};
  if (jacobian && distance > 0) {
    const double rho2 = out.inverse_distance * out.inverse_distance;
    jacobian->setZero();
    jacobian->topLeftCorner<3, 3>() = r.transpose();
    jacobian->block<1, 3>(3, 0) =
        -rho2 * t.transpose() * (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / norm;
    (*jacobian)(3, 3) = rho2 / (inverse_distance * inverse_distance);
  }
  return out;
}

bool ProjectInverseDepth(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                         const Eigen::Vector3d& ray, double rho, Eigen::Vector2d* pixel, ProjectionJacobians* j) {
  const Eigen::Matrix3d rc_t = world_from_current.rotation.toRotationMatrix().transpose();
  const Eigen::Matrix3d rr = world_from_ref.rotation.toRotationMatrix();
  const Eigen::Vector3d baseline = world_from_ref.translation - world_from_current.translation;
  const Eigen::Vector3d h = rc_t * (rho * baseline + rr * ray);
  if (h.z() <= 1e-9 * h.norm()) return false;
  *pixel = camera.Project(h);
  if (!j) return true;
  Matrix23d dpixel_dh;
  dpixel_dh << camera.fx / h.z(), 0, -camera.fx * h.x() / (h.z() * h.z()), 0, camera.fy / h.z(),
      -camera.fy * h.y() / (h.z() * h.z());
  j->current << dpixel_dh * (-rho * rc_t), dpixel_dh * Hat(h);
  j->reference << dpixel_dh * (rho * rc_t), dpixel_dh * (-rc_t * rr * Hat(ray));
  j->inverse_depth = dpixel_dh * (rc_t * baseline);
  return true;
}

bool ProjectPlanePoint(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                       const InversePlane& plane, const Eigen::Vector3d& ray, Eigen::Vector2d* pixel,
                       ProjectionJacobians* j, Eigen::Matrix<double, 2, 4>* plane_jacobian) {
  const double rho = plane.InverseDepthAlong(ray);
  if (rho <= 0) return false;
  if (!ProjectInverseDepth(camera, world_from_current, world_from_ref, ray, rho, pixel, j)) return false;
  if (plane_jacobian && j) *plane_jacobian = j->inverse_depth * plane.InverseDepthJacobian(ray);
  return true;
}

Eigen::Matrix3d PlaneHomography(const Camera& camera, const Rigid3d& world_from_current, const Rigid3d& world_from_ref,
                                const InversePlane& plane) {
  const Rigid3d current_from_ref = world_from_current.Inverse() * world_from_ref;
  Eigen::Matrix3d k;
  cv::cv2eigen(camera.K(), k);
  const Eigen::Matrix3d euclidean =
      current_from_ref.rotation.toRotationMatrix() -
      plane.inverse_distance * current_from_ref.translation * plane.normal.normalized().transpose();
  return k * euclidean * k.inverse();
}

InversePlane FrontoParallel(const Eigen::Vector3d& ray, double inverse_depth) {
  return {-ray.normalized(), inverse_depth};
}

}  // namespace pdvo::vo
