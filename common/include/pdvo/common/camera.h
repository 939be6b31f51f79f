// Pinhole camera with OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3).
//
// Pixel convention: x right, y down, (0, 0) the centre of the top-left pixel. The camera frame has x right,
// y down, z along the optical axis. YAML layout (a map at the root or under `camera:`):
//   width: 640   height: 480   fx: 517.3   fy: 516.5   cx: 318.6   cy: 255.3
//   k1: 0.2624   k2: -0.9531   p1: -0.0054   p2: 0.0026   k3: 1.1633     # optional, default 0
//   depth_scale: 5000   # optional: an RGB-D camera's depth image units per metre
// Width, height, fx, fy, cx and cy are required; any other key is an error.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace pdvo {

// The largest image side (pixels) the readers of cameras and annotations accept: larger ones are refused
// before anything is allocated for them.
inline constexpr int kMaxImageSide = 16384;

struct Camera {
  int width = 0, height = 0;              // pixels
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels
  std::array<double, 5> distortion{};     // k1, k2, p1, p2, k3
  double depth_scale = 0;                 // depth image units per metre; 0: not given

  // Reads from YAML; throws IoError / FormatError naming the file and the missing or bad key.
  static Camera Read(const std::string& path);
  static Camera Read(const cv::FileNode& node, const std::string& where);
  // Writes YAML atomically.
  void Write(const std::string& path) const;
  void Write(cv::FileStorage& fs) const;
  // Throws InvalidArgument if sizes or focal lengths are not positive or a value is not finite.
  void Check(const std::string& where) const;

  bool HasDistortion() const;
  cv::Matx33d K() const;

  // Projects a point in camera coordinates (z > 0) to distorted pixel coordinates.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const;
  // The viewing ray (z = 1) of a distorted pixel: undistorts iteratively.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const;
  // The same ray as a unit vector.
  Eigen::Vector3d Ray(const Eigen::Vector2d& pixel) const;
  // Maps distorted pixels to the pixels of the ideal pinhole camera with the same K.
  std::vector<cv::Point2d> UndistortPoints(const std::vector<cv::Point2d>& pixels) const;

  // The same camera without distortion (its images come from Undistorter).
  Camera Undistorted() const;
  // The camera of the image resized to width x height (pixel centres map to pixel centres).
  Camera Rescaled(int new_width, int new_height) const;
  // A pinhole camera without distortion.
  static Camera Pinhole(int width, int height, double fx, double fy, double cx, double cy);
  // A pinhole camera without distortion with the given horizontal field of view, square pixels and the
  // principal point at the image's centre.
  static Camera WithFieldOfView(int width, int height, double horizontal_fov_deg);

  bool operator==(const Camera&) const = default;
};

// Remaps distorted images of `camera` to images of camera.Undistorted(). Holds the remap tables; build once.
class Undistorter {
 public:
  explicit Undistorter(const Camera& camera);
  // Throws InvalidArgument if the image size differs from the camera's.
  cv::Mat Apply(const cv::Mat& image, int interpolation = cv::INTER_LINEAR) const;

 private:
  Camera camera_;
  cv::Mat map1_, map2_;
};

}  // namespace pdvo
