// pdvo ate: absolute trajectory error after alignment, and relative pose error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/eval/trajectory_error.h"
#include "tool.h"

namespace pdvo::apps {
namespace {

// The poses of `est` that pdvo vo's statistics (`stats_path`, its stats.json) call tracked, in the segment with
// the most of them (poses of different segments share no frame of reference). Prints what it left out.
Trajectory TrustedPoses(const Trajectory& est, const std::string& est_path, const std::string& stats_path) {
  nlohmann::json stats;
  try {
    stats = nlohmann::json::parse(ReadFile(stats_path));
  } catch (const nlohmann::json::exception& e) {
    PDVO_THROW(FormatError, stats_path << ": " << e.what());
  }
  PDVO_THROW_CHECK(stats.is_object() && stats.contains("frames") && stats["frames"].is_array(), FormatError,
                   stats_path << ": not the statistics of pdvo vo (no frames)");
  const nlohmann::json& frames = stats["frames"];
  PDVO_THROW_CHECK(
      frames.size() == est.size(), FormatError,
      stats_path << ": " << frames.size() << " frames, but " << est_path << " has " << est.size() << " poses");
  std::map<int, Trajectory> tracked;  // per segment
  size_t untrusted = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    const nlohmann::json& f = frames[i];
    PDVO_THROW_CHECK(f.is_object() && f.contains("t") && f["t"].is_number() && f.contains("health") &&
                         f["health"].is_string() && f.contains("segment") && f["segment"].is_number_integer(),
                     FormatError, stats_path << ": frame " << i << " has no t, health or segment");
    PDVO_THROW_CHECK(std::abs(f["t"].get<double>() - est[i].timestamp) < 1e-4, FormatError,
                     stats_path << ": frame " << i << " is at t " << f["t"].get<double>() << ", " << est_path << " at "
                                << est[i].timestamp);
    if (f["health"] == "tracked") {
      tracked[f["segment"].get<int>()].push_back(est[i]);
    } else {
      ++untrusted;
    }
  }
  PDVO_THROW_CHECK(!tracked.empty(), FormatError, stats_path << ": no pose is tracked: nothing to compare");
  const auto best = std::max_element(tracked.begin(), tracked.end(),
                                     [](const auto& a, const auto& b) { return a.second.size() < b.second.size(); });
  std::printf(
      "trusted poses   %zu of %zu: segment %d (of %zu with tracked poses); left out %zu uncertain or lost, %zu tracked "
      "in other "
      "segments\n",
      best->second.size(), est.size(), best->first, tracked.size(), untrusted,
      est.size() - untrusted - best->second.size());
  return best->second;
}

}  // namespace

int RunAte(int argc, char** argv) {
  CLI::App app(
      "Compares an estimated trajectory with ground truth: poses are associated by timestamp, the "
      "estimate is aligned (se3: rigid; sim3: with scale, for monocular runs; none), and the absolute "
      "trajectory error (ATE) and the relative pose error (RPE) are reported. The ATE's rotation part "
      "compares the orientations after the rotation that best aligns them (the positions alone hardly "
      "fix the rotation about a straight path).",
      "pdvo ate");
  std::string gt_path, est_path, format_name = "tum", est_format_name, align_name = "sim3", gt_times, est_times,
                                 json_path;
  std::string rpe_unit = "frames", verbosity = "info", health_path;
  double max_dt = 0.02, rpe_delta = 1;
  app.add_option("--gt", gt_path, "Ground-truth trajectory")->required();
  app.add_option("--est", est_path, "Estimated trajectory")->required();
  app.add_option("--format", format_name, "Trajectory format: tum (t tx ty tz qx qy qz qw) or kitti (3x4 rows)")
      ->capture_default_str();
  app.add_option("--est-format", est_format_name,
                 "Format of the estimate, if not --format's (e.g. pdvo vo's tum against KITTI poses)");
  app.add_option("--align", align_name, "Alignment: se3, sim3 or none")->capture_default_str();
  app.add_option("--max-dt", max_dt, "Largest time difference of associated poses, seconds")->capture_default_str();
  app.add_option("--gt-times", gt_times, "KITTI: times file of the ground truth (default: pose index)");
  app.add_option("--est-times", est_times, "KITTI: times file of the estimate (default: pose index)");
  app.add_option("--rpe-delta", rpe_delta, "RPE: distance between compared poses")->capture_default_str();
  app.add_option("--rpe-unit", rpe_unit, "RPE: delta in frames or seconds")->capture_default_str();
  app.add_option("--json", json_path, "Write the results as JSON");
  app.add_option("--health", health_path,
                 "pdvo vo's stats.json: compare only the poses it calls tracked, in its longest segment");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  PDVO_THROW_CHECK(rpe_unit == "frames" || rpe_unit == "seconds", InvalidArgument,
                   "--rpe-unit must be frames or seconds, got '" << rpe_unit << "'");

  const TrajectoryFormat format = ParseTrajectoryFormat(format_name);
  const Alignment alignment = ParseAlignment(align_name);
  const Trajectory gt = ReadTrajectory(gt_path, format, gt_times);
  Trajectory est =
      ReadTrajectory(est_path, est_format_name.empty() ? format : ParseTrajectoryFormat(est_format_name), est_times);
  if (!health_path.empty()) est = TrustedPoses(est, est_path, health_path);
  // The library's complaints about the data (too few matches, positions that do not move) are data errors here,
  // named by the two files.
  AteResult ate;
  try {
    ate = ComputeAte(gt, est, alignment, max_dt);
  } catch (const InvalidArgument& e) {
    PDVO_THROW(FormatError, est_path << " against " << gt_path << ": " << e.what());
  }
  PDVO_THROW_CHECK(std::isfinite(ate.translation.rmse) && std::isfinite(ate.rotation_deg.rmse) &&
                       std::isfinite(ate.gt_from_estimate.scale),
                   FormatError,
                   est_path << ": the alignment to " << gt_path
                            << " is undefined (positions that do not spread out, or not finite): no ATE");
  const RpeResult rpe =
      ComputeRpe(gt, est, max_dt, rpe_delta, rpe_unit == "frames" ? RpeUnit::kFrames : RpeUnit::kSeconds,
                 ate.gt_from_estimate.scale);
  std::printf("matched poses   %zu of %zu (ground truth %zu)\n", ate.matched, est.size(), gt.size());
  std::printf("alignment       %s, scale %.6f\n", align_name.c_str(), ate.gt_from_estimate.scale);
  std::printf("ATE translation rmse %.6f  mean %.6f  median %.6f  max %.6f\n", ate.translation.rmse,
              ate.translation.mean, ate.translation.median, ate.translation.max);
  std::printf("ATE rotation    rmse %.4f  mean %.4f  median %.4f  max %.4f deg\n", ate.rotation_deg.rmse,
              ate.rotation_deg.mean, ate.rotation_deg.median, ate.rotation_deg.max);
  std::printf("RPE (%g %s, %zu pairs) translation rmse %.6f, rotation rmse %.4f deg\n", rpe_delta, rpe_unit.c_str(),
              rpe.pairs, rpe.translation.rmse, rpe.rotation_deg.rmse);
  if (!json_path.empty()) {
    nlohmann::json j = {{"gt", gt_path},    {"est", est_path},    {"align", align_name},
                        {"max_dt", max_dt}, {"ate", ToJson(ate)}, {"rpe", ToJson(rpe)}};
    WriteFileAtomically(json_path, j.dump(1) + "\n");
  }
  return 0;
}

}  // namespace pdvo::apps
