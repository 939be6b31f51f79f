// The visual odometry on a synthetic street (default 1,000 frames at 320x240, 30 frames/s, seed 1): tracking
// speed on one thread (frames are rendered first and not timed), ATE after Sim(3) alignment as a share of the
// path length, keyframes, lost-track events, the filter's consistency (NEES of the camera orientation, which
// monocular VO observes without scale, against the ground truth expressed in the first camera's frame), and the
// resident memory of tracking (rendered frames excluded). The NEES takes the camera the filter fixed when it
// started (the first frame, or the frame of the two-view bootstrap) as exact. In idpp mode, the purity of the
// planes: how many of their points lie on the same true surface, and the median error of their normals. The
// match accuracy: how many of the matches the filter used lie within 1.5 px of where the true point under the
// feature's keyframe pixel is seen (the rendered depth; a corner on an occluding edge counts as its pixel's),
// and their median distance from it. The searches by age: per feature age (frames since its keyframe), the share
// of searches that found the feature, and of the misses with a truth (not the sky) those predicted within 3 px of
// it (the patch did not correlate well enough) or beyond the largest search window (the prediction was off).
// In pdvo mode the planes come from `source=model` (the detector with the shipped model, or model=PATH) or
// `source=oracle` (the street's exact annotation of each keyframe); the tracking thread's time is its CPU time
// (the detector's thread excluded; the deterministic schedule's waits excluded).
// Usage: vo_bench [frames] [seed] [option=value ...]   (VoOptions, e.g. mode=idpp search.pixel_sigma=0.5,
//        and for mode=pdvo source=model|oracle model=PATH; synth=FILE: the street's options, section synth:,
//        e.g. synth=sim/config/driving.yaml for a car)
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <map>
#include <set>

#include "pdvo/common/geometry.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"

#include "pdvo/annotations/annotation.h"
#include "pdvo/eval/plane_match.h"
#include "pdvo/eval/trajectory_error.h"
#include "pdvo/infer/detector.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/odometry.h"

using pdvo::ResidentMiB;

namespace {
double ThreadSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}
}  // namespace

int main(int argc, char** argv) {
  pdvo::KeepFreedMemory();  // as pdvo does
  const int frames = argc > 1 ? std::atoi(argv[1]) : 1000;
  const uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const bool help = argc > 1 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help");
  if (help || frames <= 0) {
    std::fprintf(stderr,
                 "usage: vo_bench [frames (default 1000)] [seed (default 1)] [option=value ...]\n"
                 "  options: those of pdvo vo (e.g. mode=idpp search.min_ncc=0.85); source=model|oracle and\n"
                 "  model=PATH for mode=pdvo; synth=FILE for the street (e.g. synth=sim/config/driving.yaml)\n");
    return help ? 0 : 2;
  }
  pdvo::vo::VoOptions vo_options;
  std::string source = "model", model_path = std::string(PDVO_SOURCE_DIR) + "/models/default/model.yml";
  std::string synth_path;  // the street's options (section synth:), e.g. sim/config/driving.yaml
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "vo_bench: expected option=value, got '%s'\n", argv[i]);
      return 2;
    }
    const std::string key = arg.substr(0, eq);
    if (key == "source" || key == "model" || key == "synth") {
      (key == "source" ? source : key == "model" ? model_path : synth_path) = arg.substr(eq + 1);
      continue;
    }
    try {
      pdvo::SetOption(vo_options, arg.substr(0, eq), arg.substr(eq + 1));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "vo_bench: %s\n", e.what());
      return 2;
    }
  }
  pdvo::sim::SynthOptions options;
  try {
    if (!synth_path.empty()) options = pdvo::LoadOptions<pdvo::sim::SynthOptions>(synth_path, "synth");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vo_bench: %s\n", e.what());
    return 2;
  }
  // What the benchmark records per frame, for the figures after the run: a frame has at most max_measurements
  // observations. Both records are allocated and touched first, before the frames are rendered (whose freed
  // memory the odometry reuses), so that the memory tracking adds is the odometry's alone.
  struct Member {  // a plane's point in view, for the purity below
    int frame = 0, segment = 0, plane = 0, keyframe = 0;
    Eigen::Vector2d keyframe_pixel = Eigen::Vector2d::Zero();
  };
  struct Match {  // a feature searched for, for the match accuracy and the searches by age below
    int frame = 0, keyframe = 0;
    Eigen::Vector2d keyframe_pixel = Eigen::Vector2d::Zero();
    Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // found, or predicted if not
    bool found = false, used = false;
  };
  const size_t most = static_cast<size_t>(frames) * vo_options.features.max_measurements;
  std::vector<Member> members(most);
  std::vector<Match> matches(most);
  members.clear();
  matches.clear();
  const pdvo::Camera camera = options.MakeCamera();
  const auto [street, walk] = pdvo::sim::MakeWalkedStreet(options, frames, seed);
  std::vector<cv::Mat> grey, colour;
  const pdvo::sim::Renderer renderer(street, camera, options.render, seed);
  const pdvo::vo::FramePreparer preparer(camera, vo_options.working_width);  // as pdvo vo prepares frames
  const bool pdvo_mode = vo_options.mode == pdvo::vo::PlaneMode::kPdvo;
  for (const pdvo::StampedPose& pose : walk) {
    pdvo::sim::RenderedFrame frame;
    renderer.Render({pose.world_from_cam}, pose.timestamp, grey.size(), &frame);
    const pdvo::vo::PreparedFrame prepared = preparer.Prepare(frame.image);
    grey.push_back(prepared.grey);
    if (pdvo_mode) colour.push_back(prepared.colour);
  }
  const pdvo::Camera& working = preparer.working_camera();
  pdvo::vo::PlaneDetector detect;
  std::unique_ptr<pdvo::Detector> detector;
  if (pdvo_mode && source == "model") {
    detector = std::make_unique<pdvo::Detector>(pdvo::PlaneModel::Read(model_path), pdvo::DetectorOptions());
    detect = [&](const pdvo::vo::KeyframeImage& k) {
      return detector->Detect(k.colour, working).Planes(working.width, working.height);
    };
  } else if (pdvo_mode && source == "oracle") {
    detect = [&](const pdvo::vo::KeyframeImage& k) {
      return pdvo::DetectedPlanes(pdvo::sim::AnnotateView(renderer, walk.at(k.frame).world_from_cam), working.width);
    };
  } else if (pdvo_mode) {
    std::fprintf(stderr, "vo_bench: source is model or oracle, not '%s'\n", source.c_str());
    return 2;
  }
  const double before = ResidentMiB();
  pdvo::vo::Odometry odometry(working, vo_options, nullptr, detect);
  int keyframes = 0, lost = 0, uncertain = 0, bootstrap = -1;
  double measurements = 0, peak = before, nees_sum = 0, relative_nees_sum = 0;
  // The newest keyframe's orientation, estimated and true.
  Eigen::Quaterniond key_estimate = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond key_truth = walk.front().world_from_cam.rotation;
  int nees_frames = 0, nees_inside = 0;
  // The filter fixes the orientation of the camera it starts at (the gauge), the first frame's and again the
  // frame of a restart (bootstrap or lost): the truth is compared in that camera's frame.
  Eigen::Quaterniond gauge = walk.front().world_from_cam.rotation.conjugate();
  // Per plane (segment, id: a restart's filter numbers its planes again): its last normal and the keyframe (frame
  // index) of whose camera frame it is; a plane that moved to a later keyframe is one plane.
  struct LastNormal {
    int keyframe = 0;
    Eigen::Vector3d normal;
  };
  std::map<std::pair<int, int>, LastNormal> normals;
  int detected = 0, seeded = 0, extended = 0, dropped = 0;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadSeconds();
  std::vector<double> frame_cpu;  // the tracking thread's CPU time per frame
  // Per plane (keyframe, id): its used measurements by frames since its keyframe (the paper's Fig. 4).
  constexpr int kCurveFrames = 90;
  pdvo::vo::MeasurementCurve measured_after(kCurveFrames, vo_options.planes.min_plane_points);
  for (size_t k = 0; k < grey.size(); ++k) {
    const double frame_start = ThreadSeconds();
    const pdvo::vo::FrameStats s = odometry.Track(grey[k], walk[k].timestamp, pdvo_mode ? colour[k] : cv::Mat());
    frame_cpu.push_back(ThreadSeconds() - frame_start);
    for (const pdvo::vo::DetectionEvent& e : s.detections) {
      detected += e.seeding.detected;
      seeded += e.seeding.seeded;
      extended += e.seeding.extended;
      dropped += e.keyframe_gone;
    }
    keyframes += s.keyframe;
    if (s.bootstrap) bootstrap = static_cast<int>(k);
    lost += s.lost;
    uncertain += s.health == pdvo::vo::Health::kUncertain;
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
    if (s.bootstrap) {  // the map forgets the planes of the filter the bootstrap replaced, and so does this
      members.clear();
      normals.clear();
      measured_after = pdvo::vo::MeasurementCurve(kCurveFrames, vo_options.planes.min_plane_points);
    }
    if (s.keyframe) {
      key_estimate = odometry.world_from_cam().rotation;
      key_truth = walk[k].world_from_cam.rotation;
    }
    for (const pdvo::vo::Observation& o : odometry.observations()) {
      const int keyframe = static_cast<int>(std::lround(o.keyframe_time * options.walk.fps));
      matches.push_back({static_cast<int>(k), keyframe, o.keyframe_pixel, o.pixel, o.matched, o.used});
      if (o.plane >= 0) {
        members.push_back({static_cast<int>(k), s.segment, o.plane, keyframe, o.keyframe_pixel});
        measured_after.Add(static_cast<int>(k), keyframe, o.plane, o.keyframe_pixel, o.used);
        const auto plane = odometry.filter().planes().find(o.plane);
        if (plane != odometry.filter().planes().end()) {
          normals[{s.segment, o.plane}] = {keyframe, plane->second.plane.normal.normalized()};
        }
      }
    }
    if (k % 100 == 0) peak = std::max(peak, ResidentMiB());
  }
  const double cpu_seconds = ThreadSeconds() - cpu_start;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  peak = std::max(peak, ResidentMiB());
  const pdvo::AteResult ate = pdvo::ComputeAte(walk, odometry.trajectory(), pdvo::Alignment::kSim3, 1e-3);
  const double path = pdvo::PathLength(walk);
  const pdvo::vo::MappingStats mapping = odometry.mapping();
  // Plane purity: per frame, each plane's members (if 4 or more) by the true surface at their keyframe pixel
  // (coplanar polygons share a surface; non-planar objects and the sky count as one other); the share of them
  // on their plane's most common surface.
  std::map<int, pdvo::sim::RenderedFrame> geometry;  // by keyframe: the true depths and ids
  auto geometry_of = [&](int keyframe) -> const pdvo::sim::RenderedFrame& {
    pdvo::sim::RenderedFrame& g = geometry[keyframe];
    if (g.id.empty()) renderer.RenderGeometry(walk.at(keyframe).world_from_cam, &g);
    return g;
  };
  pdvo::PlanePurity purity;
  // Per mapped plane (segment, id): the true planes under its points, and its points (keyframe and pixel).
  std::map<std::pair<int, int>, std::map<int, int>> true_planes;
  std::map<std::pair<int, int>, std::set<std::array<int, 3>>> plane_pixels;
  for (const Member& m : members) {
    const cv::Mat& id = geometry_of(m.keyframe).id;
    const int at = id.at<int>(cvRound(m.keyframe_pixel.y()), cvRound(m.keyframe_pixel.x()));
    purity.Add(m.frame, m.plane, at >= 0 ? street.planes.at(at).surface : -1);
    ++true_planes[{m.segment, m.plane}][at];
    plane_pixels[{m.segment, m.plane}].insert(
        {m.keyframe, cvRound(m.keyframe_pixel.x()), cvRound(m.keyframe_pixel.y())});
  }
  // Where the points off their plane's main surface lie (the purity's complement): on non-planar things or the
  // sky, on another surface of the same orientation (within 10 degrees: the next facade), on a surface at another
  // angle (a wall round a corner, the ground), or on a surface while their plane lies mostly on non-planar things;
  // and how many are within 2% of their depth of the main surface (near the crease where two surfaces meet, no
  // test of depth can tell them apart).
  std::array<long, 4> off_kind{};  // non-planar, parallel, angled, in a non-planar plane
  long off_near = 0;
  for (const Member& m : members) {
    const std::optional<int> main = purity.MainLabel(m.frame, m.plane, 4);
    if (!main) continue;
    const pdvo::sim::RenderedFrame& g = geometry_of(m.keyframe);
    const cv::Point at(cvRound(m.keyframe_pixel.x()), cvRound(m.keyframe_pixel.y()));
    const int id = g.id.at<int>(at);
    if ((id >= 0 ? street.planes.at(id).surface : -1) == *main) continue;
    if (*main < 0) {
      ++off_kind[3];
      continue;
    }
    const pdvo::sim::WorldPlane& surface = street.planes.at(*main);
    const bool parallel = id >= 0 && surface.normal.dot(street.planes.at(id).normal) > std::cos(10 * M_PI / 180);
    ++off_kind[id < 0 ? 0 : parallel ? 1 : 2];
    const float z = g.depth.at<float>(at);
    if (!(z > 0)) continue;
    const Eigen::Vector3d world = walk.at(m.keyframe).world_from_cam * (camera.Unproject(m.keyframe_pixel) * z);
    off_near += std::abs(surface.normal.dot(world) + surface.distance) < 0.02 * z;
  }
  // Normal error: each plane of min_plane_points or more against the true plane under most of its points, in the
  // camera frame of the keyframe it was last in (the estimated keyframe orientation's error is part of it).
  std::vector<double> normal_errors;
  std::set<int> surfaces_mapped;  // the true surfaces that are some such plane's main one
  for (const auto& [key, votes] : true_planes) {
    if (static_cast<int>(plane_pixels[key].size()) < vo_options.planes.min_plane_points || !normals.count(key)) {
      continue;
    }
    const auto main =
        std::max_element(votes.begin(), votes.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    if (main->first < 0) continue;
    surfaces_mapped.insert(street.planes.at(main->first).surface);
    const LastNormal& last = normals.at(key);
    const Eigen::Vector3d truth =
        walk.at(last.keyframe).world_from_cam.rotation.conjugate() * street.planes.at(main->first).normal;
    const double c = std::min(1.0, std::abs(truth.normalized().dot(last.normal)));
    normal_errors.push_back(std::acos(c) * 180 / M_PI);
  }
  std::sort(normal_errors.begin(), normal_errors.end());
  // Match accuracy: where each match should have been, the true point under its keyframe pixel (the rendered
  // depth there) seen from the frame's true pose; the share of the used matches within 1.5 px of it and beyond
  // 6 px, and of the rejected ones within 1.5 px. Matches of the sky (no depth) are left out.
  constexpr double kTrueMatch = 1.5, kGrossMatch = 6;
  long used = 0, used_true = 0, used_gross = 0, rejected = 0, rejected_true = 0;
  std::vector<double> used_errors;  // px
  // Searches by the feature's age (frames since its keyframe): how many found it, and of those that did not and
  // have a truth, how many were predicted within kNearMiss px of it or beyond the largest search window.
  constexpr double kNearMiss = 3;
  const std::array<int, 5> age_bounds = {1, 2, 5, 10, std::numeric_limits<int>::max()};  // upper bounds
  std::array<long, 5> searched{}, found{}, missed{}, missed_near{}, missed_far{};
  // Keyframe pixels are the working camera's: measured only where they are the renderer's.
  const bool same_pixels = working.width == camera.width && working.height == camera.height;
  if (same_pixels) {
    for (const Match& m : matches) {
      const size_t age =
          std::lower_bound(age_bounds.begin(), age_bounds.end(), m.frame - m.keyframe) - age_bounds.begin();
      ++searched[age];
      found[age] += m.found;
      const float z =
          geometry_of(m.keyframe).depth.at<float>(cvRound(m.keyframe_pixel.y()), cvRound(m.keyframe_pixel.x()));
      if (!(z > 0)) continue;
      const Eigen::Vector3d world = walk.at(m.keyframe).world_from_cam * (camera.Unproject(m.keyframe_pixel) * z);
      const Eigen::Vector3d seen = walk.at(m.frame).world_from_cam.Inverse() * world;
      if (seen.z() <= 0) continue;
      const double error = (camera.Project(seen) - m.pixel).norm();
      if (!m.found) {
        ++missed[age];
        missed_near[age] += error < kNearMiss;
        missed_far[age] += error > vo_options.search.max_search_radius;
      } else if (m.used) {
        ++used;
        used_errors.push_back(error);
        used_true += error < kTrueMatch;
        used_gross += error > kGrossMatch;
      } else {
        ++rejected;
        rejected_true += error < kTrueMatch;
      }
    }
  }
  std::sort(used_errors.begin(), used_errors.end());
  const double median_error = used > 0 ? used_errors[used_errors.size() / 2] : -1;
  const double true_share = used > 0 ? static_cast<double>(used_true) / used : -1;
  const double gross_share = used > 0 ? static_cast<double>(used_gross) / used : -1;
  // The mean plane's measurements by frames since its keyframe, over the planes of min_plane_points or more.
  const std::vector<double> curve = measured_after.Mean();
  long plane_members = 0;
  const double pure = purity.Share(4, &plane_members);
  std::printf("vo_bench: %d frames 320x240, seed %llu, mode %s, path %.1f m\n", frames,
              static_cast<unsigned long long>(seed), pdvo::OptionName(vo_options.mode).c_str(), path);
  std::printf("  tracking         %.1f frames/s (one thread; target >= 200); tracking thread's CPU %.1f frames/s\n",
              frames / seconds, frames / cpu_seconds);
  std::printf("  ATE (Sim3)       rmse %.3f m = %.2f%% of the path (target <= 1%%), max %.3f m\n", ate.translation.rmse,
              100 * ate.translation.rmse / path, ate.translation.max);
  std::printf(
      "  NEES orientation mean %.2f (chi-square(3): 3), %.1f%% of frames inside the 95%% bound (7.81); "
      "relative to the newest keyframe %.2f\n",
      nees_sum / std::max(1, nees_frames), 100.0 * nees_inside / std::max(1, nees_frames),
      relative_nees_sum / std::max(1, nees_frames));
  std::printf(
      "  measurements     %.1f per frame; %d keyframes; lost %d times, %d frames uncertain; two-view "
      "bootstrap at frame %d\n",
      measurements / frames, keyframes, lost, uncertain, bootstrap);
  if (used > 0) {
    std::printf(
        "  match accuracy   %.1f%% of the matches used within %.1f px of the truth, %.1f%% beyond %.0f px, median "
        "error %.2f px; %.1f%% of the %ld rejected within %.1f px\n",
        100 * true_share, kTrueMatch, 100 * gross_share, kGrossMatch, median_error,
        rejected > 0 ? 100.0 * rejected_true / rejected : 0.0, rejected, kTrueMatch);
  } else {
    std::printf("  match accuracy   not measured (no matches, or working pixels that are not the renderer's)\n");
  }
  if (same_pixels) {
    auto row = [&](const char* name, const std::array<long, 5>& count, const std::array<long, 5>& of) {
      std::printf("    %-24s", name);
      for (size_t k = 0; k < count.size(); ++k) std::printf(" %5.1f%%", of[k] > 0 ? 100.0 * count[k] / of[k] : 0.0);
      std::printf("\n");
    };
    std::printf("  searches by age  frames since the feature's keyframe:  1      2    3-5   6-10    11+\n");
    row("found", found, searched);
    char near_name[32];
    std::snprintf(near_name, sizeof near_name, "missed, within %.0f px", kNearMiss);
    row(near_name, missed_near, missed);
    row("missed, beyond window", missed_far, missed);
  }
  if (plane_members > 0) {
    std::printf("  plane purity     %.2f of the points of planes on their plane's main true surface\n", pure);
    std::printf(
        "  off the surface  %ld of the points: %ld on non-planar things, %ld on a surface of the same orientation, "
        "%ld at another angle, %ld in planes mostly on non-planar things; %ld of the first three within 2%% of their "
        "depth of the plane's surface\n",
        off_kind[0] + off_kind[1] + off_kind[2] + off_kind[3], off_kind[0], off_kind[1], off_kind[2], off_kind[3],
        off_near);
  }
  std::printf("  planes           %d made, %.1f points per plane, mean area %.0f px\n", mapping.planes,
              mapping.points_per_plane, mapping.mean_plane_area);
  if (!normal_errors.empty()) {
    std::printf("  plane normals    median error %.1f deg over %zu planes, on %zu true surfaces\n",
                normal_errors[normal_errors.size() / 2], normal_errors.size(), surfaces_mapped.size());
  }
  if (pdvo_mode) {
    const pdvo::vo::Odometry::DetectionCounts counts = odometry.detection_counts();
    std::printf(
        "  detections       source %s: %d planes detected, %d seeded, %d extended older planes; %d keyframes "
        "dropped (left the filter), %d skipped, %d timed out, %d failed\n",
        source.c_str(), detected, seeded, extended, dropped, counts.skipped, counts.timed_out, counts.failed);
  }
  // One line for scripts (bench/pdvo_compare.sh): key=value, lists comma-separated.
  auto share = [&](long count) { return plane_members > 0 ? static_cast<double>(count) / plane_members : -1.0; };
  std::printf(
      "result seed=%llu mode=%s source=%s ate_percent=%.4f tracking_fps=%.1f planes=%d points_per_plane=%.2f "
      "mean_area=%.0f purity=%.4f normal_median=%.2f normal_planes=%zu surfaces=%zu seeded=%d matches_true=%.4f "
      "matches_gross=%.4f match_median_px=%.3f found_after_one_frame=%.4f off_nonplanar=%.4f off_parallel=%.4f "
      "off_angled=%.4f off_nonplanar_planes=%.4f curve=",
      static_cast<unsigned long long>(seed), pdvo::OptionName(vo_options.mode).c_str(),
      pdvo_mode ? source.c_str() : "none", 100 * ate.translation.rmse / path, frames / cpu_seconds, mapping.planes,
      mapping.points_per_plane, mapping.mean_plane_area, plane_members > 0 ? pure : -1.0,
      normal_errors.empty() ? -1.0 : normal_errors[normal_errors.size() / 2], normal_errors.size(),
      surfaces_mapped.size(), seeded, true_share, gross_share, median_error,
      searched[0] > 0 ? static_cast<double>(found[0]) / searched[0] : -1.0, share(off_kind[0]), share(off_kind[1]),
      share(off_kind[2]), share(off_kind[3]));
  for (int a = 0; a < kCurveFrames; ++a) std::printf("%s%.2f", a ? "," : "", curve[a]);
  std::printf(" fps_by_100_frames=");
  for (size_t w = 0; w * 100 < frame_cpu.size(); ++w) {
    double t = 0;
    size_t n = 0;
    for (size_t k = w * 100; k < std::min(frame_cpu.size(), (w + 1) * 100); ++k, ++n) t += frame_cpu[k];
    std::printf("%s%.1f", w ? "," : "", n / std::max(t, 1e-9));
  }
  std::printf("\n");
  std::printf(
      "  memory           %.1f MiB resident with the frames and records, tracking added %.1f MiB (peak %.1f MiB)\n",
      before, peak - before, peak);
  return 0;
}
