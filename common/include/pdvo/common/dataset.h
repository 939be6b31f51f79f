// Dataset readers: one interface that yields frames from an image folder, a video file, a TUM RGB-D folder
// or a KITTI odometry folder.
//
// OpenSequence() tells the kind from what is at the path:
// - a TUM RGB-D folder: rgb.txt (+ depth.txt, groundtruth.txt); depth and ground truth are associated with
//   each colour image by nearest timestamp within `max_association_dt`;
// - a KITTI odometry folder: calib.txt and image_0/ (or image_l/), with times.txt and poses.txt if present;
// - an image folder: every .png/.jpg/.jpeg/.bmp/.tif/.ppm/.pgm file, in name order, with times from
//   `times_path` if given (one per line), otherwise index / `fps`;
// - a video file (anything else that is a file), decoded with OpenCV.
// A folder holding camera.yaml gives its camera (KITTI's comes from calib.txt).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "pdvo/common/camera.h"
#include "pdvo/common/geometry.h"

namespace pdvo {

struct Frame {
  size_t index = 0;                       // position in the sequence
  double timestamp = 0;                   // seconds
  cv::Mat image;                          // 8-bit BGR
  cv::Mat depth;                          // CV_32F metres, 0 where unknown; empty if the sequence has no depth
  std::optional<Rigid3d> world_from_cam;  // ground truth, if the sequence has it near this time
  std::string image_path;                 // file the image came from (empty for video)
};

struct SequenceOptions {
  double max_association_dt = 0.02;  // seconds; TUM depth and ground truth association window
  double depth_scale = 5000.0;       // depth PNG units per metre (TUM); camera.yaml's depth_scale overrides it
  double fps = 30.0;                 // image folders without times, and videos without time stamps
  std::string times_path;            // image folder: optional file of one time per line
  bool load_depth = true;            // TUM: read depth maps
  bool load_groundtruth = true;      // TUM groundtruth.txt, KITTI poses.txt: read (a command that does not use
                                     // them leaves them unread, so that a bad one does not stop it)
};

class Sequence {
 public:
  virtual ~Sequence() = default;
  // Reads the next frame into *frame; returns false at the end. Throws IoError naming the file for a frame
  // that cannot be read or decoded.
  virtual bool Next(Frame* frame) = 0;
  // Number of frames (for a video, as its container reports it).
  virtual size_t size() const = 0;
  // The camera, if the sequence holds one.
  virtual std::optional<Camera> camera() const = 0;
  // "TUM RGB-D folder /path (100 frames)", for logs.
  virtual std::string Describe() const = 0;
};

// Opens the sequence at `path`; throws IoError if it does not exist and FormatError if it holds no frames or
// its index files are malformed.
// True if the path ends in an image extension the readers take (.png .jpg .jpeg .bmp .tif .tiff .ppm .pgm, any case).
bool HasImageExtension(const std::string& path);

std::unique_ptr<Sequence> OpenSequence(const std::string& path, const SequenceOptions& options = {});

// A TUM list file (`timestamp path` per line, '#' comments): returns (time, path relative to the folder).
std::vector<std::pair<double, std::string>> ReadTumList(const std::string& path);

}  // namespace pdvo
