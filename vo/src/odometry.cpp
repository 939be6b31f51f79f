#include "pdvo/vo/odometry.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/vo/patch.h"

namespace pdvo::vo {

bool VoOptions::Check() const {
  PDVO_CHECK_OPTION(working_width == 0 || working_width >= 64);
  PDVO_CHECK_OPTION(patch_half >= 1 && border > patch_half);
  PDVO_CHECK_OPTION(search_sigmas > 0 && max_search_radius >= 1);
  PDVO_CHECK_OPTION(min_ncc > -1 && min_ncc < 1 && pixel_sigma > 0);
  PDVO_CHECK_OPTION(max_measurements >= 1 && min_features >= 1 && new_features >= 1 && min_distance >= 1);
  PDVO_CHECK_OPTION(max_misses >= 1 && lost_after >= 1 && min_rejections >= 1 && max_rejected_share >= 0);
  PDVO_CHECK_OPTION(ransac_hypotheses >= 1 && ransac_threshold > 0);
  PDVO_CHECK_OPTION(mode == "idpp" || mode == "points");
  PDVO_CHECK_OPTION(max_new_planes >= 0 && grow_radius > min_distance && new_plane_points >= 1);
  PDVO_CHECK_OPTION(candidate_frames >= 1 && plane_grow_frames >= 1 && min_plane_points >= 3);
  PDVO_CHECK_OPTION(plane_sigma_normal > 0 && planarity > 0 && join_gate > 0);
  PDVO_CHECK_OPTION(initial_inverse_depth_sigma > 0 && initial_velocity_sigma > 0 &&
                    initial_angular_velocity_sigma > 0);
  PDVO_CHECK_OPTION(bootstrap_frames >= 0 && bootstrap_parallax > 0 && bootstrap_velocity_sigma > 0);
  PDVO_CHECK_OPTION(linear_acceleration > 0 && angular_acceleration > 0);
  return true;
}

struct Odometry::Impl {
  Pinhole camera;
  VoOptions o;
  std::unique_ptr<Filter> filter;
  cv::Size size;
  std::mt19937 rng{1};  // RANSAC; fixed seed: the same frames give the same trajectory
  double last_time = 0;
  bool started = false;
  int frames_without_measurements = 0;

  // Per reference camera: its keyframe image and the corners found in it (planes grow over these).
  struct Corner {
    Eigen::Vector2d pixel;
    bool used = false;
  };
  struct Keyframe {
    cv::Mat grey;
    double time = 0;
    std::vector<Corner> corners;
  };
  std::map<int, Keyframe> keyframes;
  // How a feature has fared: a feature leaves after more than max_misses failed searches in a row, or when
  // RANSAC has rejected too many of its matches (the patch straddles a depth edge or slides on a repetition).
  struct History {
    int misses = 0;    // consecutive failed searches
    int matched = 0;   // searches that found a match
    int rejected = 0;  // matches that RANSAC and its rescue rejected
  };
  struct PointTrack {
    Eigen::Vector2d keyframe_pixel;
    History history;
  };
  std::map<int, PointTrack> point_tracks;  // by point id
  struct PlanePoint {
    Eigen::Vector2d keyframe_pixel;
    Eigen::Vector3d ray;
    History history;
  };
  struct Candidate {
    int point = -1;  // a point of the filter, until the test decides
    int age = 0;     // frames since it was made
  };
  struct PlaneTrack {
    std::vector<PlanePoint> members;  // members[0] is the seed
    std::vector<Candidate> candidates;
    int age = 0;                      // frames since the plane was made
  };
  std::map<int, PlaneTrack> plane_tracks;  // by plane id
  // Every plane that reached min_plane_points, by (generation, plane id): each start is a new filter, whose
  // ids start again.
  std::map<std::pair<int, int>, PlaneRecord> records;
  int generation = 0;                      // filters started so far
  Map mapped;                              // features that left the filter
  std::vector<Observation> observations;   // of the last frame

  bool Inside(const Eigen::Vector2d& p) const {
    return p.x() >= o.border && p.y() >= o.border && p.x() < size.width - o.border &&
           p.y() < size.height - o.border;
  }

  // Features' priors: pixel and inverse distance (PriorInverseDepth takes the nearest).
  using Priors = std::vector<std::pair<Eigen::Vector2d, double>>;

  // Starts at rest at `at` with generic priors, and arms the two-view bootstrap.
  void Start(const cv::Mat& grey, double timestamp, const CameraState& at) {
    CameraState rest = at;
    rest.velocity.setZero();
    rest.angular_velocity.setZero();
    Restart(grey, timestamp, rest, o.initial_velocity_sigma, nullptr);
    boot = {};
    if (o.bootstrap_frames == 0) return;
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(grey, corners, kBootstrapCorners, 0.01, o.min_distance, InsideMask(grey.size()));
    boot.active = corners.size() >= kBootstrapInliers;
    boot.tracks = {corners};
    boot.previous = grey.clone();
    boot.time = timestamp;
    boot.index = trajectory.size();
    boot.first = rest;
  }

  // A new filter holding only the camera `at` (its position and orientation fixed: the gauge) and a keyframe.
  void Restart(const cv::Mat& grey, double timestamp, const CameraState& at, double velocity_sigma,
               const Priors* priors) {
    Vector12d sigma;
    sigma << Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-6),
        Eigen::Vector3d::Constant(velocity_sigma), Eigen::Vector3d::Constant(o.initial_angular_velocity_sigma);
    filter = std::make_unique<Filter>(at, Matrix12d(sigma.cwiseAbs2().asDiagonal()));
    keyframes.clear();
    point_tracks.clear();
    plane_tracks.clear();
    ++generation;
    frames_without_measurements = 0;
    MakeKeyframe(grey, timestamp, priors);
  }

  // The two-view bootstrap. A monocular filter started at rest has to find the speed and the depths together,
  // and while the velocity prior holds the speed near zero the map takes a scale that then drifts for a few
  // hundred frames (synthetic streets: the first 100 frames at 0.7 of the later scale). So the corners of the
  // first frame are tracked (pyramidal Lucas-Kanade) while the filter runs; once an essential matrix between
  // the first frame and the current one has enough inliers, seen under a median parallax of at least
  // bootstrap_parallax degrees, the filter starts again at the current frame with that motion's mean velocity
  // (known to bootstrap_velocity_sigma of itself) and the triangulated depths as its features' priors, at the
  // scale that puts their median at 1 / initial_inverse_depth (the acceleration noise is in metres, and street
  // scenes are a few metres deep). The poses of the frames in between are replaced by the poses that fit the
  // triangulated corners (PnP); what the filter had mapped before it is dropped (it is at the former scale),
  // while the planes it recorded stay counted. Without enough parallax after bootstrap_frames (e.g. a camera
  // that only rotates) the filter simply goes on. Known weaknesses: the frame-to-frame tracks drift, which adds
  // parallax, so far corners come out too near (on the odometry test's street the priors are 24% nearer than
  // the motion's scale says, and the filter settles to another scale after the bootstrap); tracking from the
  // first frame with each corner's own triangulation uncertainty removes that bias but measured worse over 1,000
  // frames (streets 31-54: 0.92 against 0.71%; 101-124: 1.45 against 0.77%), so it is not used. And nearly pure
  // forward motion can give an essential matrix of sideways motion (README.md).
  static constexpr int kBootstrapCorners = 200;
  static constexpr size_t kBootstrapInliers = 30;
  struct Bootstrap {
    bool active = false;
    double time = 0;     // of the first frame
    size_t index = 0;    // of the first frame in `trajectory`
    CameraState first;   // the camera at the first frame
    cv::Mat previous;    // the last frame
    std::vector<std::vector<cv::Point2f>> tracks;  // per frame since the first, the corners still tracked
  } boot;
  // What the bootstrap found: the motion and the triangulated inliers (first camera, at the map's scale).
  struct TwoViewMotion {
    Rigid3d first_from_current;
    std::vector<int> inliers;  // indices into the tracks
    std::vector<Eigen::Vector3d> points;
  };
  Trajectory trajectory;  // every frame's pose

  cv::Mat InsideMask(const cv::Size& image) const {
    cv::Mat mask(image, CV_8U, cv::Scalar(0));
    mask(cv::Rect(o.border, o.border, image.width - 2 * o.border, image.height - 2 * o.border)).setTo(255);
    return mask;
  }

  // Tracks the bootstrap's corners into `grey`; true if the filter started again.
  bool StepBootstrap(const cv::Mat& grey, double timestamp) {
    std::vector<cv::Point2f> next;
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(boot.previous, grey, boot.tracks.back(), next, status, error, cv::Size(21, 21), 3);
    boot.tracks.push_back(next);
    size_t kept = 0;
    for (size_t i = 0; i < next.size(); ++i) {
      if (!status[i] || !Inside(Eigen::Vector2d(next[i].x, next[i].y))) continue;
      for (std::vector<cv::Point2f>& frame : boot.tracks) frame[kept] = frame[i];
      ++kept;
    }
    for (std::vector<cv::Point2f>& frame : boot.tracks) frame.resize(kept);
    boot.previous = grey.clone();
    if (kept < kBootstrapInliers || static_cast<int>(boot.tracks.size()) > o.bootstrap_frames + 1) {
      boot = {};
      return false;
    }
    TwoViewMotion motion;
    if (!TwoView(&motion)) return false;
    const Rigid3d& first_from_current = motion.first_from_current;
    CameraState at;
    const Rigid3d world_from_first = boot.first.world_from_cam();
    const Rigid3d world_from_current = world_from_first * first_from_current;
    at.position = world_from_current.translation;
    at.orientation = world_from_current.rotation;
    const double dt = timestamp - boot.time;
    at.velocity = (at.position - boot.first.position) / dt;
    at.angular_velocity = LogSO3(first_from_current.rotation) / dt;
    // The frames in between (the tracks' frames 1 .. size - 2 are trajectory[index + 1 ..]).
    std::vector<cv::Point3d> points;
    for (const Eigen::Vector3d& x : motion.points) points.emplace_back(x.x(), x.y(), x.z());
    for (size_t f = 1; f + 1 < boot.tracks.size(); ++f) {
      std::vector<cv::Point2d> pixels;
      for (int i : motion.inliers) pixels.emplace_back(boot.tracks[f][i]);
      // Start from the pose interpolated between the first and the current camera.
      const double share = static_cast<double>(f) / (boot.tracks.size() - 1);
      const Rigid3d guess(Eigen::Quaterniond::Identity().slerp(share, first_from_current.rotation),
                          share * first_from_current.translation);
      const Rigid3d cam_from_first = guess.Inverse();
      Eigen::Vector3d r = LogSO3(cam_from_first.rotation), t = cam_from_first.translation;  // OpenCV's rvec, tvec
      cv::Mat rvec, tvec;
      cv::eigen2cv(r, rvec);
      cv::eigen2cv(t, tvec);
      Rigid3d first_from_frame = guess;
      if (cv::solvePnP(points, pixels, CameraMatrix(), cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE)) {
        cv::cv2eigen(rvec, r);
        cv::cv2eigen(tvec, t);
        first_from_frame = Rigid3d(ExpSO3(r), t).Inverse();
      }
      trajectory.at(boot.index + f).world_from_cam = world_from_first * first_from_frame;
    }
    Priors priors;
    const Rigid3d current_from_first = first_from_current.Inverse();
    for (size_t j = 0; j < motion.inliers.size(); ++j) {
      const cv::Point2f& pixel = boot.tracks.back()[motion.inliers[j]];
      priors.emplace_back(Eigen::Vector2d(pixel.x, pixel.y), 1 / (current_from_first * motion.points[j]).norm());
    }
    PDVO_LOG(Debug) << "vo: two-view bootstrap after " << boot.tracks.size() - 1 << " frames, " << priors.size()
                    << " triangulated corners, direction " << first_from_current.translation.normalized().transpose();
    boot = {};
    Restart(grey, timestamp, at, o.bootstrap_velocity_sigma * at.velocity.norm(), &priors);
    return true;
  }

  cv::Matx33d CameraMatrix() const { return {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1}; }

  // The essential matrix between the bootstrap's first and last frame (RANSAC, 1 px), its motion and the
  // triangulated inliers, scaled so that their median distance is 1 / initial_inverse_depth; false if there
  // are too few inliers or too little parallax.
  bool TwoView(TwoViewMotion* motion) const {
    const std::vector<cv::Point2f>& from = boot.tracks.front();
    const std::vector<cv::Point2f>& to = boot.tracks.back();
    cv::Mat inliers;
    const cv::Mat e = cv::findEssentialMat(from, to, CameraMatrix(), cv::RANSAC, 0.999, 1.0, inliers);
    if (e.rows != 3 || e.cols != 3) return false;
    cv::Mat r, t, triangulated;
    cv::recoverPose(e, from, to, CameraMatrix(), r, t, 1e6, inliers, triangulated);
    // x_current = R x_first + t, |t| = 1.
    Eigen::Matrix3d rotation;
    Eigen::Vector3d translation;
    cv::cv2eigen(r, rotation);
    cv::cv2eigen(t, translation);
    triangulated.convertTo(triangulated, CV_64F);
    const Eigen::Vector3d centre = -rotation.transpose() * translation;  // of the current camera, first frame
    std::vector<double> parallax, distance;
    motion->inliers.clear();
    motion->points.clear();
    for (int i = 0; i < inliers.rows; ++i) {
      if (!inliers.at<uchar>(i)) continue;
      const Eigen::Vector4d h(triangulated.at<double>(0, i), triangulated.at<double>(1, i),
                              triangulated.at<double>(2, i), triangulated.at<double>(3, i));
      if (std::abs(h(3)) < 1e-12) continue;
      const Eigen::Vector3d x = h.hnormalized();
      const Eigen::Vector3d in_current = rotation * x + translation;
      if (x.z() <= 0 || in_current.z() <= 0) continue;
      parallax.push_back(std::acos(std::clamp(x.normalized().dot((x - centre).normalized()), -1.0, 1.0)));
      distance.push_back(in_current.norm());
      motion->inliers.push_back(i);
      motion->points.push_back(x);
    }
    const size_t n = motion->inliers.size();
    if (n < kBootstrapInliers || 2 * n < to.size()) return false;
    auto median = [](std::vector<double> v) {
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    if (median(parallax) < o.bootstrap_parallax * M_PI / 180) return false;
    const double scale = 1 / (o.initial_inverse_depth * median(distance));
    for (Eigen::Vector3d& x : motion->points) x *= scale;
    motion->first_from_current = Rigid3d(Eigen::Quaterniond(rotation.transpose()), centre * scale);
    return true;
  }

  bool Gone(const History& r) const {
    return r.misses > o.max_misses || (r.rejected >= o.min_rejections && r.rejected > o.max_rejected_share * r.matched);
  }

  // The predicted pixels of the features in view (points and plane members).
  std::vector<Eigen::Vector2d> VisibleFeatures() const {
    std::vector<Eigen::Vector2d> out;
    Eigen::Vector2d pixel;
    for (const auto& [id, p] : filter->points()) {
      if (filter->PredictPoint(camera, id, &pixel, nullptr) && Inside(pixel)) out.push_back(pixel);
    }
    for (const auto& [id, t] : plane_tracks) {
      for (const PlanePoint& m : t.members) {
        if (filter->PredictPlanePoint(camera, id, m.ray, &pixel, nullptr) && Inside(pixel)) out.push_back(pixel);
      }
    }
    return out;
  }

  // A point whose inverse depth is known to 30%.
  bool Converged(const Filter::Point& p) const {
    return p.inverse_depth > 0 && std::sqrt(filter->covariance()(p.offset, p.offset)) < 0.3 * p.inverse_depth;
  }

  // The converged points as the current camera sees them: pixel and inverse distance.
  Priors ConvergedInView() const {
    Priors out;
    const Rigid3d cam_from_world = filter->camera().world_from_cam().Inverse();
    Eigen::Vector2d pixel;
    Eigen::Vector3d x;
    for (const auto& [id, p] : filter->points()) {
      if (!PointInWorld(id, &x) || !filter->PredictPoint(camera, id, &pixel, nullptr)) continue;
      out.emplace_back(pixel, 1 / (cam_from_world * x).norm());
    }
    return out;
  }

  // A new feature's inverse-depth prior at `pixel`: that of the converged point nearest in the image (depth
  // varies smoothly over most of a scene, and the median of all of them is far off for features nearer or
  // farther than most), or initial_inverse_depth while fewer than 5 have converged.
  double PriorInverseDepth(const Priors& converged, const Eigen::Vector2d& pixel) const {
    if (converged.size() < 5) return o.initial_inverse_depth;
    const auto nearest = std::min_element(converged.begin(), converged.end(), [&](const auto& a, const auto& b) {
      return (a.first - pixel).squaredNorm() < (b.first - pixel).squaredNorm();
    });
    return nearest->second;
  }

  // A prior's standard deviation: initial_inverse_depth_sigma's share of the prior.
  double PriorSigma(double rho) const { return o.initial_inverse_depth_sigma / o.initial_inverse_depth * rho; }

  // A keyframe: corners away from the visible features; in idpp mode up to max_new_planes of them, where
  // corners are densest, seed planes (fronto-parallel, facing the keyframe); the strongest others become points.
  // Priors: PriorInverseDepth and PriorSigma (the map keeps its own scale).
  bool MakeKeyframe(const cv::Mat& grey, double timestamp, const Priors* priors = nullptr) {
    cv::Mat mask = InsideMask(grey.size());
    for (const Eigen::Vector2d& p : VisibleFeatures()) {
      cv::circle(mask, cv::Point(cvRound(p.x()), cvRound(p.y())), static_cast<int>(o.min_distance), cv::Scalar(0),
                 cv::FILLED);
    }
    std::vector<cv::Point2f> found;
    cv::goodFeaturesToTrack(grey, found, 4 * o.new_features, 0.01, o.min_distance, mask);
    if (found.empty()) return false;
    const Priors converged = priors ? *priors : ConvergedInView();

    const int reference = filter->AddReference(o.fixed_references);
    Keyframe& keyframe = keyframes[reference];
    keyframe.grey = grey.clone();
    keyframe.time = timestamp;
    for (const cv::Point2f& c : found) keyframe.corners.push_back({Eigen::Vector2d(c.x, c.y), false});
    std::vector<Corner>& corners = keyframe.corners;
    std::vector<int> seeds;
    if (o.mode == "idpp") {
      std::vector<std::pair<int, int>> density;  // (corners within grow_radius, index)
      for (size_t i = 0; i < corners.size(); ++i) {
        int n = 0;
        for (const Corner& c : corners) n += (c.pixel - corners[i].pixel).norm() < o.grow_radius;
        density.emplace_back(-n, static_cast<int>(i));
      }
      std::sort(density.begin(), density.end());
      for (const auto& [minus_n, i] : density) {
        if (static_cast<int>(seeds.size()) >= o.max_new_planes || -minus_n <= o.min_plane_points) break;
        const bool apart = std::all_of(seeds.begin(), seeds.end(), [&](int s) {
          return (corners[s].pixel - corners[i].pixel).norm() > 2 * o.grow_radius;
        });
        if (apart) seeds.push_back(i);
      }
    }
    for (int i : seeds) {
      corners[i].used = true;
      const Eigen::Vector3d ray = camera.Ray(corners[i].pixel);
      const double rho = PriorInverseDepth(converged, corners[i].pixel);
      const int id = filter->AddPlane(reference, FrontoParallel(ray, rho), o.plane_sigma_normal, PriorSigma(rho));
      plane_tracks[id].members.push_back({corners[i].pixel, ray, {}});
    }
    // Points: the strongest corners left (goodFeaturesToTrack sorts by strength).
    int points = 0;
    for (Corner& c : corners) {
      if (c.used || points + static_cast<int>(seeds.size()) >= o.new_features) continue;
      c.used = true;
      ++points;
      const double rho = PriorInverseDepth(converged, c.pixel);
      point_tracks[filter->AddPoint(reference, camera.Ray(c.pixel), rho, PriorSigma(rho))] = {c.pixel, {}};
    }
    return true;
  }

  // A point's world position if it has converged.
  bool PointInWorld(int id, Eigen::Vector3d* x) const {
    const Filter::Point& p = filter->points().at(id);
    if (!Converged(p)) return false;
    *x = filter->references().at(p.reference).world_from_cam * (p.ray / p.inverse_depth);
    return true;
  }

  // A plane as the polygon of its members' convex hull (keyframe order), in the world.
  bool PlaneInWorld(int id, MapPlane* out) const {
    const PlaneTrack& t = plane_tracks.at(id);
    if (static_cast<int>(t.members.size()) < o.min_plane_points) return false;
    const Filter::Plane& plane = filter->planes().at(id);
    const Rigid3d& ref = filter->references().at(plane.reference).world_from_cam;
    out->polygon.clear();
    for (int k : Hull(t.members)) {
      const double rho = plane.plane.InverseDepthAlong(t.members[k].ray);
      if (rho <= 0) return false;
      out->polygon.push_back(ref * (t.members[k].ray / rho));
    }
    out->normal = ref.rotation * plane.plane.normal.normalized();
    return true;
  }

  void RemovePoint(int id) {
    Eigen::Vector3d x;
    if (PointInWorld(id, &x)) mapped.points.push_back(x);
    const int reference = filter->points().at(id).reference;
    filter->RemovePoint(id);
    point_tracks.erase(id);
    if (!filter->references().count(reference)) keyframes.erase(reference);
  }

  void RemovePlane(int id) {
    MapPlane plane;
    if (PlaneInWorld(id, &plane)) mapped.planes.push_back(plane);
    const int reference = filter->planes().at(id).reference;
    filter->RemovePlane(id);
    plane_tracks.erase(id);
    if (!filter->references().count(reference)) keyframes.erase(reference);
  }

  // The members on the convex hull of their keyframe pixels, in order around it.
  static std::vector<int> Hull(const std::vector<PlanePoint>& members) {
    std::vector<cv::Point2f> pixels;
    for (const PlanePoint& m : members) pixels.emplace_back(m.keyframe_pixel.x(), m.keyframe_pixel.y());
    std::vector<int> hull;
    if (!pixels.empty()) cv::convexHull(pixels, hull);
    return hull;
  }

  // The area (keyframe pixels) of the convex hull of a plane's members.
  static double Area(const PlaneTrack& t) {
    std::vector<cv::Point2f> corners;
    for (int k : Hull(t.members)) corners.emplace_back(t.members[k].keyframe_pixel.x(), t.members[k].keyframe_pixel.y());
    return corners.size() < 3 ? 0.0 : cv::contourArea(corners);
  }

  void Record(int id, const PlaneTrack& t) {
    if (static_cast<int>(t.members.size()) < o.min_plane_points) return;
    PlaneRecord& r = records[{generation, id}];
    r.points = std::max(r.points, static_cast<int>(t.members.size()));
    r.area = std::max(r.area, Area(t));
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

  // 1-point RANSAC (Civera et al. 2010): each hypothesis is the state after an update with one measurement;
  // the one that brings most other measurements within `ransac_threshold` px gives the inliers, which update
  // the filter; then any other measurement whose innovation is now within the 99% gate updates it too.
  // Returns, per measurement, whether it was used.
  std::vector<bool> UpdateRobustly(const std::vector<PointMeasurement>& all) {
    std::vector<bool> used(all.size(), false);
    if (all.empty()) return used;
    auto agreeing = [&](const Filter& f) {
      std::vector<bool> in(all.size(), false);
      for (size_t i = 0; i < all.size(); ++i) {
        Eigen::Vector2d predicted;
        in[i] = f.PredictMeasurement(camera, all[i], &predicted, nullptr) &&
                (predicted - all[i].pixel).norm() < o.ransac_threshold;
      }
      return in;
    };
    const int hypotheses = std::min<int>(o.ransac_hypotheses, static_cast<int>(all.size()));
    std::uniform_int_distribution<size_t> pick(0, all.size() - 1);
    long most = 0;
    for (int k = 0; k < hypotheses; ++k) {
      Filter hypothesis = *filter;
      hypothesis.Update(camera, {all[pick(rng)]});
      std::vector<bool> in = agreeing(hypothesis);
      const long count = std::count(in.begin(), in.end(), true);
      if (count > most) {
        most = count;
        used = std::move(in);
      }
    }
    if (most == 0) return used;
    filter->Update(camera, Select(all, used));
    // Rescue: the rest, gated on their innovation after the inliers' update.
    std::vector<bool> rescued(all.size(), false);
    for (size_t i = 0; i < all.size(); ++i) {
      Eigen::Vector2d predicted;
      Eigen::MatrixXd jacobian;
      if (used[i] || !filter->PredictMeasurement(camera, all[i], &predicted, &jacobian)) continue;
      Eigen::Matrix2d s = jacobian * filter->covariance() * jacobian.transpose();
      s.diagonal().array() += all[i].sigma * all[i].sigma;
      const Eigen::Vector2d v = all[i].pixel - predicted;
      rescued[i] = v.dot(s.ldlt().solve(v)) < 9.21;  // chi-square(2), 99%
    }
    const std::vector<PointMeasurement> more = Select(all, rescued);
    if (!more.empty()) filter->Update(camera, more);
    for (size_t i = 0; i < all.size(); ++i) used[i] = used[i] || rescued[i];
    return used;
  }

  // The measurements whose flag is set.
  static std::vector<PointMeasurement> Select(const std::vector<PointMeasurement>& all, const std::vector<bool>& flags) {
    std::vector<PointMeasurement> out;
    for (size_t i = 0; i < all.size(); ++i) {
      if (flags[i]) out.push_back(all[i]);
    }
    return out;
  }

  // Searches for a feature whose pixel is predicted with `jacobian`, warping its keyframe patch by `h`.
  bool Find(const cv::Mat& grey, const cv::Mat& keyframe, const Eigen::Matrix3d& h, const Eigen::Vector2d& predicted,
            const Eigen::MatrixXd& jacobian, Eigen::Vector2d* found) const {
    Eigen::Matrix2d s = jacobian * filter->covariance() * jacobian.transpose();
    s.diagonal().array() += o.pixel_sigma * o.pixel_sigma;
    cv::Mat templ;
    return WarpPatch(keyframe, h, predicted, o.patch_half, &templ) && Search(grey, templ, predicted, s, found);
  }

  void Measure(const cv::Mat& grey, FrameStats* stats) {
    const Rigid3d current = filter->camera().world_from_cam();
    Eigen::Vector2d pixel;
    // Points that left the view (or went behind the camera) leave the filter; planes whose members all left
    // are kept in the record and leave the filter.
    std::vector<int> gone;
    for (const auto& [id, p] : filter->points()) {
      if (!filter->PredictPoint(camera, id, &pixel, nullptr) || !Inside(pixel)) gone.push_back(id);
    }
    for (int id : gone) RemovePoint(id);
    gone.clear();
    for (const auto& [id, t] : plane_tracks) {
      const bool any = std::any_of(t.members.begin(), t.members.end(), [&, id = id](const PlanePoint& m) {
        return filter->PredictPlanePoint(camera, id, m.ray, &pixel, nullptr) && Inside(pixel);
      });
      if (!any) gone.push_back(id);
    }
    for (int id : gone) {
      Record(id, plane_tracks.at(id));
      RemovePlane(id);
    }

    std::vector<PointMeasurement> measurements;
    std::vector<std::pair<History*, size_t>> searched;  // per measurement: its feature's history, observation
    Eigen::MatrixXd jacobian;
    // Searches for the feature predicted at `pixel` (with `jacobian`); `plane` is its plane's id or -1.
    auto search = [&](int id, int plane, const Eigen::Vector3d& ray, int reference, const Eigen::Matrix3d& h,
                      const Eigen::Vector2d& keyframe_pixel, History* history) {
      ++stats->attempted;
      const Keyframe& keyframe = keyframes.at(reference);
      Eigen::Vector2d found;
      const bool matched = Find(grey, keyframe.grey, h, pixel, jacobian, &found);
      if (matched) {
        measurements.push_back({id, found, o.pixel_sigma, ray});
        searched.emplace_back(history, observations.size());
        history->misses = 0;
      } else {
        ++history->misses;
      }
      observations.push_back({matched ? found : pixel, plane, matched, false, keyframe_pixel, keyframe.time});
    };
    for (const auto& [id, p] : filter->points()) {
      if (stats->attempted >= o.max_measurements) break;
      filter->PredictPoint(camera, id, &pixel, &jacobian);
      const Eigen::Matrix3d h = PlaneHomography(camera, current, filter->references().at(p.reference).world_from_cam,
                                                FrontoParallel(p.ray, std::max(p.inverse_depth, 1e-3)));
      PointTrack& track = point_tracks.at(id);
      search(id, -1, Eigen::Vector3d::Zero(), p.reference, h, track.keyframe_pixel, &track.history);
    }
    for (auto& [id, t] : plane_tracks) {
      const Filter::Plane& plane = filter->planes().at(id);
      const Eigen::Matrix3d h =
          PlaneHomography(camera, current, filter->references().at(plane.reference).world_from_cam, plane.plane);
      for (PlanePoint& m : t.members) {
        if (stats->attempted >= o.max_measurements) break;
        if (!filter->PredictPlanePoint(camera, id, m.ray, &pixel, &jacobian) || !Inside(pixel)) continue;
        search(id, id, m.ray, plane.reference, h, m.keyframe_pixel, &m.history);
      }
    }
    const std::vector<bool> used = UpdateRobustly(measurements);
    for (size_t i = 0; i < used.size(); ++i) {
      ++searched[i].first->matched;
      searched[i].first->rejected += !used[i];
      observations[searched[i].second].used = used[i];
    }
    stats->measurements = static_cast<int>(std::count(used.begin(), used.end(), true));
    frames_without_measurements = stats->measurements == 0 ? frames_without_measurements + 1 : 0;
    std::vector<int> bad;
    for (const auto& [id, t] : point_tracks) {
      if (Gone(t.history)) bad.push_back(id);
    }
    for (int id : bad) RemovePoint(id);
    if (o.mode == "idpp") GrowPlanes();
  }

  // The 3D consistency test of plane growing: a candidate is an inverse-depth point of its own (prior: where
  // its ray meets the plane, 100% uncertain), measured like any point; once its inverse depth is known to 25%
  // (after at least candidate_frames frames) it joins the plane if that agrees with where its ray meets the
  // plane (within join_gate combined standard deviations; its depth is then fused into the plane, up to `planarity`),
  // otherwise it stays an ordinary point; one not known after plane_grow_frames stays a point too. Members
  // missed too often leave; each plane takes up to new_plane_points new candidates a frame from its keyframe's
  // corners near its members (at least min_distance apart); a plane with fewer than min_plane_points after
  // plane_grow_frames becomes a point.
  void GrowPlanes() {
    std::vector<int> to_points, empty;
    for (auto& [id, t] : plane_tracks) {
      ++t.age;
      std::erase_if(t.members, [&](const PlanePoint& m) { return Gone(m.history); });
      if (t.members.empty()) {
        empty.push_back(id);
        continue;
      }
      std::vector<Candidate> waiting;
      for (Candidate& c : t.candidates) {
        if (!filter->points().count(c.point)) continue;  // left the view or was lost
        ++c.age;
        const Filter::Point& p = filter->points().at(c.point);
        const double variance = filter->covariance()(p.offset, p.offset);
        const bool known = p.inverse_depth > 0 && std::sqrt(variance) < 0.25 * p.inverse_depth;
        if (!known || c.age < o.candidate_frames) {
          if (c.age < o.plane_grow_frames) waiting.push_back(c);
          continue;  // otherwise it stays an ordinary point
        }
        const Filter::Plane& plane = filter->planes().at(id);
        if (p.reference != plane.reference) continue;
        const double on_plane = plane.plane.InverseDepthAlong(p.ray);
        const double plane_variance = InverseDepthVariance(plane, p.ray);
        if (on_plane > 0 && std::abs(p.inverse_depth - on_plane) < o.join_gate * std::sqrt(variance + plane_variance)) {
          const PointTrack& track = point_tracks.at(c.point);
          const PlanePoint joined{track.keyframe_pixel, p.ray, track.history};
          filter->MergePointIntoPlane(c.point, id, o.planarity * on_plane);
          point_tracks.erase(c.point);
          t.members.push_back(joined);
        }
      }
      t.candidates = std::move(waiting);
      AddCandidates(id, &t);
      Record(id, t);
      if (t.age >= o.plane_grow_frames && static_cast<int>(t.members.size()) < o.min_plane_points) {
        to_points.push_back(id);
      }
    }
    for (int id : empty) RemovePlane(id);
    // A plane that did grow and has lost its members (most left the view) stays in the record.
    for (int id : to_points) {
      const PlanePoint seed = plane_tracks.at(id).members.front();
      plane_tracks.erase(id);
      point_tracks[filter->PlaneToPoint(id, seed.ray)] = {seed.keyframe_pixel, {}};
    }
  }

  // The variance of the inverse depth at which `ray` meets the plane (first order in (n, rho_p)).
  double InverseDepthVariance(const Filter::Plane& plane, const Eigen::Vector3d& ray) const {
    const Eigen::RowVector4d j = plane.plane.InverseDepthJacobian(ray);
    return (j * filter->covariance().block<4, 4>(plane.offset, plane.offset) * j.transpose())(0, 0);
  }

  void AddCandidates(int id, PlaneTrack* t) {
    const Filter::Plane& plane = filter->planes().at(id);
    Keyframe& keyframe = keyframes.at(plane.reference);
    int added = 0;
    for (Corner& corner : keyframe.corners) {
      if (added >= o.new_plane_points) break;
      if (corner.used) continue;
      double nearest = 1e9;
      for (const PlanePoint& m : t->members) nearest = std::min(nearest, (m.keyframe_pixel - corner.pixel).norm());
      if (nearest > o.grow_radius || nearest < o.min_distance) continue;
      const Eigen::Vector3d ray = camera.Ray(corner.pixel);
      const double rho = plane.plane.InverseDepthAlong(ray);
      if (rho <= 0) continue;
      corner.used = true;
      const int point = filter->AddPoint(plane.reference, ray, rho, PriorSigma(rho));
      point_tracks[point] = {corner.pixel, {}};
      t->candidates.push_back({point, 0});
      ++added;
    }
  }

  // The features in the filter now, as map entries.
  Map CurrentMap() const {
    Map m;
    Eigen::Vector3d x;
    for (const auto& [id, p] : filter->points()) {
      if (PointInWorld(id, &x)) m.points.push_back(x);
    }
    MapPlane plane;
    for (const auto& [id, t] : plane_tracks) {
      if (PlaneInWorld(id, &plane)) m.planes.push_back(plane);
    }
    return m;
  }

  FrameStats Track(const cv::Mat& grey, double timestamp) {
    FrameStats stats;
    stats.timestamp = timestamp;
    observations.clear();
    if (!started) {
      size = grey.size();
      Start(grey, timestamp, CameraState());
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
        for (const auto& [id, t] : plane_tracks) Record(id, t);
        mapped.Append(CurrentMap());
        Start(grey, timestamp, at);
        stats.keyframe = true;
      } else if (boot.active && StepBootstrap(grey, timestamp)) {
        stats.keyframe = stats.bootstrap = true;
      } else if (static_cast<int>(VisibleFeatures().size()) < o.min_features) {
        stats.keyframe = MakeKeyframe(grey, timestamp);
      }
    }
    last_time = timestamp;
    trajectory.push_back({timestamp, filter->camera().world_from_cam()});
    stats.points = static_cast<int>(filter->points().size());
    stats.planes = static_cast<int>(filter->planes().size());
    for (const auto& [id, t] : plane_tracks) stats.plane_points += static_cast<int>(t.members.size());
    stats.state_size = filter->size();
    return stats;
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

Rigid3d Odometry::world_from_cam() const {
  PDVO_THROW_CHECK(impl_->started, InvalidArgument, "odometry: no frame tracked yet");
  return impl_->filter->camera().world_from_cam();
}

Map Odometry::map() const {
  Map m = impl_->mapped;
  if (impl_->started) {
    m.Append(impl_->CurrentMap());
  }
  return m;
}

const std::vector<Observation>& Odometry::observations() const { return impl_->observations; }

const Trajectory& Odometry::trajectory() const { return impl_->trajectory; }

MappingStats Odometry::mapping() const {
  MappingStats m;
  for (const auto& [id, r] : impl_->records) {
    ++m.planes;
    m.points_per_plane += r.points;
    m.mean_plane_area += r.area;
  }
  if (m.planes > 0) {
    m.points_per_plane /= m.planes;
    m.mean_plane_area /= m.planes;
  }
  return m;
}

const Filter& Odometry::filter() const { return *impl_->filter; }

}  // namespace pdvo::vo
