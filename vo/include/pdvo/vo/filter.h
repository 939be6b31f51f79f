// The EKF's state and its operations (the paper's section IV): the camera (motion.h), reference cameras (the
// poses of keyframes at which features were initialised, shared by those features), and inverse-depth points
// and planes anchored at them (idpp.h), with one dense covariance over the error state
//   [camera 12 | per reference camera 6 (dp, dtheta) | per point 1 (rho) | per plane 4 (n, rho_p)]
// in the order they were added. A plane's points are keyframe rays outside the state: a plane costs four values
// however many points it holds. Features and reference cameras are named by ids (one sequence for all) that
// stay valid while the rest of the state changes. Cameras are pdvo::Camera without distortion; pixels theirs.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <map>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/vo/idpp.h"
#include "pdvo/vo/motion.h"

namespace pdvo::vo {

// What became of an update. Per-frame failures are values: the filter is left as it was unless kOk.
enum class UpdateStatus {
  kOk,
  kNoMeasurements,  // nothing to update with
  kNotInFront,      // a measured feature is not in front of the camera (no prediction)
  kNotPositive,     // the innovation covariance is not positive definite (numerically)
  kNonFinite,       // the step or the innovation is not finite
};
const char* ToString(UpdateStatus status);  // "ok", "no-measurements", "not-in-front", "not-positive", "non-finite"
struct UpdateResult {
  UpdateStatus status = UpdateStatus::kOk;
  double nis = 0;  // normalised innovation squared (chi-square with 2 x count degrees of freedom) when kOk
  bool ok() const { return status == UpdateStatus::kOk; }
};

// One pixel measurement of a point, or of one of a plane's points (given by its keyframe ray).
struct PointMeasurement {
  int point = -1;                                 // point id, or plane id
  Eigen::Vector2d pixel;                          // measured, current camera (pinhole, undistorted)
  double sigma = 1.0;                             // pixels
  Eigen::Vector3d ray = Eigen::Vector3d::Zero();  // planes: the measured point's ray (unit, reference frame)
};

// A measurement's Jacobian with respect to the error state (2 x Filter::size()), kept as its only non-zero
// blocks: the current camera's pose (columns 0-5), the feature's reference camera (6 columns at its offset) and
// the feature itself (a point's inverse depth: 1 column; a plane: 4). Products with the covariance then cost
// O(size) instead of O(size^2).
struct MeasurementJacobian {
  Eigen::Matrix<double, 2, 6> camera = Eigen::Matrix<double, 2, 6>::Zero();
  Eigen::Matrix<double, 2, 6> reference = Eigen::Matrix<double, 2, 6>::Zero();
  Eigen::Matrix<double, 2, 4> feature = Eigen::Matrix<double, 2, 4>::Zero();  // its first feature_size columns
  int reference_offset = 0, feature_offset = 0, feature_size = 1;

  Eigen::MatrixXd Dense(int size) const;  // the 2 x size matrix
  // P J^T (size x 2) for a covariance P.
  Eigen::Matrix<double, Eigen::Dynamic, 2> CovarianceTimesTranspose(const Eigen::MatrixXd& p) const;
  // J P J^T: the predicted pixel's covariance.
  Eigen::Matrix2d Propagate(const Eigen::MatrixXd& p) const;
  // J X for X with size() rows (e.g. P H^T of several measurements: then their rows of H P H^T).
  Eigen::Matrix<double, 2, Eigen::Dynamic> Times(const Eigen::MatrixXd& x) const;
};

class Filter {
 public:
  struct Reference {
    Rigid3d world_from_cam;
    int offset = 0;  // in the error state
    int users = 0;   // points anchored here
  };
  struct Point {
    int reference = -1;
    Eigen::Vector3d ray;  // unit, reference camera frame
    double inverse_depth = 0;
    int offset = 0;
  };
  struct Plane {
    int reference = -1;
    InversePlane plane;  // reference camera frame
    int offset = 0;
  };

  Filter(const CameraState& camera, const Matrix12d& covariance);

  const CameraState& camera() const { return camera_; }
  const Eigen::MatrixXd& covariance() const { return covariance_; }
  int size() const { return static_cast<int>(covariance_.rows()); }
  const std::map<int, Reference>& references() const { return references_; }
  const std::map<int, Point>& points() const { return points_; }
  const std::map<int, Plane>& planes() const { return planes_; }

  // Constant velocity over dt seconds (PredictCamera), with its process noise. Throws for dt < 0.
  void Predict(double dt, const MotionNoise& noise);

  // A reference camera at the current camera's pose. Tracked (fixed = false): it takes the camera pose's
  // covariance and correlations, and later updates move it with the camera. Fixed: the pose is taken as exact
  // (no variance, no correlation), so no update moves it: the map's frame is fixed again at each keyframe, as
  // the first camera's is at the start (docs/odometry.md says why).
  int AddReference(bool fixed);
  // A point on the ray (reference frame) at inverse depth rho with standard deviation sigma_rho, uncorrelated
  // with the rest of the state. Adding several at once grows the covariance once. Returns the ids.
  struct NewPoint {
    Eigen::Vector3d ray;
    double rho = 0, sigma_rho = 0;
  };
  std::vector<int> AddPoints(int reference, const std::vector<NewPoint>& points);
  int AddPoint(int reference, const Eigen::Vector3d& ray, double rho, double sigma_rho) {
    return AddPoints(reference, {{ray, rho, sigma_rho}}).front();
  }
  // A plane with independent standard deviations for each normal component and its inverse distance.
  int AddPlane(int reference, const InversePlane& plane, double sigma_normal, double sigma_inverse_distance);
  // Removes points or a plane; a reference camera goes when its last feature does. Removing several points at
  // once copies the covariance once.
  void RemovePoint(int point) { RemovePoints({point}); }
  void RemovePoints(const std::vector<int>& points);
  void RemovePlane(int plane);
  // A plane that could not grow becomes a point on `ray` (unit, reference frame): the point's inverse depth is
  // where the ray meets the plane, with the covariance that follows (first order). Returns the point's id.
  int PlaneToPoint(int plane, const Eigen::Vector3d& ray);
  // A point of the plane's reference camera joins the plane: what the point's inverse depth says is fused into
  // the plane (an update with the constraint rho_point = rho_plane(ray), standard deviation `sigma` in inverse
  // depth: how far off the plane a point may be), then the point leaves the state. If the fusion fails (not
  // kOk), nothing changes and the point stays.
  UpdateStatus MergePointIntoPlane(int point, int plane, double sigma);

  // The plane moves to reference camera `reference`: the same plane in that camera's frame (InversePlane::InFrame),
  // its covariance rows and columns carried by the transform's Jacobian. Its old reference camera goes if it has
  // no other feature. Both cameras' poses must be exact (fixed references, AddReference); false, and nothing
  // changes, if they are not, or if the new camera does not see the plane's front.
  bool MovePlane(int plane, int reference);
  // Plane `plane` as reference camera `reference` sees it (InversePlane::InFrame; `jacobian` with both cameras
  // taken as exact).
  InversePlane PlaneSeenFrom(int plane, int reference, Eigen::Matrix4d* jacobian = nullptr) const;

  // The predicted pixel of a point and its Jacobian with respect to the whole error state (2 x size()); false
  // if the point is behind the camera.
  bool PredictPoint(const Camera& camera, int point, Eigen::Vector2d* pixel, MeasurementJacobian* jacobian) const;
  // The same for the point of a plane on `ray`; false also if the ray does not meet the plane in front.
  bool PredictPlanePoint(const Camera& camera, int plane, const Eigen::Vector3d& ray, Eigen::Vector2d* pixel,
                         MeasurementJacobian* jacobian) const;

  // The predicted pixel of a measurement's feature (a point, or the plane point on its ray), as above.
  bool PredictMeasurement(const Camera& camera, const PointMeasurement& z, Eigen::Vector2d* pixel,
                          MeasurementJacobian* jacobian) const;

  // One batched EKF update with the measurements (their features must exist).
  UpdateResult Update(const Camera& camera, const std::vector<PointMeasurement>& measurements);
  // The step (size()) that Update would add to the state, computed without changing the filter or copying its
  // covariance: 1-point RANSAC's hypotheses (robust_update.h). `step` is set only when kOk.
  UpdateStatus Step(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                    Eigen::VectorXd* step) const;
  // The predicted pixels of the measurements' features as PredictMeasurement would give them after
  // Apply(step), without changing the filter; `predicted[k]` is false where there is no prediction.
  void PredictAfter(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                    const Eigen::VectorXd& step, std::vector<Eigen::Vector2d>* pixels,
                    std::vector<bool>* predicted) const;

  // Adds `delta` (size()) to the state: the camera and reference cameras on their manifolds. Throws if
  // `delta` has the wrong size or is not finite.
  void Apply(const Eigen::VectorXd& delta);

 private:
  // The measurements' Jacobians, their stacked innovation (measured - predicted) and noise variances.
  struct Linearised {
    std::vector<MeasurementJacobian> jacobians;
    Eigen::VectorXd innovation, noise;
  };
  UpdateStatus Linearise(const Camera& camera, const std::vector<PointMeasurement>& measurements,
                         Linearised* out) const;
  // The Kalman gain's parts: P H^T and the Cholesky factor of the innovation covariance S = H P H^T + R.
  struct Gain {
    Eigen::MatrixXd ph_t;
    Eigen::LLT<Eigen::MatrixXd> llt;
  };
  UpdateStatus ComputeGain(const Linearised& l, Gain* gain) const;
  // The same from P H^T and S.
  static UpdateStatus ComputeGain(Eigen::MatrixXd ph_t, const Eigen::MatrixXd& s, Gain* gain);
  // The EKF correction: the state moves by K innovation and P becomes P - K H P.
  UpdateResult Correct(const Gain& gain, const Eigen::VectorXd& innovation);
  // Drops the error-state indices `dropped` and, of `references` (one entry per removed feature), those left
  // without users.
  void Remove(std::vector<int> dropped, const std::vector<int>& references);
  void Renumber();
  // Grows the covariance by variances.size() rows and columns, zero but for `variances` on the new diagonal.
  void Augment(const Eigen::VectorXd& variances);

  CameraState camera_;
  Eigen::MatrixXd covariance_;
  std::map<int, Reference> references_;
  std::map<int, Point> points_;
  std::map<int, Plane> planes_;
  int next_id_ = 0;
};

}  // namespace pdvo::vo
