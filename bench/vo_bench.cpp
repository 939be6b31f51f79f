// The visual odometry on a synthetic street (default 1,000 frames at 320x240, 30 frames/s, seed 1): tracking
// speed on one thread (frames are rendered first and not timed), ATE after Sim(3) alignment as a share of the
// path length, keyframes, lost-track events, the filter's consistency (NEES of the camera orientation, which
// monocular VO observes without scale, against the ground truth expressed in the first camera's frame), and the
// resident memory of tracking (rendered frames excluded). The NEES takes the camera the filter fixed when it
// started (the first frame, or the frame of the two-view bootstrap) as exact. In idpp mode, the purity of the
// planes: how many of their points lie on the same true surface.
// Usage: vo_bench [frames] [seed] [option=value ...]   (VoOptions, e.g. mode=idpp search.pixel_sigma=0.5)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"

#include "pdvo/eval/plane_match.h"
#include "pdvo/eval/trajectory_error.h"
#include "memory.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/odometry.h"

using pdvo::bench::ResidentMiB;

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 1000;
  const uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  pdvo::vo::VoOptions vo_options;
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "vo_bench: expected option=value, got '%s'\n", argv[i]);
      return 2;
    }
    try {
      pdvo::SetOption(vo_options, arg.substr(0, eq), arg.substr(eq + 1));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "vo_bench: %s\n", e.what());
      return 2;
    }
  }
  pdvo::sim::SynthOptions options;
  const pdvo::Camera camera = options.MakeCamera();
  const double length = options.walk.speed * frames / options.walk.fps;
  const pdvo::sim::Street street = pdvo::sim::GenerateStreet(options.street, length + 30, seed);
  const pdvo::Trajectory walk = pdvo::sim::WalkStreet(street, options.walk, frames, seed);
  std::vector<cv::Mat> grey;
  const pdvo::sim::Renderer renderer(street, camera, options.render, seed);
  const pdvo::vo::FramePreparer preparer(camera, vo_options.working_width);  // as pdvo vo prepares frames
  for (const pdvo::StampedPose& pose : walk) {
    pdvo::sim::RenderedFrame frame;
    renderer.Render({pose.world_from_cam}, pose.timestamp, grey.size(), &frame);
    grey.push_back(preparer.Prepare(frame.image).grey);
  }
  const double before = ResidentMiB();
  pdvo::vo::Odometry odometry(preparer.working_camera(), vo_options);
  int keyframes = 0, lost = 0, bootstrap = -1;
  double measurements = 0, peak = before, nees_sum = 0, relative_nees_sum = 0;
  // The newest keyframe's orientation, estimated and true.
  Eigen::Quaterniond key_estimate = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond key_truth = walk.front().world_from_cam.rotation;
  int nees_frames = 0, nees_inside = 0;
  struct Member {  // a plane's point in view, for the purity below
    int frame, plane, keyframe;
    Eigen::Vector2d keyframe_pixel;
  };
  std::vector<Member> members;
  // The filter fixes the orientation of the camera it starts at (the gauge), the first frame's and again the
  // frame of a restart (bootstrap or lost): the truth is compared in that camera's frame.
  Eigen::Quaterniond gauge = walk.front().world_from_cam.rotation.conjugate();
  const auto start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < grey.size(); ++k) {
    const pdvo::vo::FrameStats s = odometry.Track(grey[k], walk[k].timestamp);
    keyframes += s.keyframe;
    if (s.bootstrap) bootstrap = static_cast<int>(k);
    lost += s.lost;
    measurements += s.measurements;
    if (s.lost || s.bootstrap) gauge = odometry.world_from_cam().rotation * walk[k].world_from_cam.rotation.conjugate();
    if (!s.lost && !s.bootstrap && k > 0) {
      // Orientation error on the right, as the filter's error state: R_est Exp(e) = R_true.
      const Eigen::Quaterniond truth = gauge * walk[k].world_from_cam.rotation;
      const Eigen::Vector3d e = pdvo::LogSO3(odometry.world_from_cam().rotation.conjugate() * truth);
      const Eigen::Matrix3d p = odometry.filter().covariance().block<3, 3>(3, 3);
      const double nees = e.dot(p.ldlt().solve(e));
      nees_sum += nees;
      ++nees_frames;
      nees_inside += nees < 7.815;  // chi-square(3), 95%
      // The same relative to the newest keyframe, whose pose fixed reference cameras take as exact: then the
      // camera's covariance is its uncertainty relative to its keyframes.
      const Eigen::Quaterniond relative_truth = key_truth.conjugate() * walk[k].world_from_cam.rotation;
      const Eigen::Quaterniond relative = key_estimate.conjugate() * odometry.world_from_cam().rotation;
      const Eigen::Vector3d r = pdvo::LogSO3(relative.conjugate() * relative_truth);
      relative_nees_sum += r.dot(p.ldlt().solve(r));
    }
    if (s.keyframe) {
      key_estimate = odometry.world_from_cam().rotation;
      key_truth = walk[k].world_from_cam.rotation;
    }
    for (const pdvo::vo::Observation& o : odometry.observations()) {
      if (o.plane >= 0) {
        const int keyframe = static_cast<int>(std::lround(o.keyframe_time * options.walk.fps));
        members.push_back({static_cast<int>(k), o.plane, keyframe, o.keyframe_pixel});
      }
    }
    if (k % 100 == 0) peak = std::max(peak, ResidentMiB());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  peak = std::max(peak, ResidentMiB());
  const pdvo::AteResult ate = pdvo::ComputeAte(walk, odometry.trajectory(), pdvo::Alignment::kSim3, 1e-3);
  const double path = pdvo::PathLength(walk);
  const pdvo::vo::MappingStats mapping = odometry.mapping();
  // Plane purity: per frame, each plane's members (if 4 or more) by the true surface at their keyframe pixel
  // (coplanar polygons share a surface; non-planar objects and the sky count as one other); the share of them
  // on their plane's most common surface.
  std::map<int, cv::Mat> surfaces;  // by keyframe: the true ids
  pdvo::PlanePurity purity;
  for (const Member& m : members) {
    cv::Mat& id = surfaces[m.keyframe];
    if (id.empty()) {
      pdvo::sim::RenderedFrame geometry;
      renderer.RenderGeometry(walk.at(m.keyframe).world_from_cam, &geometry);
      id = geometry.id;
    }
    const int at = id.at<int>(cvRound(m.keyframe_pixel.y()), cvRound(m.keyframe_pixel.x()));
    purity.Add(m.frame, m.plane, at >= 0 ? street.planes.at(at).surface : -1);
  }
  long plane_members = 0;
  const double pure = purity.Share(4, &plane_members);
  std::printf("vo_bench: %d frames 320x240, seed %llu, mode %s, path %.1f m\n", frames,
              static_cast<unsigned long long>(seed), pdvo::OptionName(vo_options.mode).c_str(), path);
  std::printf("  tracking         %.1f frames/s (one thread; target >= 200)\n", frames / seconds);
  std::printf("  ATE (Sim3)       rmse %.3f m = %.2f%% of the path (target <= 1%%), max %.3f m\n",
              ate.translation.rmse, 100 * ate.translation.rmse / path, ate.translation.max);
  std::printf("  NEES orientation mean %.2f (chi-square(3): 3), %.1f%% of frames inside the 95%% bound (7.81); "
              "relative to the newest keyframe %.2f\n",
              nees_sum / std::max(1, nees_frames), 100.0 * nees_inside / std::max(1, nees_frames),
              relative_nees_sum / std::max(1, nees_frames));
  std::printf("  measurements     %.1f per frame; %d keyframes; lost %d times; two-view bootstrap at frame %d\n",
              measurements / frames, keyframes, lost, bootstrap);
  if (plane_members > 0) {
    std::printf("  plane purity     %.2f of the points of planes on their plane's main true surface\n", pure);
  }
  std::printf("  planes           %d made, %.1f points per plane, mean area %.0f px\n", mapping.planes,
              mapping.points_per_plane, mapping.mean_plane_area);
  std::printf("  memory           %.1f MiB resident with the frames, tracking added %.1f MiB (peak %.1f MiB)\n",
              before, peak - before, peak);
  return 0;
}
