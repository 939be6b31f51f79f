#include "pdvo/vo/odometry.h"

#include <algorithm>
#include <chrono>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"

namespace pdvo::vo {
namespace {

// A keyframe looks for this many corners per new feature it may make.
constexpr int kCornersPerNewFeature = 4;
// The standard deviation (m, rad) of the pose the filter starts at: the gauge, fixed.
constexpr double kGaugeSigma = 1e-6;
// New features take the depth of the nearest mapped point once this many are mapped in view.
constexpr size_t kMinPriorPoints = 5;
// A point's patch is warped as the fronto-parallel plane at its inverse depth, at least this (1/m).
constexpr double kMinWarpInverseDepth = 1e-3;
// The motion noise's adaptation (MotionNoise::max_adaptation): the mean normalised innovation squared of a
// frame's matches (2 expected of a consistent filter; about 0.2 on synthetic streets, whose motion is smooth)
// above which the noise doubles, and under which it shrinks back by kAdaptationDecay.
constexpr double kNisHigh = 1.0;
constexpr double kNisLow = 0.3;
constexpr double kAdaptationDecay = 1.2;

}  // namespace

bool PriorOptions::Check() const {
  PDVO_CHECK_OPTION(inverse_depth > 0 && inverse_depth_sigma > 0 && velocity_sigma > 0 && angular_velocity_sigma > 0);
  return true;
}

bool VoOptions::Check() const {
  PDVO_CHECK_OPTION(working_width == 0 || (working_width >= 64 && working_width <= kMaxImageSide));
  PDVO_CHECK_OPTION(lost_after >= 1);
  if (!features.Check() || !search.Check() || !ransac.Check() || !prior.Check() || !bootstrap.Check() ||
      !motion.Check() || !planes.Check() || !pdvo.Check() || !health.Check()) {
    return false;
  }
  PDVO_CHECK_OPTION(features.border > search.patch_half);
  PDVO_CHECK_OPTION(planes.grow_radius > features.min_distance);
  return true;
}

struct Odometry::Impl {
  Impl(const Camera& c, const VoOptions& options, std::unique_ptr<PlaneSeeder> s, PlaneDetector detector)
      : camera(c),
        o(options),
        seeder(s ? std::move(s) : MakePlaneSeeder(options.mode, options.planes)),
        grower(c, options.planes, options.pdvo.Growth(), options.features,
               options.prior.inverse_depth_sigma / options.prior.inverse_depth),
        bootstrap(c, options.bootstrap, options.features.border, options.features.min_distance,
                  options.prior.inverse_depth),
        record(options.planes.min_plane_points),
        health(c, options.health, options.features.border, options.features.min_distance) {
    if (detector) {
      detections = std::make_unique<DetectionWorker>(std::move(detector), o.pdvo.schedule, o.pdvo.delay_frames,
                                                     o.pdvo.timeout_seconds);
    }
  }

  Camera camera;
  VoOptions o;
  std::unique_ptr<PlaneSeeder> seeder;  // none: no planes
  PlaneGrower grower;
  TwoViewBootstrap bootstrap;
  std::unique_ptr<Filter> filter;
  Tracks tracks;
  MapRecord record;
  Trajectory trajectory;                        // every frame's pose
  std::vector<Observation> observations;        // of the last frame
  std::mt19937 rng{1};                          // RANSAC; fixed seed: the same frames give the same trajectory
  std::unique_ptr<DetectionWorker> detections;  // mode pdvo
  int detections_failed = 0;
  double last_time = 0;
  bool started = false;
  HealthCheck health;
  int segment = 0;
  double adaptation = 1;  // of the motion noise (MotionNoise::max_adaptation)
  int rough_frames = 0;   // in a row whose innovations exceed kNisHigh

  FrameStats Track(const cv::Mat& grey, double timestamp, const cv::Mat& colour) {
    FrameStats stats;
    stats.timestamp = timestamp;
    observations.clear();
    if (!started) {
      Start(grey, timestamp, CameraState());
      started = true;
      stats.keyframe = true;
    } else {
      filter->Predict(timestamp - last_time, o.motion.Scaled(adaptation));
      tracks.LeaveView(camera, o.features, filter.get(), &record);
      const Search search = SearchFeatures(grey, &stats);
      const RobustUpdateResult update = UpdateRobustly(camera, o.ransac, search.matches, &rng, filter.get());
      Tally(search, update, &stats);
      Adapt(stats);
      const bool evidence = health.Evidence(stats.update, stats.measurements, stats.attempted);
      std::vector<int> used_references;
      for (size_t i = 0; i < update.used.size(); ++i)
        if (update.used[i]) used_references.push_back(search.references[i]);
      stats.health = health.Judge(evidence, stats.nis, used_references, filter->references());
      tracks.LeaveRejected(o.features, filter.get(), &record);
      grower.Grow(filter.get(), &tracks, &record);
      if (Lost()) {
        stats.lost = true;
        stats.health = Health::kLost;
        ++segment;
        CameraState at = filter->camera();
        if (!at.position.allFinite() || !at.orientation.coeffs().allFinite()) at = CameraState();
        record.KeepAll(*filter, tracks);
        Start(grey, timestamp, at);
        stats.keyframe = true;
      } else if (std::optional<BootstrapStart> start = bootstrap.Step(grey, timestamp, filter->camera().orientation)) {
        for (const auto& [index, pose] : start->revised) trajectory.at(index).world_from_cam = pose;
        record.DiscardFilter();
        Restart(grey, timestamp, start->camera, o.bootstrap.velocity_sigma * start->camera.velocity.norm(),
                &start->corners);
        stats.keyframe = stats.bootstrap = true;
      } else if (static_cast<int>(tracks.Visible(*filter, camera, o.features.border).size()) <
                 o.features.min_features) {
        stats.keyframe = MakeKeyframe(grey, timestamp, nullptr);
        const int reference = stats.keyframe ? filter->references().rbegin()->first : -1;
        if (health.AtKeyframe(grey, filter->camera().world_from_cam(), reference, evidence))
          stats.health = Health::kUncertain;
      }
    }
    stats.segment = segment;
    if (detections) Detect(timestamp, colour, &stats);
    last_time = timestamp;
    trajectory.push_back({timestamp, filter->camera().world_from_cam()});
    stats.points = static_cast<int>(filter->points().size());
    stats.planes = static_cast<int>(filter->planes().size());
    stats.plane_points = tracks.PlanePoints();
    stats.state_size = filter->size();
    return stats;
  }

  // Mode pdvo, at the end of a frame: the detections that arrive now are seeded in their keyframes (or dropped
  // if it has left), and a new keyframe goes to the detector.
  void Detect(double timestamp, const cv::Mat& colour, FrameStats* stats) {
    const int frame = static_cast<int>(trajectory.size());
    for (DetectionResult& result : detections->Collect(frame, &stats->detector_wait_seconds)) {
      DetectionEvent& event = stats->detections.emplace_back();
      event.result = std::move(result);
      const auto keyframe = KeyframeOf(event.result.keyframe);
      event.keyframe_gone = event.result.error.empty() && keyframe == tracks.keyframes.end();
      if (!event.result.error.empty()) {
        if (detections_failed++ == 0) {
          PDVO_LOG(Warning) << "vo: the plane detector failed at the keyframe of frame " << event.result.keyframe
                            << " (" << event.result.error << "); going on without its planes (said once)";
        }
      } else if (!event.keyframe_gone) {
        event.seeding = SeedDetectedPlanes(event.result.planes, keyframe->first, frame, camera, o.pdvo, o.features,
                                           o.prior.inverse_depth_sigma / o.prior.inverse_depth, o.prior.inverse_depth,
                                           filter.get(), &tracks, &record);
      }
      tracks.RemoveOutOfView(filter.get(), &record);  // the planes waiting for it that it did not carry on
    }
    if (stats->keyframe) {
      detections->Offer(
          {frame, timestamp, KeyframeOf(frame)->second.grey, colour.empty() ? cv::Mat() : colour.clone()});
    }
  }
  std::map<int, Keyframe>::iterator KeyframeOf(int frame) {
    return std::find_if(tracks.keyframes.begin(), tracks.keyframes.end(),
                        [&](const auto& k) { return k.second.frame == frame; });
  }

  // The motion noise follows the matches' innovations (MotionNoise::max_adaptation).
  // One frame's large innovations are a jump in the images (the health check flags it), not rougher motion: the
  // noise grows from the second such frame in a row.
  void Adapt(const FrameStats& stats) {
    if (stats.measurements < o.health.min_inliers) return;
    rough_frames = stats.nis > kNisHigh ? rough_frames + 1 : 0;
    if (rough_frames >= 2) {
      adaptation = std::min(o.motion.max_adaptation, 2 * adaptation);
    } else if (stats.nis < kNisLow) {
      adaptation = std::max(1.0, adaptation / kAdaptationDecay);
    }
  }

  // Tracking has failed: a non-finite state, or lost_after frames in a row without enough matches.
  bool Lost() const {
    return !filter->covariance().allFinite() || !filter->camera().position.allFinite() ||
           health.frames_without_evidence() >= o.lost_after;
  }

  // Starts at rest at `at` with generic priors, and arms the two-view bootstrap.
  void Start(const cv::Mat& grey, double timestamp, const CameraState& at) {
    CameraState rest = at;
    rest.velocity.setZero();
    rest.angular_velocity.setZero();
    Restart(grey, timestamp, rest, o.prior.velocity_sigma, nullptr);
    bootstrap.Begin(grey, timestamp, trajectory.size(), rest);
  }

  // A new filter holding only the camera `at` (its position and orientation fixed: the gauge) and a keyframe
  // whose new features take `priors` (if given) or the mapped points' depths.
  void Restart(const cv::Mat& grey, double timestamp, const CameraState& at, double velocity_sigma,
               const std::vector<DepthPrior>* priors) {
    Vector12d sigma;
    sigma << Eigen::Vector3d::Constant(kGaugeSigma), Eigen::Vector3d::Constant(kGaugeSigma),
        Eigen::Vector3d::Constant(velocity_sigma), Eigen::Vector3d::Constant(o.prior.angular_velocity_sigma);
    filter = std::make_unique<Filter>(at, Matrix12d(sigma.cwiseAbs2().asDiagonal()));
    tracks = Tracks();
    record.NewFilter();
    health.Restart(grey, at.world_from_cam());
    MakeKeyframe(grey, timestamp, priors);
  }

  // The matches of a frame's search, and per match its feature's history and its observation.
  struct Search {
    std::vector<PointMeasurement> matches;
    std::vector<std::pair<History*, size_t>> searched;
    std::vector<double> nis;      // per match: its normalised innovation squared against the prediction
    std::vector<int> references;  // per match: its feature's reference camera
  };
  // Searches for every feature in view (at most max_measurements): predicts its pixel and innovation
  // covariance, warps its keyframe patch by its plane's homography (a point's: fronto-parallel), and searches by
  // NCC inside the innovation ellipse. Observations get every feature searched for.
  Search SearchFeatures(const cv::Mat& grey, FrameStats* stats) {
    const Rigid3d current = filter->camera().world_from_cam();
    const cv::Size size(camera.width, camera.height);
    Search out;
    Eigen::Vector2d pixel;
    MeasurementJacobian jacobian;
    auto search = [&](int id, int plane, const Eigen::Vector3d& ray, int reference, const Eigen::Matrix3d& h,
                      const Eigen::Vector2d& keyframe_pixel, History* history) {
      ++stats->attempted;
      const Keyframe& keyframe = tracks.keyframes.at(reference);
      Eigen::Matrix2d s = jacobian.Propagate(filter->covariance());
      s.diagonal().array() += o.search.pixel_sigma * o.search.pixel_sigma;
      cv::Mat patch;
      Eigen::Vector2d found;
      const bool matched = WarpPatch(keyframe.grey, h, pixel, o.search.patch_half, &patch) &&
                           SearchPatch(grey, patch, pixel, s, o.search, &found);
      if (matched) {
        out.matches.push_back({id, found, o.search.pixel_sigma, ray});
        out.nis.push_back((found - pixel).dot(s.inverse() * (found - pixel)));
        out.references.push_back(reference);
        out.searched.emplace_back(history, observations.size());
        history->misses = 0;
      } else {
        ++history->misses;
      }
      observations.push_back({matched ? found : pixel, plane, matched, false, keyframe_pixel, keyframe.time});
    };
    for (const auto& [id, p] : filter->points()) {
      if (stats->attempted >= o.features.max_measurements) break;
      if (!filter->PredictPoint(camera, id, &pixel, &jacobian) || !Inside(pixel, size, o.features.border)) continue;
      const InversePlane patch_plane = FrontoParallel(p.ray, std::max(p.inverse_depth, kMinWarpInverseDepth));
      const Eigen::Matrix3d h =
          PlaneHomography(camera, current, filter->references().at(p.reference).world_from_cam, patch_plane);
      PointTrack& track = tracks.points.at(id);
      search(id, -1, Eigen::Vector3d::Zero(), p.reference, h, track.keyframe_pixel, &track.history);
    }
    for (auto& [id, t] : tracks.planes) {
      const Filter::Plane& plane = filter->planes().at(id);
      const Eigen::Matrix3d h =
          PlaneHomography(camera, current, filter->references().at(plane.reference).world_from_cam, plane.plane);
      for (PlanePoint& m : t.members) {
        if (stats->attempted >= o.features.max_measurements) break;
        const bool in_view =
            filter->PredictPlanePoint(camera, id, m.ray, &pixel, &jacobian) && Inside(pixel, size, o.features.border);
        if (!in_view) continue;
        search(id, id, m.ray, plane.reference, h, m.keyframe_pixel, &m.history);
      }
    }
    return out;
  }

  // The update's outcome in the features' histories, the observations and the frame's statistics.
  void Tally(const Search& search, const RobustUpdateResult& update, FrameStats* stats) {
    for (size_t i = 0; i < update.used.size(); ++i) {
      ++search.searched[i].first->matched;
      search.searched[i].first->rejected += !update.used[i];
      observations[search.searched[i].second].used = update.used[i];
    }
    stats->update = update.status;
    stats->measurements = static_cast<int>(std::count(update.used.begin(), update.used.end(), true));
    double nis = 0;
    for (size_t i = 0; i < update.used.size(); ++i) {
      stats->plane_measurements += update.used[i] && !search.matches[i].ray.isZero();
      if (update.used[i]) nis += search.nis[i];
    }
    stats->nis = stats->measurements > 0 ? nis / stats->measurements : 0;
  }

  // The mapped points as the current camera sees them: pixel and inverse distance.
  std::vector<DepthPrior> MappedInView() const {
    std::vector<DepthPrior> out;
    const Rigid3d cam_from_world = filter->camera().world_from_cam().Inverse();
    Eigen::Vector2d pixel;
    Eigen::Vector3d x;
    for (const auto& [id, p] : filter->points()) {
      if (!PointInWorld(*filter, id, &x) || !filter->PredictPoint(camera, id, &pixel, nullptr) ||
          !Inside(pixel, cv::Size(camera.width, camera.height), 0))
        continue;
      out.push_back({pixel, 1 / (cam_from_world * x).norm()});
    }
    return out;
  }

  // A new feature's inverse-depth prior at `pixel`: that of the prior nearest in the image (depth varies
  // smoothly over most of a scene), or the options' while fewer than kMinPriorPoints are known.
  double PriorInverseDepth(const std::vector<DepthPrior>& known, const Eigen::Vector2d& pixel) const {
    if (known.size() < kMinPriorPoints) return o.prior.inverse_depth;
    const auto nearest = std::min_element(known.begin(), known.end(), [&](const DepthPrior& a, const DepthPrior& b) {
      return (a.pixel - pixel).squaredNorm() < (b.pixel - pixel).squaredNorm();
    });
    return nearest->inverse_depth;
  }
  // A prior's standard deviation: the same share of it as the options' prior.
  double PriorSigma(double rho) const { return o.prior.inverse_depth_sigma / o.prior.inverse_depth * rho; }

  // A keyframe: corners away from the features in view; the seeder's planes at some of them, and points at the
  // strongest others. False (no keyframe) if there is no corner.
  bool MakeKeyframe(const cv::Mat& grey, double timestamp, const std::vector<DepthPrior>* priors) {
    cv::Mat mask = InsideMask(grey.size(), o.features.border);
    for (const Eigen::Vector2d& p : tracks.Visible(*filter, camera, o.features.border)) {
      cv::circle(mask, cv::Point(cvRound(p.x()), cvRound(p.y())), static_cast<int>(o.features.min_distance),
                 cv::Scalar(0), cv::FILLED);
    }
    std::vector<cv::Point2f> found;
    cv::goodFeaturesToTrack(grey, found, kCornersPerNewFeature * o.features.new_features, kCornerQuality,
                            o.features.min_distance, mask);
    if (found.empty()) return false;
    const std::vector<DepthPrior> known = priors ? *priors : MappedInView();

    const int reference = filter->AddReference(o.fixed_references);
    Keyframe& keyframe = tracks.keyframes[reference];
    keyframe.grey = grey.clone();
    keyframe.time = timestamp;
    keyframe.frame = static_cast<int>(trajectory.size());
    for (const cv::Point2f& c : found) keyframe.corners.push_back({Eigen::Vector2d(c.x, c.y), false});
    const std::vector<PlaneSeed> seeds = seeder ? seeder->Seed(keyframe, camera) : std::vector<PlaneSeed>();
    for (const PlaneSeed& seed : seeds) {
      Corner& corner = keyframe.corners.at(seed.corner);
      corner.used = true;
      const double rho = PriorInverseDepth(known, corner.pixel);
      const int id = filter->AddPlane(reference, {seed.normal, rho}, seed.sigma_normal, PriorSigma(rho));
      tracks.planes[id].members.push_back({corner.pixel, camera.Ray(corner.pixel), {}});
    }
    // Points: the strongest corners left (goodFeaturesToTrack sorts by strength).
    std::vector<Filter::NewPoint> points;
    std::vector<Eigen::Vector2d> pixels;
    for (Corner& c : keyframe.corners) {
      if (c.used || static_cast<int>(points.size() + seeds.size()) >= o.features.new_features) continue;
      c.used = true;
      const double rho = PriorInverseDepth(known, c.pixel);
      points.push_back({camera.Ray(c.pixel), rho, PriorSigma(rho)});
      pixels.push_back(c.pixel);
    }
    const std::vector<int> ids = filter->AddPoints(reference, points);
    for (size_t k = 0; k < ids.size(); ++k) tracks.points[ids[k]] = {pixels[k], {}};
    return true;
  }
};

Odometry::Odometry(const Camera& camera, const VoOptions& options, std::unique_ptr<PlaneSeeder> seeder,
                   PlaneDetector detector) {
  CheckOptionsOrThrow(options, "vo options");
  PDVO_THROW_CHECK((options.mode == PlaneMode::kPdvo) == static_cast<bool>(detector), InvalidArgument,
                   "odometry: mode " << OptionName(options.mode)
                                     << (detector ? " takes no plane detector" : " needs a plane detector"));
  camera.Check("odometry camera");
  PDVO_THROW_CHECK(!camera.HasDistortion(), InvalidArgument,
                   "odometry: the camera has distortion; frames must be undistorted (FramePreparer)");
  PDVO_THROW_CHECK(camera.width > 2 * options.features.border && camera.height > 2 * options.features.border,
                   InvalidArgument,
                   "odometry: a " << camera.width << "x" << camera.height << " camera leaves no pixels inside the "
                                  << options.features.border << " px border");
  impl_ = std::make_unique<Impl>(camera, options, std::move(seeder), std::move(detector));
}

Odometry::~Odometry() = default;

FrameStats Odometry::Track(const cv::Mat& grey, double timestamp, const cv::Mat& colour) {
  const Camera& c = impl_->camera;
  PDVO_THROW_CHECK(!grey.empty() && grey.type() == CV_8UC1, InvalidArgument, "odometry: frames must be 8-bit grey");
  PDVO_THROW_CHECK(
      grey.cols == c.width && grey.rows == c.height, InvalidArgument,
      "odometry: the frame is " << grey.cols << "x" << grey.rows << ", the camera " << c.width << "x" << c.height);
  PDVO_THROW_CHECK(std::isfinite(timestamp), InvalidArgument, "odometry: the timestamp is not finite");
  PDVO_THROW_CHECK(!impl_->started || timestamp > impl_->last_time, InvalidArgument,
                   "odometry: timestamps must increase (" << impl_->last_time << " then " << timestamp << ")");
  const auto start = std::chrono::steady_clock::now();
  PDVO_THROW_CHECK(colour.empty() || (colour.type() == CV_8UC3 && colour.size() == grey.size()), InvalidArgument,
                   "odometry: the colour frame must be 8-bit BGR of the grey frame's size");
  FrameStats stats = impl_->Track(grey, timestamp, colour);
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() - stats.detector_wait_seconds;
  return stats;
}

Rigid3d Odometry::world_from_cam() const {
  PDVO_THROW_CHECK(impl_->started, InvalidArgument, "odometry: no frame tracked yet");
  return impl_->filter->camera().world_from_cam();
}

Map Odometry::map() const {
  Map m = impl_->record.kept();
  if (impl_->started) {
    m.Append(
        CurrentMap(*impl_->filter, impl_->tracks, impl_->o.planes.min_plane_points, impl_->record.filter_number()));
  }
  return m;
}

const std::vector<Observation>& Odometry::observations() const { return impl_->observations; }

std::vector<Odometry::PlaneOutline> Odometry::plane_outlines() const {
  std::vector<PlaneOutline> out;
  if (!impl_->started) return out;
  const Filter& f = *impl_->filter;
  const Camera& camera = impl_->camera;
  const Rigid3d cam_from_world = f.camera().world_from_cam().Inverse();
  for (const auto& [id, track] : impl_->tracks.planes) {
    const Filter::Plane& plane = f.planes().at(id);
    const Rigid3d cam_from_ref = cam_from_world * f.references().at(plane.reference).world_from_cam;
    // Keyframe pixels through the plane into the current frame.
    auto carry = [&](const std::vector<Eigen::Vector2d>& pixels) {
      std::vector<Eigen::Vector2d> seen;
      for (const Eigen::Vector2d& q : pixels) {
        const Eigen::Vector3d ray = camera.Ray(q);
        const double rho = plane.plane.InverseDepthAlong(ray);
        if (rho <= 0) continue;
        const Eigen::Vector3d x = cam_from_ref * (ray / rho);
        if (x.z() > 1e-6) seen.push_back(camera.Project(x));
      }
      return seen;
    };
    out.push_back({id, carry(PlaneHull(track)), carry(track.outline)});
  }
  return out;
}

Odometry::DetectionCounts Odometry::detection_counts() const {
  if (!impl_->detections) return {};
  return {impl_->detections->skipped(), impl_->detections->timed_out(), impl_->detections_failed};
}

const Trajectory& Odometry::trajectory() const { return impl_->trajectory; }

MappingStats Odometry::mapping() const { return impl_->record.stats(); }

const Filter& Odometry::filter() const {
  PDVO_THROW_CHECK(impl_->started, InvalidArgument, "odometry: no frame tracked yet");
  return *impl_->filter;
}

}  // namespace pdvo::vo
