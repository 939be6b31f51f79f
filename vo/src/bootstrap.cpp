#include "pdvo/vo/bootstrap.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <utility>

#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"

namespace pdvo::vo {
namespace {

// Lucas-Kanade: window (px) and pyramid levels above the image.
const cv::Size kFlowWindow(21, 21);
constexpr int kFlowLevels = 3;
// The essential matrix: RANSAC confidence and inlier distance (px); triangulated points farther than this
// (in units of the baseline) are dropped as at infinity.
constexpr double kRansacConfidence = 0.999;
constexpr double kRansacThreshold = 1.0;
constexpr double kFarthest = 1e6;
// Of the parallax asked for, the share that must remain once the best pure rotation is taken out: a shallow scene
// seen across a small turn fits an essential matrix of sideways motion with all the parallax a turn could give.
// Measured on the TUM fr1 excerpt: 0.33-0.75 give the same result; 0.25 lets such starts through.
constexpr double kMinUnexplainedShare = 0.5;

// EpipolarDisagreement: corners tracked, and the RANSAC confidence of its essential matrix.
constexpr int kCheckCorners = 100;
constexpr double kCheckConfidence = 0.99;

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The median angle (degrees) between the bearings `second` and those of `first` turned by the rotation that best
// maps the one onto the other (least squares): the parallax that no pure rotation explains. A camera that only
// turns has none, however its essential matrix decomposes.
double MedianUnexplainedByRotation(const std::vector<Eigen::Vector3d>& first,
                                   const std::vector<Eigen::Vector3d>& second) {
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < first.size(); ++i) correlation += second[i] * first[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d rotation = svd.matrixU() * d * svd.matrixV().transpose();
  std::vector<double> angles;
  for (size_t i = 0; i < first.size(); ++i) angles.push_back(AngleDeg(second[i], rotation * first[i]));
  return Median(angles);
}

// The essential matrix [t]x R of the rotation R (x_second = R x_first + t) whose direction t best fits the inliers'
// epipolar constraints: t is orthogonal to every (R f1) x f2 of their bearings f1, f2, so it is the least eigenvector
// of those vectors' scatter (its sign is left to cv::recoverPose).
cv::Mat EssentialGivenRotation(const Camera& camera, const std::vector<cv::Point2f>& from,
                               const std::vector<cv::Point2f>& to, const cv::Mat& inliers,
                               const Eigen::Matrix3d& rotation) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    if (!inliers.at<uchar>(static_cast<int>(i))) continue;
    const Eigen::Vector3d first = camera.Ray(Eigen::Vector2d(from[i].x, from[i].y));
    const Eigen::Vector3d second = camera.Ray(Eigen::Vector2d(to[i].x, to[i].y));
    const Eigen::Vector3d normal = (rotation * first).cross(second);
    scatter += normal * normal.transpose();
  }
  const Eigen::Vector3d t = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  cv::Mat e;
  cv::eigen2cv(Eigen::Matrix3d(Hat(t) * rotation), e);
  return e;
}

}  // namespace

bool BootstrapOptions::Check() const {
  PDVO_CHECK_OPTION(frames >= 0 && parallax > 0 && velocity_sigma > 0);
  return true;
}

bool EstimateTwoView(const Camera& camera, const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to,
                     double parallax_deg, double inverse_depth, TwoViewMotion* motion,
                     const std::optional<Eigen::Quaterniond>& given_rotation) {
  if (from.size() < kBootstrapInliers || from.size() != to.size()) return false;
  cv::Mat inliers;
  cv::Mat e = cv::findEssentialMat(from, to, camera.K(), cv::RANSAC, kRansacConfidence, kRansacThreshold, inliers);
  if (e.rows != 3 || e.cols != 3) return false;
  if (given_rotation) {
    e = EssentialGivenRotation(camera, from, to, inliers, given_rotation->conjugate().toRotationMatrix());
  }
  cv::Mat r, t, triangulated;
  cv::recoverPose(e, from, to, camera.K(), r, t, kFarthest, inliers, triangulated);
  // x_second = R x_first + t, |t| = 1.
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(r, rotation);
  cv::cv2eigen(t, translation);
  triangulated.convertTo(triangulated, CV_64F);
  const Eigen::Vector3d centre = -rotation.transpose() * translation;  // of the second camera, first frame
  std::vector<double> parallax, distance;
  std::vector<Eigen::Vector3d> bearings_first, bearings_second;
  motion->inliers.clear();
  motion->points.clear();
  for (int i = 0; i < inliers.rows; ++i) {
    if (!inliers.at<uchar>(i)) continue;
    const Eigen::Vector4d h(triangulated.at<double>(0, i), triangulated.at<double>(1, i), triangulated.at<double>(2, i),
                            triangulated.at<double>(3, i));
    if (std::abs(h(3)) < 1e-12) continue;
    const Eigen::Vector3d x = h.hnormalized();
    const Eigen::Vector3d in_second = rotation * x + translation;
    if (x.z() <= 0 || in_second.z() <= 0) continue;
    parallax.push_back(AngleDeg(x, x - centre));
    distance.push_back(in_second.norm());
    motion->inliers.push_back(i);
    motion->points.push_back(x);
    bearings_first.push_back(camera.Ray(Eigen::Vector2d(from[i].x, from[i].y)));
    bearings_second.push_back(camera.Ray(Eigen::Vector2d(to[i].x, to[i].y)));
  }
  const size_t n = motion->inliers.size();
  if (n < kBootstrapInliers) return false;
  motion->found = true;
  motion->first_from_second = Rigid3d(Eigen::Quaterniond(rotation.transpose()), centre);
  if (2 * n < to.size()) return false;
  if (Median(parallax) < parallax_deg) return false;
  if (MedianUnexplainedByRotation(bearings_first, bearings_second) < kMinUnexplainedShare * parallax_deg) return false;
  const double scale = 1 / (inverse_depth * Median(distance));
  for (Eigen::Vector3d& x : motion->points) x *= scale;
  motion->first_from_second.translation *= scale;
  return true;
}

std::optional<double> EpipolarDisagreement(const Camera& camera, const cv::Mat& first, const cv::Mat& second,
                                           const Rigid3d& first_from_second, int border, double min_distance) {
  std::vector<cv::Point2f> from, to;
  cv::goodFeaturesToTrack(first, from, kCheckCorners, kCornerQuality, min_distance, InsideMask(first.size(), border));
  if (from.size() < kBootstrapInliers) return std::nullopt;
  std::vector<uchar> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(first, second, from, to, status, error, kFlowWindow, kFlowLevels);
  size_t kept = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    if (!status[i] || !Inside(Eigen::Vector2d(to[i].x, to[i].y), second.size(), border)) continue;
    from[kept] = from[i];
    to[kept++] = to[i];
  }
  from.resize(kept);
  to.resize(kept);
  if (kept < kBootstrapInliers) return std::nullopt;
  // The essential matrix only sorts out tracks that fit no rigid motion; the filter's motion is what is tested.
  cv::Mat inliers;
  // USAC (OpenCV's LO-RANSAC with SPRT): the same verdicts as plain RANSAC on the real excerpts, at half the cost
  // and without its 100 ms keyframes when few tracks are good (docs/experiments/2026-12-05-pdvo-extension.md).
  const cv::Mat e =
      cv::findEssentialMat(from, to, camera.K(), cv::USAC_DEFAULT, kCheckConfidence, kRansacThreshold, inliers);
  if (e.rows != 3 || e.cols != 3) return std::nullopt;
  const Eigen::Matrix3d rotation = first_from_second.rotation.toRotationMatrix();
  const Eigen::Vector3d& baseline = first_from_second.translation;
  std::vector<double> angles;
  for (int i = 0; i < inliers.rows; ++i) {
    if (!inliers.at<uchar>(i)) continue;
    const Eigen::Vector3d b1 = camera.Ray(Eigen::Vector2d(from[i].x, from[i].y));
    const Eigen::Vector3d b2 = rotation * camera.Ray(Eigen::Vector2d(to[i].x, to[i].y));
    const Eigen::Vector3d normal = baseline.cross(b1);  // of the epipolar plane, in the first view's frame
    angles.push_back(normal.norm() > 1e-12 * baseline.norm() && baseline.norm() > 0
                         ? std::asin(std::min(1.0, std::abs(normal.normalized().dot(b2)))) * 180 / M_PI
                         : AngleDeg(b1, b2));
  }
  if (angles.size() < kBootstrapInliers || 2 * angles.size() < kept) return std::nullopt;
  return Median(angles);
}

TwoViewBootstrap::TwoViewBootstrap(const Camera& camera, const BootstrapOptions& options, int border,
                                   double min_distance, double inverse_depth)
    : camera_(camera), o_(options), border_(border), min_distance_(min_distance), inverse_depth_(inverse_depth) {}

void TwoViewBootstrap::Stop() {
  active_ = false;
  tracks_.clear();
  previous_ = cv::Mat();
  last_direction_.reset();
}

void TwoViewBootstrap::Begin(const cv::Mat& grey, double timestamp, size_t index, const CameraState& first) {
  Stop();
  if (o_.frames == 0) return;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey, corners, kBootstrapCorners, kCornerQuality, min_distance_,
                          InsideMask(grey.size(), border_));
  active_ = corners.size() >= kBootstrapInliers;
  tracks_ = {corners};
  previous_ = grey.clone();
  time_ = timestamp;
  index_ = index;
  first_ = first;
}

std::optional<BootstrapStart> TwoViewBootstrap::Step(const cv::Mat& grey, double timestamp,
                                                     const Eigen::Quaterniond& orientation) {
  if (!active_) return std::nullopt;
  std::vector<cv::Point2f> next;
  std::vector<uchar> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(previous_, grey, tracks_.back(), next, status, error, kFlowWindow, kFlowLevels);
  tracks_.push_back(next);
  size_t kept = 0;
  for (size_t i = 0; i < next.size(); ++i) {
    if (!status[i] || !Inside(Eigen::Vector2d(next[i].x, next[i].y), grey.size(), border_)) continue;
    for (std::vector<cv::Point2f>& frame : tracks_) frame[kept] = frame[i];
    ++kept;
  }
  for (std::vector<cv::Point2f>& frame : tracks_) frame.resize(kept);
  previous_ = grey.clone();
  if (kept < kBootstrapInliers || static_cast<int>(tracks_.size()) > o_.frames + 1) {
    Stop();
    return std::nullopt;
  }
  TwoViewMotion motion;
  const bool enough = EstimateTwoView(camera_, tracks_.front(), tracks_.back(), o_.parallax, inverse_depth_, &motion,
                                      first_.orientation.conjugate() * orientation);
  // Its direction must agree with the motion found a frame before (kMaxDirectionChange).
  const std::optional<Eigen::Vector3d> before = std::exchange(last_direction_, std::nullopt);
  if (motion.found) last_direction_ = motion.first_from_second.translation.normalized();
  if (!enough || !before || AngleDeg(*before, *last_direction_) > kMaxDirectionChange) {
    return std::nullopt;
  }
  const Rigid3d& first_from_current = motion.first_from_second;
  BootstrapStart start;
  CameraState& at = start.camera;
  const Rigid3d world_from_first = first_.world_from_cam();
  const Rigid3d world_from_current = world_from_first * first_from_current;
  at.position = world_from_current.translation;
  at.orientation = world_from_current.rotation;
  const double dt = timestamp - time_;
  at.velocity = (at.position - first_.position) / dt;
  at.angular_velocity = LogSO3(first_from_current.rotation) / dt;
  // The frames in between: the tracks' frames 1 .. size - 2.
  std::vector<cv::Point3d> points;
  for (const Eigen::Vector3d& x : motion.points) points.emplace_back(x.x(), x.y(), x.z());
  for (size_t f = 1; f + 1 < tracks_.size(); ++f) {
    std::vector<cv::Point2d> pixels;
    for (int i : motion.inliers) pixels.emplace_back(tracks_[f][i]);
    // Start from the pose interpolated between the first and the current camera.
    const double share = static_cast<double>(f) / (tracks_.size() - 1);
    const Rigid3d guess(Eigen::Quaterniond::Identity().slerp(share, first_from_current.rotation),
                        share * first_from_current.translation);
    const Rigid3d cam_from_first = guess.Inverse();
    Eigen::Vector3d r = LogSO3(cam_from_first.rotation), t = cam_from_first.translation;  // OpenCV's rvec, tvec
    cv::Mat rvec, tvec;
    cv::eigen2cv(r, rvec);
    cv::eigen2cv(t, tvec);
    Rigid3d first_from_frame = guess;
    if (cv::solvePnP(points, pixels, camera_.K(), cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE)) {
      cv::cv2eigen(rvec, r);
      cv::cv2eigen(tvec, t);
      first_from_frame = Rigid3d(ExpSO3(r), t).Inverse();
    }
    start.revised.emplace_back(index_ + f, world_from_first * first_from_frame);
  }
  const Rigid3d current_from_first = first_from_current.Inverse();
  for (size_t j = 0; j < motion.inliers.size(); ++j) {
    const cv::Point2f& pixel = tracks_.back()[motion.inliers[j]];
    start.corners.push_back({Eigen::Vector2d(pixel.x, pixel.y), 1 / (current_from_first * motion.points[j]).norm()});
  }
  PDVO_LOG(Debug) << "vo: two-view bootstrap after " << tracks_.size() - 1 << " frames, " << start.corners.size()
                  << " triangulated corners, direction " << first_from_current.translation.normalized().transpose();
  Stop();
  return start;
}

}  // namespace pdvo::vo
