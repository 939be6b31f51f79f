#include "pdvo/vo/odometry.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <random>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/vo/patch.h"

namespace pdvo::vo {

bool VoOptions::Check() const {
  PDVO_CHECK_OPTION(working_width == 0 || working_width >= 64);
  PDVO_CHECK_OPTION(patch_half >= 1 && border > patch_half);
  PDVO_CHECK_OPTION(search_sigmas > 0 && max_search_radius >= 1);
  PDVO_CHECK_OPTION(min_ncc > -1 && min_ncc < 1 && pixel_sigma > 0);
  PDVO_CHECK_OPTION(max_measurements >= 1 && min_features >= 1 && new_features >= 1 && min_distance >= 1);
  PDVO_CHECK_OPTION(max_misses >= 1 && lost_after >= 1);
  PDVO_CHECK_OPTION(ransac_hypotheses >= 1 && ransac_threshold > 0);
  PDVO_CHECK_OPTION(initial_inverse_depth_sigma > 0 && initial_velocity_sigma > 0);
  PDVO_CHECK_OPTION(linear_acceleration > 0 && angular_acceleration > 0);
  return true;
}

struct Odometry::Impl {
  Pinhole camera;
  VoOptions o;
  std::unique_ptr<Filter> filter;
  std::map<int, std::shared_ptr<const cv::Mat>> keyframe_of_reference;
  struct Track {
    Eigen::Vector2d keyframe_pixel;
    int misses = 0;
  };
  std::map<int, Track> tracks;  // by point id
  double last_time = 0;
  bool started = false;
  int frames_without_measurements = 0;
  cv::Size size;
  std::mt19937 rng{1};  // RANSAC; fixed seed: the same frames give the same trajectory

  bool Inside(const Eigen::Vector2d& p) const {
    return p.x() >= o.border && p.y() >= o.border && p.x() < size.width - o.border &&
           p.y() < size.height - o.border;
  }

  void Start(const cv::Mat& grey, const CameraState& at) {
    CameraState rest = at;
    rest.velocity.setZero();
    rest.angular_velocity.setZero();
    Vector12d sigma;
    sigma << Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-6),
        Eigen::Vector3d::Constant(o.initial_velocity_sigma), Eigen::Vector3d::Constant(o.angular_acceleration);
    filter = std::make_unique<Filter>(rest, Matrix12d(sigma.cwiseAbs2().asDiagonal()));
    keyframe_of_reference.clear();
    tracks.clear();
    frames_without_measurements = 0;
    MakeKeyframe(grey);
  }

  // New points at the strongest corners at least min_distance from the visible features.
  bool MakeKeyframe(const cv::Mat& grey) {
    cv::Mat mask(grey.size(), CV_8U, cv::Scalar(0));
    mask(cv::Rect(o.border, o.border, grey.cols - 2 * o.border, grey.rows - 2 * o.border)).setTo(255);
    for (const auto& [id, p] : filter->points()) {
      Eigen::Vector2d pixel;
      if (filter->PredictPoint(camera, id, &pixel, nullptr)) {
        cv::circle(mask, cv::Point(cvRound(pixel.x()), cvRound(pixel.y())), static_cast<int>(o.min_distance),
                   cv::Scalar(0), cv::FILLED);
      }
    }
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(grey, corners, o.new_features, 0.01, o.min_distance, mask);
    if (corners.empty()) return false;
    // New points start at the median inverse depth of the converged points in view, with the same relative
    // uncertainty as the configured prior: priors in the map's own (drifting, monocular) scale.
    double rho = o.initial_inverse_depth;
    const std::vector<double> in_view = ConvergedInverseDepths();
    if (in_view.size() >= 5) rho = in_view[in_view.size() / 2];
    const double sigma = o.initial_inverse_depth_sigma / o.initial_inverse_depth * rho;
    const int reference = filter->AddReference();
    keyframe_of_reference[reference] = std::make_shared<const cv::Mat>(grey.clone());
    for (const cv::Point2f& c : corners) {
      const Eigen::Vector2d pixel(c.x, c.y);
      const int id = filter->AddPoint(reference, camera.Ray(pixel), rho, sigma);
      tracks[id] = {pixel, 0};
    }
    return true;
  }

  // Inverse distances from the current camera of the points whose inverse depth is known to 30%, sorted.
  std::vector<double> ConvergedInverseDepths() const {
    std::vector<double> out;
    const Rigid3d cam_from_world = filter->camera().world_from_cam().Inverse();
    for (const auto& [id, p] : filter->points()) {
      const double variance = filter->covariance()(p.offset, p.offset);
      if (p.inverse_depth <= 0 || std::sqrt(variance) > 0.3 * p.inverse_depth) continue;
      const Rigid3d& ref = filter->references().at(p.reference).world_from_cam;
      out.push_back(1 / (cam_from_world * (ref * (p.ray / p.inverse_depth))).norm());
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  void Remove(int id) {
    const int reference = filter->points().at(id).reference;
    filter->RemovePoint(id);
    tracks.erase(id);
    if (!filter->references().count(reference)) keyframe_of_reference.erase(reference);
  }

  // NCC search for `templ` (CV_32F) in `grey` within the ellipse of S around `predicted`.
  bool Search(const cv::Mat& grey, const cv::Mat& templ, const Eigen::Vector2d& predicted, const Eigen::Matrix2d& s,
              Eigen::Vector2d* found) const {
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s).eigenvalues().maxCoeff();
    const int radius = std::min(o.max_search_radius, static_cast<int>(std::ceil(o.search_sigmas * std::sqrt(largest))));
    const int half = o.patch_half;
    const cv::Point centre(cvRound(predicted.x()), cvRound(predicted.y()));
    const cv::Rect wanted(centre.x - radius - half, centre.y - radius - half, 2 * (radius + half) + 1,
                          2 * (radius + half) + 1);
    const cv::Rect window = wanted & cv::Rect(0, 0, grey.cols, grey.rows);
    if (window.width < templ.cols || window.height < templ.rows) return false;
    cv::Mat region, score;
    grey(window).convertTo(region, CV_32F);
    cv::matchTemplate(region, templ, score, cv::TM_CCOEFF_NORMED);
    const Eigen::Matrix2d information = s.inverse();
    const double gate = o.search_sigmas * o.search_sigmas;
    double best = -2;
    cv::Point at(-1, -1);
    for (int y = 0; y < score.rows; ++y) {
      for (int x = 0; x < score.cols; ++x) {
        const float v = score.at<float>(y, x);
        if (!std::isfinite(v) || v <= best) continue;
        const Eigen::Vector2d d(window.x + x + half - predicted.x(), window.y + y + half - predicted.y());
        if (d.dot(information * d) > gate) continue;
        best = v;
        at = cv::Point(x, y);
      }
    }
    if (best < o.min_ncc) return false;
    // Sub-pixel: a parabola through the peak and its neighbours, per axis.
    auto offset = [](double l, double c, double r) {
      const double curvature = l - 2 * c + r;
      return curvature < 0 ? std::clamp(0.5 * (l - r) / curvature, -0.5, 0.5) : 0.0;
    };
    double dx = 0, dy = 0;
    if (at.x > 0 && at.x + 1 < score.cols) {
      dx = offset(score.at<float>(at.y, at.x - 1), best, score.at<float>(at.y, at.x + 1));
    }
    if (at.y > 0 && at.y + 1 < score.rows) {
      dy = offset(score.at<float>(at.y - 1, at.x), best, score.at<float>(at.y + 1, at.x));
    }
    *found = Eigen::Vector2d(window.x + at.x + half + dx, window.y + at.y + half + dy);
    return true;
  }

  FrameStats Track(const cv::Mat& grey, double timestamp) {
    FrameStats stats;
    stats.timestamp = timestamp;
    if (!started) {
      size = grey.size();
      Start(grey, CameraState());
      started = true;
      stats.keyframe = true;
    } else {
      PDVO_THROW_CHECK(grey.size() == size, InvalidArgument, "odometry: frames changed size");
      PDVO_THROW_CHECK(timestamp > last_time, InvalidArgument,
                       "odometry: timestamps must increase (" << last_time << " then " << timestamp << ")");
      filter->Predict(timestamp - last_time, {o.linear_acceleration, o.angular_acceleration});
      Measure(grey, &stats);
      if (!filter->covariance().allFinite() || !filter->camera().position.allFinite() ||
          frames_without_measurements >= o.lost_after) {
        stats.lost = true;
        CameraState at = filter->camera();
        if (!at.position.allFinite() || !at.orientation.coeffs().allFinite()) at = CameraState();
        Start(grey, at);
        stats.keyframe = true;
      } else if (static_cast<int>(filter->points().size()) < o.min_features) {
        stats.keyframe = MakeKeyframe(grey);
      }
    }
    last_time = timestamp;
    stats.points = static_cast<int>(filter->points().size());
    stats.state_size = filter->size();
    return stats;
  }

  // 1-point RANSAC (Civera et al. 2010): each hypothesis is the state after an update with one measurement;
  // the one that brings most other measurements within `ransac_threshold` px gives the inliers, which update
  // the filter; then any other measurement whose innovation is now within the 99% gate updates it too.
  // Returns the number of measurements used.
  int UpdateRobustly(const std::vector<PointMeasurement>& all) {
    if (all.empty()) return 0;
    auto agreeing = [&](const Filter& f, double threshold) {
      std::vector<PointMeasurement> in;
      for (const PointMeasurement& z : all) {
        Eigen::Vector2d predicted;
        if (f.PredictPoint(camera, z.point, &predicted, nullptr) && (predicted - z.pixel).norm() < threshold) {
          in.push_back(z);
        }
      }
      return in;
    };
    std::vector<PointMeasurement> best;
    const int hypotheses = std::min<int>(o.ransac_hypotheses, static_cast<int>(all.size()));
    std::uniform_int_distribution<size_t> pick(0, all.size() - 1);
    for (int k = 0; k < hypotheses; ++k) {
      Filter hypothesis = *filter;
      hypothesis.Update(camera, {all[pick(rng)]});
      std::vector<PointMeasurement> in = agreeing(hypothesis, o.ransac_threshold);
      if (in.size() > best.size()) best = std::move(in);
    }
    if (best.empty()) return 0;
    filter->Update(camera, best);
    // Rescue: the rest, gated on their innovation after the inliers' update.
    std::vector<PointMeasurement> rescued;
    for (const PointMeasurement& z : all) {
      if (std::any_of(best.begin(), best.end(), [&](const PointMeasurement& b) { return b.point == z.point; })) continue;
      Eigen::Vector2d predicted;
      Eigen::MatrixXd jacobian;
      if (!filter->PredictPoint(camera, z.point, &predicted, &jacobian)) continue;
      Eigen::Matrix2d s = jacobian * filter->covariance() * jacobian.transpose();
      s.diagonal().array() += z.sigma * z.sigma;
      const Eigen::Vector2d v = z.pixel - predicted;
      if (v.dot(s.ldlt().solve(v)) < 9.21) rescued.push_back(z);  // chi-square(2), 99%
    }
    if (!rescued.empty()) filter->Update(camera, rescued);
    return static_cast<int>(best.size() + rescued.size());
  }

  void Measure(const cv::Mat& grey, FrameStats* stats) {
    // Features that left the view (or went behind the camera) leave the filter.
    std::vector<int> gone;
    for (const auto& [id, p] : filter->points()) {
      Eigen::Vector2d pixel;
      if (!filter->PredictPoint(camera, id, &pixel, nullptr) || !Inside(pixel)) gone.push_back(id);
    }
    for (int id : gone) Remove(id);

    const Rigid3d current = filter->camera().world_from_cam();
    std::vector<PointMeasurement> measurements;
    std::vector<int> missed;
    for (const auto& [id, p] : filter->points()) {
      if (stats->attempted >= o.max_measurements) break;
      ++stats->attempted;
      Eigen::Vector2d predicted;
      Eigen::MatrixXd jacobian;
      filter->PredictPoint(camera, id, &predicted, &jacobian);
      Eigen::Matrix2d s = jacobian * filter->covariance() * jacobian.transpose();
      s.diagonal().array() += o.pixel_sigma * o.pixel_sigma;
      const Filter::Reference& reference = filter->references().at(p.reference);
      const Eigen::Matrix3d h = PlaneHomography(camera, current, reference.world_from_cam,
                                                FrontoParallel(p.ray, std::max(p.inverse_depth, 1e-3)));
      cv::Mat templ;
      Eigen::Vector2d found;
      if (WarpPatch(*keyframe_of_reference.at(p.reference), h, predicted, o.patch_half, &templ) &&
          Search(grey, templ, predicted, s, &found)) {
        measurements.push_back({id, found, o.pixel_sigma});
        tracks[id].misses = 0;
      } else if (++tracks[id].misses > o.max_misses) {
        missed.push_back(id);
      }
    }
    const int used = UpdateRobustly(measurements);
    frames_without_measurements = used == 0 ? frames_without_measurements + 1 : 0;
    stats->measurements = used;
    for (int id : missed) Remove(id);
  }
};

Odometry::Odometry(const Pinhole& camera, const VoOptions& options) : impl_(std::make_unique<Impl>()) {
  CheckOptionsOrThrow(options, "vo options");
  impl_->camera = camera;
  impl_->o = options;
}

Odometry::~Odometry() = default;

FrameStats Odometry::Track(const cv::Mat& grey, double timestamp) {
  PDVO_THROW_CHECK(!grey.empty() && grey.type() == CV_8UC1, InvalidArgument, "odometry: frames must be 8-bit grey");
  const auto start = std::chrono::steady_clock::now();
  FrameStats stats = impl_->Track(grey, timestamp);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

Rigid3d Odometry::world_from_cam() const { return impl_->filter->camera().world_from_cam(); }

const Filter& Odometry::filter() const { return *impl_->filter; }

}  // namespace pdvo::vo
