// pdvo vo: monocular visual odometry (the IDPP EKF: inverse-depth points and planes) over a sequence, with the
// plane detector's planes as priors in mode pdvo.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "pdvo/common/dataset.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/odometry.h"
#include "plane_sources.h"
#include "tool.h"

namespace pdvo::apps {
namespace {

// stats.json's plane_measurements_after_keyframe: frames 0 .. kCurveFrames - 1 after a plane's keyframe.
constexpr int kCurveFrames = 60;

std::string FrameName(size_t frame) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06zu", frame);
  return name;
}

cv::Scalar PlaneColour(int id) {
  return cv::Scalar(60 + (id * 67) % 196, 60 + (id * 131) % 196, 60 + (id * 199) % 196);
}

std::vector<cv::Point> Pixels(const std::vector<Eigen::Vector2d>& polygon) {
  std::vector<cv::Point> out;
  for (const Eigen::Vector2d& q : polygon) out.emplace_back(cvRound(q.x()), cvRound(q.y()));
  return out;
}

// The frame with its features: points green, plane points in a colour per plane; filled where the update used
// the match, hollow where the search failed, red where RANSAC rejected the match. Each plane's region (its
// points' hull, carried through the plane) tinted in its colour, and a detected plane's polygon in yellow.
cv::Mat DrawOverlay(const cv::Mat& colour, const std::vector<vo::Observation>& observations, const vo::FrameStats& s,
                    const std::vector<vo::Odometry::PlaneOutline>& planes) {
  cv::Mat out = colour.clone(), tint = colour.clone();
  for (const vo::Odometry::PlaneOutline& p : planes) {
    if (p.region.size() >= 3) cv::fillConvexPoly(tint, Pixels(p.region), PlaneColour(p.id), cv::LINE_AA);
  }
  cv::addWeighted(out, 0.6, tint, 0.4, 0, out);
  for (const vo::Odometry::PlaneOutline& p : planes) {
    if (p.region.size() >= 3) cv::polylines(out, {Pixels(p.region)}, true, PlaneColour(p.id), 1, cv::LINE_AA);
    if (p.detected.size() >= 3) cv::polylines(out, {Pixels(p.detected)}, true, cv::Scalar(0, 220, 255), 1, cv::LINE_AA);
  }
  for (const vo::Observation& o : observations) {
    const cv::Scalar c = o.matched && !o.used ? cv::Scalar(0, 0, 255)
                         : o.plane < 0        ? cv::Scalar(0, 220, 0)
                                              : PlaneColour(o.plane);
    cv::circle(out, cv::Point(cvRound(o.pixel.x()), cvRound(o.pixel.y())), 3, c, o.used ? cv::FILLED : 1, cv::LINE_AA);
  }
  char text[128];
  std::snprintf(text, sizeof(text), "t %.2f  %d/%d matched  %d points  %d planes%s", s.timestamp, s.measurements,
                s.attempted, s.points, s.planes,
                s.health == vo::Health::kTracked ? ""
                : s.lost                         ? "  LOST"
                                                 : "  UNCERTAIN");
  cv::putText(out, text, cv::Point(4, 12), cv::FONT_HERSHEY_PLAIN, 0.8, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

// A keyframe's detections in stats.json.
nlohmann::json DetectionJson(const vo::DetectionEvent& e, double now) {
  const vo::SeedingOutcome& o = e.seeding;
  nlohmann::json j = {{"keyframe", e.result.keyframe},
                      {"started", e.result.started},
                      {"applied", e.result.delivered},
                      {"latency_frames", e.result.delivered - e.result.keyframe},
                      {"latency_seconds", now - e.result.keyframe_time},
                      {"detector_seconds", e.result.seconds},
                      {"detected", e.result.planes.size()},
                      {"seeded", o.seeded},
                      {"extended", o.extended},
                      {"discarded",
                       {{"small", o.small},
                        {"too_many", o.too_many},
                        {"near_plane", o.near_plane},
                        {"mapped", o.mapped},
                        {"no_corner", o.no_corner},
                        {"grazing", o.grazing},
                        {"invalid", o.invalid}}},
                      {"keyframe_gone", e.keyframe_gone}};
  if (!e.result.error.empty()) j["error"] = e.result.error;
  return j;
}

// stats.json, written as the frames go (a line per frame; the keyframes' detections wait in a file beside it until
// the end), so that memory does not grow with the number of frames. Readers see one ordinary JSON object.
class StatsFile {
 public:
  // `path`: where to write (in the staging folder); `shown`: the name errors give. `head`: the first keys.
  StatsFile(std::string path, std::string shown, const nlohmann::json& head)
      : path_(std::move(path)), shown_(std::move(shown)), out_(path_), detections_(path_ + ".detections") {
    PDVO_THROW_CHECK(out_ && detections_, IoError, shown_ << ": cannot write");
    out_ << "{";
    for (const auto& [key, value] : head.items())
      out_ << "\n " << nlohmann::json(key).dump() << ": " << value.dump() << ",";
    out_ << "\n \"frames\": [";
  }
  void AddFrame(const nlohmann::json& frame) { out_ << (frames_++ > 0 ? ",\n  " : "\n  ") << frame.dump(); }
  void AddDetection(const nlohmann::json& detection) {
    detections_ << (detections_written_++ > 0 ? ",\n  " : "\n  ") << detection.dump();
  }
  // Ends the file: the detections (if `with_detections`), then `tail`'s keys.
  void Finish(const nlohmann::json& tail, bool with_detections) {
    out_ << "\n ]";
    detections_.close();
    PDVO_THROW_CHECK(detections_, IoError, shown_ << ": cannot write");
    if (with_detections) {
      out_ << ",\n \"detections\": [";
      if (detections_written_ > 0) out_ << std::ifstream(path_ + ".detections").rdbuf();
      out_ << "\n ]";
    }
    std::filesystem::remove(path_ + ".detections");
    for (const auto& [key, value] : tail.items()) {
      out_ << ",\n " << nlohmann::json(key).dump() << ": ";
      for (const char c : value.dump(1)) out_ << c << (c == '\n' ? " " : "");  // indented one level
    }
    out_ << "\n}\n";
    out_.close();
    PDVO_THROW_CHECK(out_, IoError, shown_ << ": cannot write (disk full?)");
  }

 private:
  std::string path_, shown_;
  std::ofstream out_, detections_;
  size_t frames_ = 0, detections_written_ = 0;
};

}  // namespace

int RunVo(int argc, char** argv) {
  CLI::App app(
      "Monocular visual odometry: an EKF with inverse-depth points and planes anchored at keyframes "
      "(the IDPP system with --mode idpp; points only by default). Frames are undistorted and resized to "
      "the working width. Writes trajectory.txt (world_from_cam per frame), stats.json (per frame and "
      "totals), map.ply (points, planes as polygons, the camera path) and vo.yaml (the options used) to "
      "the output folder. All options: vo/config/default.yaml.",
      "pdvo vo");
  std::string sequence_path, camera_path, out_dir, config_path, format_name = "tum", mode, verbosity = "info";
  std::vector<std::string> overrides;
  size_t max_frames = 0;
  bool overlay = false;
  app.add_option("--sequence,-s", sequence_path, "Image folder, video, TUM or KITTI folder, or pdvo synth output")
      ->required();
  app.add_option("--camera,-c", camera_path, "Camera YAML (default: the sequence's own)");
  app.add_option("--out,-o", out_dir, "Output folder")->required();
  app.add_option("--mode", mode,
                 "pdvo (planes where the detector finds them), idpp (planes where corners are densest) or points "
                 "(default: pdvo if the model file is there and no --config or --set says otherwise, else points)");
  std::string model_path = "models/default/model.yml", source = "model";
  app.add_option("--model,-m", model_path, "Plane model file, for --mode pdvo")->capture_default_str();
  app.add_option("--detections", source,
                 "Mode pdvo's planes: model (the detector), oracle (the sequence's own annotations: pdvo synth "
                 "output), or a folder of annotation files matched to frames by image name")
      ->capture_default_str();
  app.add_option("--format", format_name, "Trajectory format: tum or kitti")->capture_default_str();
  app.add_option("--max-frames", max_frames, "Stop after this many frames (0: all)")->check(NotNegative());
  app.add_flag("--overlay", overlay,
               "Also write overlay.avi: each frame with its features (points green, plane points coloured by "
               "plane; filled where the update used the match, hollow where not found, red where RANSAC "
               "rejected it), each plane's region tinted, detected outlines in yellow, and a status line; the "
               "same frames as views/FRAME.jpg where detections were applied (other modes: at keyframes); in "
               "mode pdvo with the model, the detector's stages of each keyframe as stages/FRAME.jpg");
  AddConfigFlags(app, &config_path, &overrides, "VO options (YAML, section 'vo')", "search.min_ncc=0.85");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  const bool mode_set =
      !mode.empty() || !config_path.empty() ||
      std::any_of(overrides.begin(), overrides.end(), [](const std::string& o) { return o.rfind("mode=", 0) == 0; });
  if (!mode_set && std::filesystem::exists(model_path)) mode = "pdvo";
  if (!mode.empty()) overrides.push_back("mode=" + mode);
  const vo::VoOptions options = LoadToolOptions<vo::VoOptions>(config_path, "vo", overrides);
  const TrajectoryFormat format = ParseTrajectoryFormat(format_name);
  SequenceOptions reading;  // the images and their times: depth maps and ground truth are not read
  reading.load_depth = reading.load_groundtruth = false;
  std::unique_ptr<Sequence> sequence = OpenSequence(sequence_path, reading);
  const Camera camera = SequenceCamera(*sequence, sequence_path, camera_path);
  const vo::FramePreparer preparer(camera, options.working_width);
  const Camera& working = preparer.working_camera();
  const int width = working.width, height = working.height;
  const bool pdvo = options.mode == vo::PlaneMode::kPdvo;
  std::unique_ptr<PlaneSource> planes;
  if (pdvo) planes = std::make_unique<PlaneSource>(source, model_path, sequence_path, working);
  vo::Odometry odometry(working, options, nullptr, planes ? planes->detector() : vo::PlaneDetector());
  PDVO_LOG(Info) << "vo (mode " << OptionName(options.mode) << ") on " << sequence->Describe() << " at " << width << "x"
                 << height << (planes ? ", planes from " + planes->Describe() : "");

  StagedOutputDir out(out_dir);
  SaveOptions(out.path("vo.yaml"), options, "vo");
  size_t tracked = 0;
  StatsFile stats(out.path("stats.json"), out.final_path("stats.json"),
                  {{"sequence", sequence_path}, {"mode", OptionName(options.mode)}});
  int keyframes_detected = 0, planes_detected = 0, planes_seeded = 0, planes_extended = 0;
  // The paper's Fig. 4; planes are matched to their keyframe's frame by its timestamp.
  vo::MeasurementCurve measured_after(kCurveFrames, options.planes.min_plane_points);
  std::vector<double> times;
  int keyframes_gone = 0;
  double seconds = 0, waited = 0;
  int lost = 0, uncertain = 0, keyframes = 0, update_failures = 0;
  const size_t total = max_frames > 0 ? std::min(max_frames, sequence->size()) : sequence->size();
  Progress progress("vo", total);
  cv::VideoWriter video;
  if (overlay) {
    video.open(out.path("overlay.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, cv::Size(width, height));
    PDVO_THROW_CHECK(video.isOpened(), IoError, out.final_path("overlay.avi") << ": cannot open a video writer");
    if (planes) planes->KeepStages();
  }
  Frame frame;
  while ((max_frames == 0 || tracked < max_frames) && sequence->Next(&frame)) {
    PDVO_THROW_CHECK(frame.image.cols == camera.width && frame.image.rows == camera.height, FormatError,
                     frame.image_path << ": image is " << frame.image.cols << "x" << frame.image.rows
                                      << ", the camera says " << camera.width << "x" << camera.height);
    const vo::PreparedFrame prepared = preparer.Prepare(frame.image);
    const size_t index = tracked++;
    if (planes) planes->AddFrame(static_cast<int>(index), frame.image_path);
    const vo::FrameStats s = odometry.Track(prepared.grey, frame.timestamp, prepared.colour);
    for (const vo::DetectionEvent& e : s.detections) {
      stats.AddDetection(DetectionJson(e, frame.timestamp));
      ++keyframes_detected;
      planes_detected += static_cast<int>(e.result.planes.size());
      planes_seeded += e.seeding.seeded;
      planes_extended += e.seeding.extended;
      keyframes_gone += e.keyframe_gone;
    }
    times.push_back(frame.timestamp);
    // The planes of a filter that the bootstrap replaced are not in the map, nor in the curve.
    if (s.bootstrap) measured_after = vo::MeasurementCurve(kCurveFrames, options.planes.min_plane_points);
    for (const vo::Observation& o : odometry.observations()) {
      if (o.plane < 0) continue;
      const int keyframe =
          static_cast<int>(std::lower_bound(times.begin(), times.end(), o.keyframe_time) - times.begin());
      measured_after.Add(static_cast<int>(index), keyframe, o.plane, o.keyframe_pixel, o.used);
    }
    seconds += s.seconds;
    lost += s.lost;
    uncertain += s.health == vo::Health::kUncertain;
    keyframes += s.keyframe;
    waited += s.detector_wait_seconds;
    stats.AddFrame({{"t", s.timestamp},
                    {"seconds", s.seconds},
                    {"attempted", s.attempted},
                    {"measurements", s.measurements},
                    {"nis", s.nis},
                    {"points", s.points},
                    {"planes", s.planes},
                    {"plane_points", s.plane_points},
                    {"plane_measurements", s.plane_measurements},
                    {"state", s.state_size},
                    {"keyframe", s.keyframe},
                    {"lost", s.lost},
                    {"health", OptionName(s.health)},
                    {"segment", s.segment},
                    {"bootstrap", s.bootstrap},
                    {"update", vo::ToString(s.update)},
                    {"resident_mib", ResidentMiB()}});
    update_failures += s.update != vo::UpdateStatus::kOk && s.update != vo::UpdateStatus::kNoMeasurements;
    if (overlay) {
      const cv::Mat drawn = DrawOverlay(prepared.colour, odometry.observations(), s, odometry.plane_outlines());
      video.write(drawn);
      if (pdvo ? !s.detections.empty() : s.keyframe) {
        WriteImage(out.path("views/" + FrameName(index) + ".jpg"), drawn);
      }
    }
    progress.SetNote("state " + std::to_string(s.state_size) + ", " + std::to_string(s.points) + " points, " +
                     std::to_string(s.planes) + " planes");
    progress.Step();
  }
  progress.Finish();
  video.release();
  PDVO_THROW_CHECK(tracked > 0, FormatError, sequence_path << ": no frames");
  if (update_failures > 0) {
    PDVO_LOG(Warning) << "vo: the update failed and was skipped in " << update_failures
                      << " frames (stats.json: frames[].update)";
  }
  if (uncertain + lost > 0) {
    PDVO_LOG(Warning) << "vo: " << uncertain << " of " << tracked << " poses are uncertain and tracking was lost "
                      << lost << " times: do not trust those poses (stats.json: frames[].health)";
  }
  const Trajectory& trajectory = odometry.trajectory();  // with the poses the bootstrap revised
  WriteTrajectory(out.path("trajectory.txt"), trajectory, format);
  const vo::Map map = odometry.map();
  vo::WritePly(out.path("map.ply"), map, trajectory);
  if (planes) {
    const std::map<int, std::vector<unsigned char>> stages = planes->TakeStages();
    for (const auto& [keyframe, jpeg] : stages) {
      WriteFileAtomically(out.path("stages/" + FrameName(keyframe) + ".jpg"), std::string(jpeg.begin(), jpeg.end()));
    }
  }
  const double fps = trajectory.size() / std::max(seconds, 1e-9);
  const vo::MappingStats mapping = odometry.mapping();
  const nlohmann::json totals = {{"frames", trajectory.size()},
                                 {"tracking_seconds", seconds},
                                 {"fps", fps},
                                 {"keyframes", keyframes},
                                 {"lost", lost},
                                 {"uncertain", uncertain},
                                 {"update_failures", update_failures},
                                 {"planes", mapping.planes},
                                 {"points_per_plane", mapping.points_per_plane},
                                 {"mean_plane_area_px", mapping.mean_plane_area},
                                 {"map_points", map.points.size()},
                                 {"map_planes", map.planes.size()}};
  nlohmann::json tail = {{"totals", totals}, {"plane_measurements_after_keyframe", measured_after.Mean()}};
  if (pdvo) {
    const vo::Odometry::DetectionCounts counts = odometry.detection_counts();
    tail["totals"]["detections"] = {{"keyframes_detected", keyframes_detected},
                                    {"skipped", counts.skipped},
                                    {"timed_out", counts.timed_out},
                                    {"failed", counts.failed},
                                    {"keyframe_gone", keyframes_gone},
                                    {"planes_detected", planes_detected},
                                    {"planes_seeded", planes_seeded},
                                    {"planes_extended", planes_extended}};
    tail["totals"]["detector_wait_seconds"] = waited;
    if (counts.timed_out > 0) {
      PDVO_LOG(Warning) << "vo: " << counts.timed_out << " detections took longer than pdvo.timeout_seconds and "
                        << "were given up: the trajectory may differ from run to run";
    }
  }
  stats.Finish(tail, pdvo);
  out.Commit();
  std::printf(
      "%zu frames, tracking %.1f frames/s (the tracking thread%s), %d keyframes, lost %d times, %d uncertain; "
      "%d planes, "
      "%.1f points per plane, mean area %.0f px; wrote %s\n",
      trajectory.size(), fps,
      waited > 0 ? (", and it waited " + std::to_string(waited).substr(0, 5) + " s for the detector").c_str() : "",
      keyframes, lost, uncertain, mapping.planes, mapping.points_per_plane, mapping.mean_plane_area, out_dir.c_str());
  return 0;
}

}  // namespace pdvo::apps
