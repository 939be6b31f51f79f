// pdvo report: one self-contained HTML page of `pdvo vo` runs: Table I, the speed over time, a plane's
// measurements after its keyframe, the trajectory from above, detections and the odometry's view, and the planar
// map in 3D. The page (apps/report/page.html) is built into the binary; three.js and Chart.js come from Debian's
// libjs-three and libjs-chart.js and are inlined, so that the file opens offline.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/eval/trajectory_error.h"
#include "pdvo/vo/map.h"
#include "tool.h"

namespace pdvo::apps {

extern const char* const kReportPage;  // report_page.cpp, generated from report/page.html

namespace {

namespace fs = std::filesystem;

// Frames over which the frames-per-second timeline is averaged.
constexpr int kFpsWindow = 30;

std::string Base64(const std::string& bytes) {
  static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

nlohmann::json Xyz(const Eigen::Vector3d& x) { return {x.x(), x.y(), x.z()}; }

// Up to `count` of the .jpg files in `folder`, evenly spaced in name order, as data URLs with their frame.
nlohmann::json Pictures(const fs::path& folder, size_t count) {
  std::vector<fs::path> files;
  if (fs::is_directory(folder)) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string stem = entry.path().stem().string();
      const bool numbered = !stem.empty() && std::all_of(stem.begin(), stem.end(), ::isdigit);
      if (entry.path().extension() == ".jpg" && numbered) files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  nlohmann::json out = nlohmann::json::array();
  for (size_t k = 0; k < std::min(count, files.size()); ++k) {
    const fs::path& f = files[count >= files.size() ? k : k * (files.size() - 1) / std::max<size_t>(1, count - 1)];
    out.push_back(
        {{"frame", std::stoi(f.stem().string())}, {"src", "data:image/jpeg;base64," + Base64(ReadFile(f.string()))}});
  }
  return out;
}

// JSON of a number that may be NaN (no value): null.
nlohmann::json Value(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

struct Run {
  std::string name, dir;
  nlohmann::json stats;
  Trajectory trajectory;
};

// One run as the page shows it; `gt` may be empty. Positions are in the ground truth's frame when there is one.
nlohmann::json RunJson(const Run& run, const Trajectory& gt, size_t pictures) {
  const nlohmann::json& totals = run.stats.at("totals");
  nlohmann::json table = {{"frames", totals.at("frames")},
                          {"keyframes", totals.at("keyframes")},
                          {"lost", totals.at("lost")},
                          {"planes", totals.at("planes")},
                          {"points_per_plane", totals.at("points_per_plane")},
                          {"mean_plane_area_px", totals.at("mean_plane_area_px")},
                          {"fps", totals.at("fps")}};
  Sim3d gt_from_estimate;
  if (!gt.empty()) {
    const AteResult ate = ComputeAte(gt, run.trajectory, Alignment::kSim3, 0.02);
    gt_from_estimate = ate.gt_from_estimate;
    table["ate_m"] = ate.translation.rmse;
    table["ate_percent"] = 100 * ate.translation.rmse / std::max(PathLength(gt), 1e-12);
    table["rotation_deg"] = ate.rotation_deg.rmse;
  }
  std::vector<double> latency_frames, latency_seconds;
  if (run.stats.contains("detections")) {
    for (const nlohmann::json& d : run.stats.at("detections")) {
      latency_frames.push_back(d.at("latency_frames").get<double>());
      latency_seconds.push_back(d.at("latency_seconds").get<double>());
    }
    const nlohmann::json& counts = totals.at("detections");
    table["planes_detected"] = counts.at("planes_detected");
    table["planes_seeded"] = counts.at("planes_seeded");
    table["latency_frames"] = Value(Median(latency_frames));
    table["latency_seconds"] = Value(Median(latency_seconds));
  }
  // The frame rate, averaged over kFpsWindow frames.
  nlohmann::json fps = nlohmann::json::array();
  const nlohmann::json& frames = run.stats.at("frames");
  double window = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    window += frames[k].at("seconds").get<double>();
    if (k >= kFpsWindow) window -= frames[k - kFpsWindow].at("seconds").get<double>();
    const size_t n = std::min<size_t>(k + 1, kFpsWindow);
    if (k % 5 == 0 || k + 1 == frames.size()) fps.push_back({k, n / std::max(window, 1e-9)});
  }
  nlohmann::json path = nlohmann::json::array(), points = nlohmann::json::array(), planes = nlohmann::json::array();
  for (const StampedPose& p : run.trajectory) path.push_back(Xyz(gt_from_estimate * p.world_from_cam.translation));
  std::vector<Eigen::Vector3d> ply_path;
  const vo::Map map = vo::ReadPly((fs::path(run.dir) / "map.ply").string(), &ply_path);
  for (const Eigen::Vector3d& x : map.points) points.push_back(Xyz(gt_from_estimate * x));
  for (const vo::MapPlane& p : map.planes) {
    nlohmann::json polygon = nlohmann::json::array();
    for (const Eigen::Vector3d& x : p.polygon) polygon.push_back(Xyz(gt_from_estimate * x));
    planes.push_back({{"polygon", polygon}, {"normal", Xyz(gt_from_estimate.rotation * p.normal)}});
  }
  return {{"name", run.name},
          {"dir", run.dir},
          {"mode", run.stats.value("mode", "")},
          {"table", table},
          {"fps", fps},
          {"plane_measurements_after_keyframe", run.stats.value("plane_measurements_after_keyframe", nlohmann::json())},
          {"path", path},
          {"points", points},
          {"planes", planes},
          {"stages", Pictures(fs::path(run.dir) / "stages", pictures)},
          {"views", Pictures(fs::path(run.dir) / "views", pictures)}};
}

// The camera's up direction in the world, averaged over a trajectory (cameras look along +z with y down).
Eigen::Vector3d Up(const Trajectory& t) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const StampedPose& p : t) up += p.world_from_cam.rotation * Eigen::Vector3d(0, -1, 0);
  return up.norm() > 0 ? up.normalized() : Eigen::Vector3d(0, -1, 0);
}

std::string Replace(std::string text, const std::string& marker, const std::string& with) {
  const size_t at = text.find(marker);
  PDVO_THROW_CHECK(at != std::string::npos, Error, "report page: no " << marker);
  return text.replace(at, marker.size(), with);
}

// A script's text as it may stand inside <script>: "</script" (any case) cannot end the element early; in the
// strings of JavaScript and JSON, where alone it can occur, "<\/" means the same.
std::string ScriptSafe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t k = 0; k < text.size(); ++k) {
    out.push_back(text[k]);
    if (text[k] == '<' && text.compare(k + 1, 1, "/") == 0 && k + 8 <= text.size()) {
      std::string tag = text.substr(k + 2, 6);
      std::transform(tag.begin(), tag.end(), tag.begin(), ::tolower);
      if (tag == "script") out.push_back('\\');
    }
  }
  return out;
}

}  // namespace

int RunReport(int argc, char** argv) {
  CLI::App app(
      "Writes one self-contained HTML page (no network needed to open it) of one or more pdvo vo output "
      "folders: Table I side by side (planes, points per plane, area; ATE and rotation error after Sim(3) "
      "alignment where there is ground truth; tracking frames/s; detector latency), the frame rate over time "
      "(Fig. 10), a plane's measurements after its keyframe (Fig. 4), the trajectory from above, the "
      "detector's stages and the odometry's view on a few keyframes (with vo --overlay), and the planar map in "
      "3D. Uses Debian's libjs-three and libjs-chart.js.",
      "pdvo report");
  std::vector<std::string> dirs, names;
  std::string out_path, gt_path, format_name = "tum", title = "pdvo", js_dir = "/usr/share/javascript";
  std::string verbosity = "info";
  size_t pictures = 4;
  app.add_option("runs", dirs, "Output folders of pdvo vo")->required();
  app.add_option("--out,-o", out_path, "The HTML file to write")->required();
  app.add_option("--gt", gt_path,
                 "Ground-truth trajectory (default: groundtruth.txt of the sequence the first run's stats.json "
                 "names, if it has one)");
  app.add_option("--format", format_name, "Trajectory format of the runs and --gt: tum or kitti")
      ->capture_default_str();
  app.add_option("--name", names, "A name per run (default: the folder's name)");
  app.add_option("--title", title, "The page's title")->capture_default_str();
  app.add_option("--pictures", pictures, "Keyframes shown per run (detections and views)")->capture_default_str();
  app.add_option("--js-dir", js_dir, "Where libjs-three and libjs-chart.js are")->capture_default_str();
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  PDVO_THROW_CHECK(names.empty() || names.size() == dirs.size(), InvalidArgument,
                   "--name: give one per run (" << dirs.size() << " runs, " << names.size() << " names)");
  const TrajectoryFormat format = ParseTrajectoryFormat(format_name);
  const std::string three = ReadFile((fs::path(js_dir) / "three/three.min.js").string());
  const std::string chart = ReadFile((fs::path(js_dir) / "chart.js/chart.min.js").string());

  std::vector<Run> runs;
  for (size_t i = 0; i < dirs.size(); ++i) {
    Run& r = runs.emplace_back();
    r.dir = dirs[i];
    r.name = names.empty() ? fs::path(dirs[i]).lexically_normal().filename().string() : names[i];
    if (r.name.empty()) r.name = fs::path(dirs[i]).lexically_normal().parent_path().filename().string();
    const std::string stats = (fs::path(dirs[i]) / "stats.json").string();
    try {
      r.stats = nlohmann::json::parse(ReadFile(stats));
    } catch (const nlohmann::json::exception& e) {
      PDVO_THROW(FormatError, stats << ": " << e.what());
    }
    PDVO_THROW_CHECK(r.stats.is_object() && r.stats.contains("totals") && r.stats.contains("frames"), FormatError,
                     stats << ": not the statistics of pdvo vo (no totals or frames)");
    r.trajectory = ReadTrajectory((fs::path(dirs[i]) / "trajectory.txt").string(), format);
  }
  if (gt_path.empty() && runs[0].stats.contains("sequence")) {
    const fs::path candidate = fs::path(runs[0].stats["sequence"].get<std::string>()) / "groundtruth.txt";
    if (fs::is_regular_file(candidate)) gt_path = candidate.string();
  }
  const Trajectory gt = gt_path.empty() ? Trajectory() : ReadTrajectory(gt_path, format);
  nlohmann::json page = {{"title", title}, {"runs", nlohmann::json::array()}, {"gt", gt_path}};
  for (const Run& r : runs) {
    try {
      page["runs"].push_back(RunJson(r, gt, pictures));
    } catch (const nlohmann::json::exception& e) {
      PDVO_THROW(FormatError, (fs::path(r.dir) / "stats.json").string() << ": not as pdvo vo writes it: " << e.what());
    }
  }
  nlohmann::json gt_path_json = nlohmann::json::array();
  for (const StampedPose& p : gt) gt_path_json.push_back(Xyz(p.world_from_cam.translation));
  page["gt_path"] = gt_path_json;
  page["up"] = Xyz(Up(gt.empty() ? runs[0].trajectory : gt));

  std::string html = Replace(kReportPage, "/*PDVO:THREE*/", ScriptSafe(three));
  html = Replace(html, "/*PDVO:CHART*/", ScriptSafe(chart));
  html = Replace(html, "/*PDVO:DATA*/", ScriptSafe(page.dump()));
  WriteFileAtomically(out_path, html);
  for (const nlohmann::json& r : page["runs"]) {
    const nlohmann::json& t = r["table"];
    std::printf("%-12s %5d planes, %.2f points per plane, mean area %.0f px, tracking %.0f frames/s",
                r.value("name", "").c_str(), t["planes"].get<int>(), t["points_per_plane"].get<double>(),
                t["mean_plane_area_px"].get<double>(), t["fps"].get<double>());
    if (t.contains("ate_m")) {
      std::printf(", ATE %.3f m (%.2f%% of the path), rotation %.2f deg", t["ate_m"].get<double>(),
                  t["ate_percent"].get<double>(), t["rotation_deg"].get<double>());
    }
    std::printf("\n");
  }
  std::printf("wrote %s (%.1f MB)\n", out_path.c_str(), html.size() / 1e6);
  return 0;
}

}  // namespace pdvo::apps
