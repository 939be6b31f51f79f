// pdvo vo: monocular visual odometry (the IDPP EKF: inverse-depth points and planes) over a sequence.
#include <cstdio>
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
#include "tool.h"

namespace pdvo::apps {
namespace {

// The frame with its features: points green, plane points in a colour per plane; filled where the update used
// the match, hollow where the search failed, red where RANSAC rejected the match.
cv::Mat DrawOverlay(const cv::Mat& colour, const std::vector<vo::Observation>& observations,
                    const vo::FrameStats& s) {
  cv::Mat out = colour.clone();
  for (const vo::Observation& o : observations) {
    const cv::Scalar c = o.matched && !o.used ? cv::Scalar(0, 0, 255)
                         : o.plane < 0        ? cv::Scalar(0, 220, 0)
                                              : cv::Scalar(60 + (o.plane * 67) % 196, 60 + (o.plane * 131) % 196,
                                                           60 + (o.plane * 199) % 196);
    cv::circle(out, cv::Point(cvRound(o.pixel.x()), cvRound(o.pixel.y())), 3, c, o.used ? cv::FILLED : 1,
               cv::LINE_AA);
  }
  char text[128];
  std::snprintf(text, sizeof(text), "t %.2f  %d/%d matched  %d points  %d planes%s", s.timestamp, s.measurements,
                s.attempted, s.points, s.planes, s.lost ? "  LOST" : "");
  cv::putText(out, text, cv::Point(4, 12), cv::FONT_HERSHEY_PLAIN, 0.8, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace

int RunVo(int argc, char** argv) {
  CLI::App app("Monocular visual odometry: an EKF with inverse-depth points and planes anchored at keyframes "
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
  app.add_option("--mode", mode, "idpp (points and planes) or points (default: the options' mode, points)");
  app.add_option("--format", format_name, "Trajectory format: tum or kitti")->capture_default_str();
  app.add_option("--max-frames", max_frames, "Stop after this many frames (0: all)");
  app.add_flag("--overlay", overlay,
               "Also write overlay.avi: each frame with its features (points green, plane points coloured by "
               "plane; filled where the update used the match, hollow where not found, red where RANSAC "
               "rejected it) and a status line");
  AddConfigFlags(app, &config_path, &overrides, "VO options (YAML, section 'vo')", "search.min_ncc=0.85");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  if (!mode.empty()) overrides.push_back("mode=" + mode);
  const vo::VoOptions options = LoadToolOptions<vo::VoOptions>(config_path, "vo", overrides);
  const TrajectoryFormat format = ParseTrajectoryFormat(format_name);
  std::unique_ptr<Sequence> sequence = OpenSequence(sequence_path);
  const Camera camera = SequenceCamera(*sequence, sequence_path, camera_path);
  const vo::FramePreparer preparer(camera, options.working_width);
  const Camera& working = preparer.working_camera();
  const int width = working.width, height = working.height;
  vo::Odometry odometry(working, options);
  PDVO_LOG(Info) << "vo on " << sequence->Describe() << " at " << width << "x" << height;

  StagedOutputDir out(out_dir);
  SaveOptions(out.path("vo.yaml"), options, "vo");
  size_t tracked = 0;
  nlohmann::json frames = nlohmann::json::array();
  double seconds = 0;
  int lost = 0, keyframes = 0, update_failures = 0;
  const size_t total = max_frames > 0 ? std::min(max_frames, sequence->size()) : sequence->size();
  Progress progress("vo", total);
  cv::VideoWriter video;
  if (overlay) {
    video.open(out.path("overlay.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, cv::Size(width, height));
    PDVO_THROW_CHECK(video.isOpened(), IoError, out.final_path("overlay.avi") << ": cannot open a video writer");
  }
  Frame frame;
  while ((max_frames == 0 || tracked < max_frames) && sequence->Next(&frame)) {
    PDVO_THROW_CHECK(frame.image.cols == camera.width && frame.image.rows == camera.height, FormatError,
                     frame.image_path << ": image is " << frame.image.cols << "x" << frame.image.rows
                                      << ", the camera says " << camera.width << "x" << camera.height);
    const vo::PreparedFrame prepared = preparer.Prepare(frame.image);
    const vo::FrameStats s = odometry.Track(prepared.grey, frame.timestamp);
    seconds += s.seconds;
    lost += s.lost;
    keyframes += s.keyframe;
    ++tracked;
    frames.push_back({{"t", s.timestamp}, {"seconds", s.seconds}, {"attempted", s.attempted},
                      {"measurements", s.measurements}, {"points", s.points}, {"planes", s.planes},
                      {"plane_points", s.plane_points},
                      {"state", s.state_size}, {"keyframe", s.keyframe}, {"lost", s.lost},
                      {"bootstrap", s.bootstrap}, {"update", vo::ToString(s.update)}});
    update_failures += s.update != vo::UpdateStatus::kOk && s.update != vo::UpdateStatus::kNoMeasurements;
    if (overlay) video.write(DrawOverlay(prepared.colour, odometry.observations(), s));
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
  const Trajectory& trajectory = odometry.trajectory();  // with the poses the bootstrap revised
  WriteTrajectory(out.path("trajectory.txt"), trajectory, format);
  const vo::Map map = odometry.map();
  vo::WritePly(out.path("map.ply"), map, trajectory);
  const double fps = trajectory.size() / std::max(seconds, 1e-9);
  const vo::MappingStats mapping = odometry.mapping();
  const nlohmann::json totals = {{"frames", trajectory.size()},
                                 {"tracking_seconds", seconds},
                                 {"fps", fps},
                                 {"keyframes", keyframes},
                                 {"lost", lost},
                                 {"update_failures", update_failures},
                                 {"planes", mapping.planes},
                                 {"points_per_plane", mapping.points_per_plane},
                                 {"mean_plane_area_px", mapping.mean_plane_area},
                                 {"map_points", map.points.size()},
                                 {"map_planes", map.planes.size()}};
  WriteFileAtomically(out.path("stats.json"), nlohmann::json({{"totals", totals}, {"frames", frames}}).dump(1) + "\n");
  out.Commit();
  std::printf("%zu frames, tracking %.1f frames/s (one thread), %d keyframes, lost %d times; %d planes, %.1f "
              "points per plane, mean area %.0f px; wrote %s\n",
              trajectory.size(), fps, keyframes, lost, mapping.planes, mapping.points_per_plane,
              mapping.mean_plane_area, out_dir.c_str());
  return 0;
}

}  // namespace pdvo::apps
