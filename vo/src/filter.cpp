#include "pdvo/vo/filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "pdvo/common/errors.h"

namespace pdvo::vo {

const char* ToString(UpdateStatus status) {
  switch (status) {
    case UpdateStatus::kOk: return "ok";
    case UpdateStatus::kNoMeasurements: return "no-measurements";
    case UpdateStatus::kNotInFront: return "not-in-front";
    case UpdateStatus::kNotPositive: return "not-positive";
    case UpdateStatus::kNonFinite: return "non-finite";
  }
  return "?";
}

Eigen::MatrixXd MeasurementJacobian::Dense(int size) const {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(2, size);
  j.leftCols<6>() = camera;
  j.middleCols<6>(reference_offset) += reference;
  j.middleCols(feature_offset, feature_size) += feature.leftCols(feature_size);
  return j;
}

Eigen::Matrix<double, Eigen::Dynamic, 2> MeasurementJacobian::CovarianceTimesTranspose(const Eigen::MatrixXd& p) const {
  return p.leftCols<6>() * camera.transpose() + p.middleCols<6>(reference_offset) * reference.transpose() +
         p.middleCols(feature_offset, feature_size) * feature.leftCols(feature_size).transpose();
}

Eigen::Matrix<double, 2, Eigen::Dynamic> MeasurementJacobian::Times(const Eigen::MatrixXd& x) const {
  return camera * x.topRows<6>() + reference * x.middleRows<6>(reference_offset) +
         feature.leftCols(feature_size) * x.middleRows(feature_offset, feature_size);
}

Eigen::Matrix2d MeasurementJacobian::Propagate(const Eigen::MatrixXd& p) const {
  // The blocks of P that the three column blocks meet: nine small products.
  const int offsets[3] = {0, reference_offset, feature_offset}, sizes[3] = {6, 6, feature_size};
  const Eigen::Matrix<double, 2, Eigen::Dynamic> blocks[3] = {camera, reference, feature.leftCols(feature_size)};
  Eigen::Matrix2d out = Eigen::Matrix2d::Zero();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      out += blocks[a] * p.block(offsets[a], offsets[b], sizes[a], sizes[b]) * blocks[b].transpose();
    }
  }
  return out;
}

Filter::Filter(const CameraState& camera, const Matrix12d& covariance) : camera_(camera), covariance_(covariance) {}

void Filter::Predict(double dt, const MotionNoise& noise) {
  PDVO_THROW_CHECK(dt >= 0, InvalidArgument, "filter: time went backwards (dt " << dt << " s)");
  Matrix12d f;
  Eigen::Matrix<double, 12, 6> g;
  camera_ = PredictCamera(camera_, dt, &f, &g);
  const int n = size();
  covariance_.topLeftCorner<12, 12>() = f * covariance_.topLeftCorner<12, 12>() * f.transpose() +
                                        ProcessNoise(g, dt, noise.linear_acceleration, noise.angular_acceleration);
  if (n > 12) {
    covariance_.topRightCorner(12, n - 12) = f * covariance_.topRightCorner(12, n - 12);
    covariance_.bottomLeftCorner(n - 12, 12) = covariance_.topRightCorner(12, n - 12).transpose();
  }
}

int Filter::AddReference(bool fixed) {
  const int n = size();
  if (fixed) {
    Augment(Eigen::VectorXd::Zero(6));
  } else {
    Eigen::MatrixXd p = Eigen::MatrixXd::Zero(n + 6, n + 6);
    p.topLeftCorner(n, n) = covariance_;
    p.bottomRows(6).leftCols(n) = covariance_.topRows(6);  // the camera pose's rows: (dp, dtheta)
    p.rightCols(6).topRows(n) = covariance_.leftCols(6);
    p.bottomRightCorner(6, 6) = covariance_.topLeftCorner(6, 6);
    covariance_ = std::move(p);
  }
  const int id = next_id_++;
  references_[id] = {camera_.world_from_cam(), n, 0};
  return id;
}

void Filter::Augment(const Eigen::VectorXd& variances) {
  const Eigen::Index n = size(), k = variances.size();
  covariance_.conservativeResize(n + k, n + k);
  covariance_.bottomRows(k).setZero();
  covariance_.rightCols(k).setZero();
  covariance_.bottomRightCorner(k, k).diagonal() = variances;
}

std::vector<int> Filter::AddPoints(int reference, const std::vector<NewPoint>& points) {
  auto r = references_.find(reference);
  PDVO_THROW_CHECK(r != references_.end(), InvalidArgument, "filter: no reference camera " << reference);
  Eigen::VectorXd variances(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    PDVO_THROW_CHECK(points[k].sigma_rho > 0 && std::isfinite(points[k].rho), InvalidArgument,
                     "filter: bad inverse depth prior");
    variances[k] = points[k].sigma_rho * points[k].sigma_rho;
  }
  const int offset = size();
  Augment(variances);
  std::vector<int> ids;
  for (size_t k = 0; k < points.size(); ++k) {
    ++r->second.users;
    ids.push_back(next_id_++);
    points_[ids.back()] = {reference, points[k].ray.normalized(), points[k].rho, offset + static_cast<int>(k)};
  }
  return ids;
}

int Filter::AddPlane(int reference, const InversePlane& plane, double sigma_normal, double sigma_inverse_distance) {
  auto r = references_.find(reference);
  PDVO_THROW_CHECK(r != references_.end(), InvalidArgument, "filter: no reference camera " << reference);
  PDVO_THROW_CHECK(plane.normal.norm() > 0 && plane.normal.allFinite() && std::isfinite(plane.inverse_distance) &&
                       sigma_normal > 0 && sigma_inverse_distance > 0,
                   InvalidArgument, "filter: bad plane prior");
  const int offset = size();
  Eigen::Vector4d variances;
  variances << Eigen::Vector3d::Constant(sigma_normal * sigma_normal), sigma_inverse_distance * sigma_inverse_distance;
  Augment(variances);
  ++r->second.users;
  const int id = next_id_++;
  planes_[id] = {reference, plane, offset};
  return id;
}

void Filter::RemovePoints(const std::vector<int>& ids) {
  if (ids.empty()) return;
  std::vector<int> dropped, references;
  for (int id : ids) {
    auto p = points_.find(id);
    PDVO_THROW_CHECK(p != points_.end(), InvalidArgument, "filter: no point " << id);
    dropped.push_back(p->second.offset);
    references.push_back(p->second.reference);
    points_.erase(p);
  }
  Remove(std::move(dropped), references);
}

void Filter::RemovePlane(int id) {
  auto p = planes_.find(id);
  PDVO_THROW_CHECK(p != planes_.end(), InvalidArgument, "filter: no plane " << id);
  const int o = p->second.offset;
  const std::vector<int> dropped = {o, o + 1, o + 2, o + 3};
  const int reference = p->second.reference;
  planes_.erase(p);
  Remove(dropped, {reference});
}

void Filter::Remove(std::vector<int> dropped, const std::vector<int>& references) {
  for (int reference : references) {
    auto r = references_.find(reference);
    if (--r->second.users == 0) {
      for (int k = 0; k < 6; ++k) dropped.push_back(r->second.offset + k);
      references_.erase(r);
    }
  }
  std::vector<bool> drop(size(), false);
  for (int i : dropped) drop[i] = true;
  std::vector<int> keep;
  for (int i = 0; i < size(); ++i) {
    if (!drop[i]) keep.push_back(i);
  }
  covariance_ = Eigen::MatrixXd(covariance_(keep, keep));
  Renumber();
}

int Filter::PlaneToPoint(int plane_id, const Eigen::Vector3d& ray) {
  auto it = planes_.find(plane_id);
  PDVO_THROW_CHECK(it != planes_.end(), InvalidArgument, "filter: no plane " << plane_id);
  const Plane plane = it->second;
  const Eigen::Vector3d m = ray.normalized();
  const double rho = plane.plane.InverseDepthAlong(m);
  const Eigen::RowVector4d j = plane.plane.InverseDepthJacobian(m);
  const int n = size();
  const Eigen::RowVectorXd cross = j * covariance_.middleRows<4>(plane.offset);  // with the whole state
  Augment(Eigen::VectorXd::Zero(1));
  covariance_.row(n).head(n) = cross;
  covariance_.col(n).head(n) = cross.transpose();
  covariance_(n, n) = (j * covariance_.block<4, 4>(plane.offset, plane.offset) * j.transpose())(0, 0);
  ++references_.at(plane.reference).users;
  const int id = next_id_++;
  points_[id] = {plane.reference, m, rho, n};
  RemovePlane(plane_id);
  return id;
}

UpdateStatus Filter::MergePointIntoPlane(int point_id, int plane_id, double sigma) {
  PDVO_THROW_CHECK(points_.count(point_id) && planes_.count(plane_id), InvalidArgument,
                   "filter: no point " << point_id << " or plane " << plane_id);
  PDVO_THROW_CHECK(sigma > 0, InvalidArgument, "filter: a plane merge needs a positive sigma, got " << sigma);
  const Point& p = points_.at(point_id);
  const Plane& q = planes_.at(plane_id);
  PDVO_THROW_CHECK(p.reference == q.reference, InvalidArgument,
                   "filter: point " << point_id << " and plane " << plane_id << " have different reference cameras");
  // r = rho_point - rho_plane(ray), measured as 0.
  Eigen::RowVectorXd h = Eigen::RowVectorXd::Zero(size());
  h[p.offset] = 1;
  h.segment<4>(q.offset) = -q.plane.InverseDepthJacobian(p.ray);
  Eigen::MatrixXd ph_t = covariance_ * h.transpose();
  const Eigen::MatrixXd s = h * ph_t + Eigen::MatrixXd::Constant(1, 1, sigma * sigma);
  Gain g;
  const UpdateStatus status = ComputeGain(std::move(ph_t), s, &g);
  if (status != UpdateStatus::kOk) return status;
  const UpdateResult fused =
      Correct(g, Eigen::VectorXd::Constant(1, q.plane.InverseDepthAlong(p.ray) - p.inverse_depth));
  if (fused.ok()) RemovePoint(point_id);
  return fused.status;
}

bool Filter::MovePlane(int plane_id, int reference) {
  auto it = planes_.find(plane_id);
  PDVO_THROW_CHECK(it != planes_.end() && references_.count(reference), InvalidArgument,
                   "filter: no plane " << plane_id << " or reference camera " << reference);
  Plane& plane = it->second;
  if (plane.reference == reference) return true;
  const Reference& from = references_.at(plane.reference);
  const Reference& to = references_.at(reference);
  const auto exact = [&](const Reference& r) { return covariance_.middleRows<6>(r.offset).isZero(0); };
  if (!exact(from) || !exact(to)) return false;
  Eigen::Matrix4d j;
  const InversePlane moved = PlaneSeenFrom(plane_id, reference, &j);
  if (!(moved.inverse_distance > 0) || !moved.normal.allFinite()) return false;
  // P <- T P T^T with T the identity but for J on the plane's block.
  const int o = plane.offset;
  covariance_.middleRows<4>(o) = (j * covariance_.middleRows<4>(o)).eval();
  covariance_.middleCols<4>(o) = (covariance_.middleCols<4>(o) * j.transpose()).eval();
  plane.plane = moved;
  const int old_reference = plane.reference;
  plane.reference = reference;
  ++references_.at(reference).users;
  Remove({}, {old_reference});
  return true;
}

InversePlane Filter::PlaneSeenFrom(int plane_id, int reference, Eigen::Matrix4d* jacobian) const {
  const Plane& plane = planes_.at(plane_id);
  return plane.plane.InFrame(
      references_.at(plane.reference).world_from_cam.Inverse() * references_.at(reference).world_from_cam, jacobian);
}

void Filter::Renumber() {
  // Removal keeps the order of what stays: new offsets are the running sum of the block sizes in that order.
  struct Block {
    int old_offset;
    int* offset;
    int size;
  };
  std::vector<Block> blocks;
  for (auto& [id, r] : references_) blocks.push_back({r.offset, &r.offset, 6});
  for (auto& [id, p] : points_) blocks.push_back({p.offset, &p.offset, 1});
  for (auto& [id, p] : planes_) blocks.push_back({p.offset, &p.offset, 4});
  std::sort(blocks.begin(), blocks.end(), [](const Block& a, const Block& b) { return a.old_offset < b.old_offset; });
  int next = 12;
  for (Block& b : blocks) {
    *b.offset = next;
    next += b.size;
  }
}

bool Filter::PredictPoint(const Camera& camera, int id, Eigen::Vector2d* pixel, MeasurementJacobian* jacobian) const {
  const Point& p = points_.at(id);
  const Reference& r = references_.at(p.reference);
  ProjectionJacobians j;
  if (!ProjectInverseDepth(camera, camera_.world_from_cam(), r.world_from_cam, p.ray, p.inverse_depth, pixel,
                           jacobian ? &j : nullptr)) {
    return false;
  }
  if (jacobian) {
    jacobian->camera = j.current;
    jacobian->reference = j.reference;
    jacobian->feature.col(0) = j.inverse_depth;
    jacobian->reference_offset = r.offset;
    jacobian->feature_offset = p.offset;
    jacobian->feature_size = 1;
  }
  return true;
}

bool Filter::PredictPlanePoint(const Camera& camera, int id, const Eigen::Vector3d& ray, Eigen::Vector2d* pixel,
                               MeasurementJacobian* jacobian) const {
  const Plane& p = planes_.at(id);
  const Reference& r = references_.at(p.reference);
  ProjectionJacobians j;
  Eigen::Matrix<double, 2, 4> jp;
  if (!ProjectPlanePoint(camera, camera_.world_from_cam(), r.world_from_cam, p.plane, ray, pixel,
                         jacobian ? &j : nullptr, jacobian ? &jp : nullptr)) {
    return false;
  }
  if (jacobian) {
    jacobian->camera = j.current;
    jacobian->reference = j.reference;
    jacobian->feature = jp;
    jacobian->reference_offset = r.offset;
    jacobian->feature_offset = p.offset;
    jacobian->feature_size = 4;
  }
  return true;
}

bool Filter::PredictMeasurement(const Camera& camera, const PointMeasurement& z, Eigen::Vector2d* pixel,
                                MeasurementJacobian* jacobian) const {
  return planes_.count(z.point) ? PredictPlanePoint(camera, z.point, z.ray, pixel, jacobian)
                                : PredictPoint(camera, z.point, pixel, jacobian);
}

UpdateStatus Filter::Linearise(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                               Linearised* l) const {
  if (measurements.empty()) return UpdateStatus::kNoMeasurements;
  const int m = 2 * static_cast<int>(measurements.size());
  l->jacobians.resize(measurements.size());
  l->innovation.resize(m);
  l->noise.resize(m);
  for (size_t k = 0; k < measurements.size(); ++k) {
    Eigen::Vector2d predicted;
    const PointMeasurement& z = measurements[k];
    if (!PredictMeasurement(camera, z, &predicted, &l->jacobians[k])) return UpdateStatus::kNotInFront;
    l->innovation.segment<2>(2 * k) = z.pixel - predicted;
    l->noise.segment<2>(2 * k).setConstant(z.sigma * z.sigma);
  }
  return l->innovation.allFinite() ? UpdateStatus::kOk : UpdateStatus::kNonFinite;
}

UpdateStatus Filter::ComputeGain(const Linearised& l, Gain* g) const {
  const int m = static_cast<int>(l.innovation.size());
  Eigen::MatrixXd ph_t(size(), m);
  for (size_t k = 0; k < l.jacobians.size(); ++k) {
    ph_t.middleCols<2>(2 * k) = l.jacobians[k].CovarianceTimesTranspose(covariance_);
  }
  Eigen::MatrixXd s(m, m);
  for (size_t k = 0; k < l.jacobians.size(); ++k) s.middleRows<2>(2 * k) = l.jacobians[k].Times(ph_t);
  s.diagonal() += l.noise;
  return ComputeGain(std::move(ph_t), s, g);
}

UpdateStatus Filter::ComputeGain(Eigen::MatrixXd ph_t, const Eigen::MatrixXd& s, Gain* g) {
  g->llt.compute(s);
  if (g->llt.info() != Eigen::Success) return UpdateStatus::kNotPositive;
  g->ph_t = std::move(ph_t);
  return UpdateStatus::kOk;
}

UpdateResult Filter::Update(const Camera& camera, const std::vector<PointMeasurement>& measurements) {
  Linearised l;
  Gain g;
  UpdateStatus status = Linearise(camera, measurements, &l);
  if (status == UpdateStatus::kOk) status = ComputeGain(l, &g);
  if (status != UpdateStatus::kOk) return {status, 0};
  return Correct(g, l.innovation);
}

UpdateStatus Filter::Step(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                          Eigen::VectorXd* step) const {
  Linearised l;
  Gain g;
  UpdateStatus status = Linearise(camera, measurements, &l);
  if (status == UpdateStatus::kOk) status = ComputeGain(l, &g);
  if (status != UpdateStatus::kOk) return status;
  Eigen::VectorXd delta = g.ph_t * g.llt.solve(l.innovation);
  if (!delta.allFinite()) return UpdateStatus::kNonFinite;
  *step = std::move(delta);
  return UpdateStatus::kOk;
}

UpdateResult Filter::Correct(const Gain& g, const Eigen::VectorXd& innovation) {
  // With S = L L^T and W = L^-1 H P: K innovation = W^T L^-1 innovation and K H P = W^T W, a symmetric rank
  // update that costs half the product and keeps P exactly symmetric.
  const Eigen::VectorXd whitened = g.llt.matrixL().solve(innovation);
  const Eigen::MatrixXd w = g.llt.matrixL().solve(g.ph_t.transpose());
  const Eigen::VectorXd delta = w.transpose() * whitened;
  if (!delta.allFinite()) return {UpdateStatus::kNonFinite, 0};
  Apply(delta);
  covariance_.selfadjointView<Eigen::Lower>().rankUpdate(w.transpose(), -1);
  covariance_.triangularView<Eigen::StrictlyUpper>() = covariance_.transpose();
  return {UpdateStatus::kOk, whitened.squaredNorm()};
}

void Filter::PredictAfter(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                          const Eigen::VectorXd& step, std::vector<Eigen::Vector2d>* pixels,
                          std::vector<bool>* predicted) const {
  PDVO_THROW_CHECK(step.size() == size(), InvalidArgument, "filter: a step of the wrong size");
  // The moved camera and reference cameras, computed as Apply computes them.
  const Rigid3d current = camera_.Plus(step.head<12>()).world_from_cam();
  std::map<int, Rigid3d> references;
  for (const auto& [id, r] : references_) {
    references[id] = Rigid3d(r.world_from_cam.rotation * ExpSO3(step.segment<3>(r.offset + 3)),
                             r.world_from_cam.translation + step.segment<3>(r.offset));
  }
  pixels->assign(measurements.size(), Eigen::Vector2d::Zero());
  predicted->assign(measurements.size(), false);
  for (size_t k = 0; k < measurements.size(); ++k) {
    const PointMeasurement& z = measurements[k];
    Eigen::Vector2d& pixel = (*pixels)[k];
    if (const auto plane = planes_.find(z.point); plane != planes_.end()) {
      const Plane& p = plane->second;
      InversePlane moved = p.plane;
      moved.normal += step.segment<3>(p.offset);
      moved.inverse_distance += step[p.offset + 3];
      (*predicted)[k] = ProjectPlanePoint(camera, current, references.at(p.reference), moved, z.ray, &pixel);
    } else {
      const Point& p = points_.at(z.point);
      (*predicted)[k] = ProjectInverseDepth(camera, current, references.at(p.reference), p.ray,
                                            p.inverse_depth + step[p.offset], &pixel);
    }
  }
}

void Filter::Apply(const Eigen::VectorXd& delta) {
  PDVO_THROW_CHECK(delta.size() == size() && delta.allFinite(), InvalidArgument, "filter: bad state step");
  camera_ = camera_.Plus(delta.head<12>());
  for (auto& [id, r] : references_) {
    r.world_from_cam = Rigid3d(r.world_from_cam.rotation * ExpSO3(delta.segment<3>(r.offset + 3)),
                               r.world_from_cam.translation + delta.segment<3>(r.offset));
  }
  for (auto& [id, p] : points_) p.inverse_depth += delta[p.offset];
  for (auto& [id, p] : planes_) {
    p.plane.normal += delta.segment<3>(p.offset);
    p.plane.inverse_distance += delta[p.offset + 3];
  }
}

}  // namespace pdvo::vo
