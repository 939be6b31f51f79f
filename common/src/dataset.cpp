#include "pdvo/common/dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/trajectory.h"

namespace pdvo {
namespace fs = std::filesystem;

bool HasImageExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" || ext == ".tiff" ||
         ext == ".ppm" || ext == ".pgm";
}

namespace {

std::optional<Camera> CameraInFolder(const fs::path& folder) {
  const fs::path yaml = folder / "camera.yaml";
  if (fs::exists(yaml)) return Camera::Read(yaml.string());
  return std::nullopt;
}

// Index of the entry of `times` (sorted) nearest to t, if within max_dt.
std::optional<size_t> Nearest(const std::vector<double>& times, double t, double max_dt) {
  if (times.empty()) return std::nullopt;
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  size_t best = static_cast<size_t>(it - times.begin());
  if (best == times.size() || (best > 0 && t - times[best - 1] < times[best] - t)) --best;
  if (std::abs(times[best] - t) > max_dt) return std::nullopt;
  return best;
}

// A sequence whose frames are files listed up front.
class ListedSequence : public Sequence {
 public:
  struct Entry {
    double timestamp;
    std::string image_path, depth_path;
    std::optional<Rigid3d> world_from_cam;
  };

  ListedSequence(std::string kind, std::string root, std::vector<Entry> entries, std::optional<Camera> camera,
                 double depth_scale)
      : kind_(std::move(kind)),
        root_(std::move(root)),
        entries_(std::move(entries)),
        camera_(std::move(camera)),
        depth_scale_(depth_scale) {
    PDVO_THROW_CHECK(!entries_.empty(), FormatError, root_ << ": " << kind_ << " holds no frames");
  }

  bool Next(Frame* frame) override {
    if (next_ >= entries_.size()) return false;
    const Entry& e = entries_[next_];
    frame->index = next_++;
    frame->timestamp = e.timestamp;
    frame->image_path = e.image_path;
    frame->world_from_cam = e.world_from_cam;
    frame->image = ReadImage(e.image_path, cv::IMREAD_COLOR);
    frame->depth.release();
    if (!e.depth_path.empty()) {
      const cv::Mat raw = ReadImage(e.depth_path, cv::IMREAD_ANYDEPTH);
      PDVO_THROW_CHECK(raw.type() == CV_16UC1, FormatError,
                       e.depth_path << ": depth must be a 16-bit single-channel PNG");
      PDVO_THROW_CHECK(raw.size() == frame->image.size(), FormatError,
                       e.depth_path << ": depth is " << raw.cols << "x" << raw.rows << " but the image is "
                                    << frame->image.cols << "x" << frame->image.rows);
      raw.convertTo(frame->depth, CV_32F, 1.0 / depth_scale_);
    }
    return true;
  }
  size_t size() const override { return entries_.size(); }
  std::optional<Camera> camera() const override { return camera_; }
  std::string Describe() const override {
    return kind_ + " " + root_ + " (" + std::to_string(entries_.size()) + " frames)";
  }

 private:
  std::string kind_, root_;
  std::vector<Entry> entries_;
  std::optional<Camera> camera_;
  double depth_scale_;
  size_t next_ = 0;
};

std::unique_ptr<Sequence> OpenTum(const fs::path& root, const SequenceOptions& options) {
  const auto rgb = ReadTumList((root / "rgb.txt").string());
  std::vector<double> depth_times;
  std::vector<std::string> depth_paths;
  if (options.load_depth && fs::exists(root / "depth.txt")) {
    for (const auto& [t, p] : ReadTumList((root / "depth.txt").string())) {
      depth_times.push_back(t);
      depth_paths.push_back((root / p).string());
    }
  }
  Trajectory gt;
  std::vector<double> gt_times;
  if (options.load_groundtruth && fs::exists(root / "groundtruth.txt")) {
    gt = ReadTrajectory((root / "groundtruth.txt").string(), TrajectoryFormat::kTum);
    for (const StampedPose& p : gt) gt_times.push_back(p.timestamp);
  }
  std::vector<ListedSequence::Entry> entries;
  size_t without_depth = 0;
  for (const auto& [t, p] : rgb) {
    ListedSequence::Entry e{t, (root / p).string(), "", std::nullopt};
    if (const auto d = Nearest(depth_times, t, options.max_association_dt)) {
      e.depth_path = depth_paths[*d];
    } else if (!depth_times.empty()) {
      ++without_depth;
    }
    if (const auto g = Nearest(gt_times, t, options.max_association_dt)) e.world_from_cam = gt[*g].world_from_cam;
    entries.push_back(std::move(e));
  }
  if (without_depth > 0) {
    PDVO_LOG(Warning) << root.string() << ": " << without_depth << " images have no depth map within "
                      << options.max_association_dt << " s";
  }
  const std::optional<Camera> camera = CameraInFolder(root);
  const double depth_scale = camera && camera->depth_scale > 0 ? camera->depth_scale : options.depth_scale;
  return std::make_unique<ListedSequence>("TUM RGB-D folder", root.string(), std::move(entries), camera, depth_scale);
}

std::unique_ptr<Sequence> OpenKitti(const fs::path& root, const SequenceOptions& options) {
  // calib.txt: lines of 12 numbers, optionally labelled "P0:"; the first is the left camera.
  const std::string calib_path = (root / "calib.txt").string();
  std::vector<double> p0;
  for (const auto& [number, line] : ReadDataLines(calib_path)) {
    std::istringstream fields(line);
    std::string token;
    while (fields >> token) {
      if (token.back() == ':') continue;  // a "P0:" label
      char* end = nullptr;
      p0.push_back(std::strtod(token.c_str(), &end));
      PDVO_THROW_CHECK(end && *end == '\0', FormatError,
                       calib_path << ":" << number << ": '" << token << "' is not a number");
    }
    break;  // the first line is the left camera
  }
  PDVO_THROW_CHECK(p0.size() == 12, FormatError,
                   calib_path << ": expected a 3x4 projection matrix (12 numbers) on the first line");

  fs::path image_dir;
  for (const char* name : {"image_0", "image_l", "image_2"}) {
    if (fs::is_directory(root / name)) {
      image_dir = root / name;
      break;
    }
  }
  PDVO_THROW_CHECK(!image_dir.empty(), FormatError, root.string() << ": KITTI folder has no image_0/ or image_l/");
  std::vector<std::string> images;
  for (const auto& e : fs::directory_iterator(image_dir)) {
    if (e.is_regular_file() && HasImageExtension(e.path().string())) images.push_back(e.path().string());
  }
  std::sort(images.begin(), images.end());
  PDVO_THROW_CHECK(!images.empty(), FormatError, image_dir.string() << ": holds no images");

  std::vector<double> times;
  if (fs::exists(root / "times.txt")) times = ReadTimes((root / "times.txt").string());
  Trajectory poses;
  if (options.load_groundtruth && fs::exists(root / "poses.txt"))
    poses = ReadTrajectory((root / "poses.txt").string(), TrajectoryFormat::kKitti);
  PDVO_THROW_CHECK(times.empty() || times.size() >= images.size(), FormatError,
                   (root / "times.txt").string()
                       << ": " << times.size() << " times for " << images.size() << " images");
  PDVO_THROW_CHECK(poses.empty() || poses.size() >= images.size(), FormatError,
                   (root / "poses.txt").string()
                       << ": " << poses.size() << " poses for " << images.size() << " images");

  const cv::Mat first = ReadImage(images[0], cv::IMREAD_GRAYSCALE);
  Camera camera;
  camera.width = first.cols;
  camera.height = first.rows;
  camera.fx = p0[0];
  camera.cx = p0[2];
  camera.fy = p0[5];
  camera.cy = p0[6];
  camera.Check(calib_path);

  std::vector<ListedSequence::Entry> entries;
  for (size_t i = 0; i < images.size(); ++i) {
    ListedSequence::Entry e{times.empty() ? i * 0.1 : times[i], images[i], "", std::nullopt};
    if (!poses.empty()) e.world_from_cam = poses[i].world_from_cam;
    entries.push_back(std::move(e));
  }
  return std::make_unique<ListedSequence>("KITTI odometry folder", root.string(), std::move(entries), camera, 1.0);
}

std::unique_ptr<Sequence> OpenImageFolder(const fs::path& root, const SequenceOptions& options) {
  std::vector<std::string> images;
  for (const auto& e : fs::directory_iterator(root)) {
    if (e.is_regular_file() && HasImageExtension(e.path().string())) images.push_back(e.path().string());
  }
  std::sort(images.begin(), images.end());
  PDVO_THROW_CHECK(!images.empty(), FormatError, root.string() << ": holds no images (.png, .jpg, ...)");
  std::vector<double> times;
  if (!options.times_path.empty()) {
    times = ReadTimes(options.times_path);
    PDVO_THROW_CHECK(times.size() == images.size(), FormatError,
                     options.times_path << ": " << times.size() << " times for " << images.size() << " images");
  }
  std::vector<ListedSequence::Entry> entries;
  for (size_t i = 0; i < images.size(); ++i) {
    entries.push_back({times.empty() ? i / options.fps : times[i], images[i], "", std::nullopt});
  }
  return std::make_unique<ListedSequence>("image folder", root.string(), std::move(entries), CameraInFolder(root), 1.0);
}

class VideoSequence : public Sequence {
 public:
  VideoSequence(const std::string& path, double fps) : path_(path) {
    // FFmpeg decodes video files; other backends (GStreamer, image sequences) print noise for files they
    // cannot open.
    // FFmpeg's own messages on a damaged stream would add lines to the one-line error (unless the user asks).
    setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
    capture_.open(path, cv::CAP_FFMPEG);
    PDVO_THROW_CHECK(capture_.isOpened(), IoError, path << ": cannot open as a video");
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    count_ = count > 0 ? static_cast<size_t>(count) : 0;
    const double video_fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = video_fps > 0 ? video_fps : fps;
  }
  bool Next(Frame* frame) override {
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) {
      PDVO_THROW_CHECK(next_ > 0, FormatError, path_ << ": video holds no frames");
      // The container's count may be an estimate (duration times rate) for some formats: a frame or 1% short is
      // taken; more is a video cut short or corrupt, which would otherwise pass as a shorter one.
      PDVO_THROW_CHECK(next_ + std::max<size_t>(1, count_ / 100) >= count_, FormatError,
                       path_ << ": the video ends after " << next_ << " of the " << count_
                             << " frames its container lists (truncated or corrupt)");
      return false;
    }
    if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
    frame->index = next_;
    frame->timestamp = next_ / fps_;
    frame->image = image;
    frame->depth.release();
    frame->world_from_cam.reset();
    frame->image_path.clear();
    ++next_;
    return true;
  }
  size_t size() const override { return count_; }
  std::optional<Camera> camera() const override { return std::nullopt; }
  std::string Describe() const override { return "video " + path_ + " (" + std::to_string(count_) + " frames)"; }

 private:
  std::string path_;
  cv::VideoCapture capture_;
  size_t count_ = 0, next_ = 0;
  double fps_ = 30;
};

}  // namespace

std::vector<std::pair<double, std::string>> ReadTumList(const std::string& path) {
  std::vector<std::pair<double, std::string>> list;
  for (const auto& [number, line] : ReadDataLines(path)) {
    std::istringstream fields(line);
    double t = 0;
    std::string file;
    PDVO_THROW_CHECK((fields >> t >> file) && std::isfinite(t), FormatError,
                     path << ":" << number << ": expected 'timestamp filename'");
    PDVO_THROW_CHECK(list.empty() || t > list.back().first, FormatError,
                     path << ":" << number << ": timestamp " << t << " does not increase");
    list.emplace_back(t, file);
  }
  PDVO_THROW_CHECK(!list.empty(), FormatError, path << ": lists no frames");
  return list;
}

std::unique_ptr<Sequence> OpenSequence(const std::string& path, const SequenceOptions& options) {
  CheckExists(path, "sequence");
  const fs::path root(path);
  if (fs::is_directory(root)) {
    if (fs::exists(root / "rgb.txt")) return OpenTum(root, options);
    if (fs::exists(root / "calib.txt")) return OpenKitti(root, options);
    return OpenImageFolder(root, options);
  }
  return std::make_unique<VideoSequence>(path, options.fps);
}

}  // namespace pdvo
