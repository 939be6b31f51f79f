#include "pdvo/common/camera.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {
constexpr const char* kDistortionKeys[5] = {"k1", "k2", "p1", "p2", "k3"};

double ReadNumber(const cv::FileNode& node, const char* key, const std::string& where, bool required, double fallback) {
  const cv::FileNode child = node[key];
  if (child.empty() || child.isNone()) {
    PDVO_THROW_CHECK(!required, FormatError, where << ": missing key '" << key << "'");
    return fallback;
  }
  double v = 0;
  detail::ReadScalar(child, where + "." + key, v);
  return v;
}
}  // namespace

Camera Camera::Read(const std::string& path) {
  cv::FileStorage fs = OpenYamlForReading(path);
  return WithOpenCvErrorsNamed(path, [&] {
    const cv::FileNode camera_node = fs["camera"];
    return camera_node.isMap() ? Read(camera_node, path + ": camera") : Read(fs.root(), path);
  });
}

Camera Camera::Read(const cv::FileNode& node, const std::string& where) {
  PDVO_THROW_CHECK(node.isMap(), FormatError, where << ": expected a map with the camera's keys");
  Camera c;
  const auto side = [&](const char* key) {  // checked before the conversion to int
    const double v = ReadNumber(node, key, where, true, 0);
    PDVO_THROW_CHECK(v >= 1 && v <= kMaxImageSide && v == std::floor(v), FormatError,
                     where << ": '" << key << "' must be a whole number of pixels from 1 to " << kMaxImageSide
                           << " (got " << v << ")");
    return static_cast<int>(v);
  };
  c.width = side("width");
  c.height = side("height");
  c.fx = ReadNumber(node, "fx", where, true, 0);
  c.fy = ReadNumber(node, "fy", where, true, 0);
  c.cx = ReadNumber(node, "cx", where, true, 0);
  c.cy = ReadNumber(node, "cy", where, true, 0);
  c.depth_scale = ReadNumber(node, "depth_scale", where, false, 0.0);
  std::set<std::string> known = {"width", "height", "fx", "fy", "cx", "cy", "depth_scale"};
  for (int i = 0; i < 5; ++i) {
    c.distortion[i] = ReadNumber(node, kDistortionKeys[i], where, false, 0.0);
    known.insert(kDistortionKeys[i]);
  }
  detail::ThrowIfUnknownKeys(node, known, where);
  try {
    c.Check(where);
  } catch (const InvalidArgument& e) {  // a file's fault: a data error
    PDVO_THROW(FormatError, e.what());
  }
  return c;
}

void Camera::Write(const std::string& path) const {
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  Write(fs);
  WriteFileAtomically(path, fs.releaseAndGetString());
}

void Camera::Write(cv::FileStorage& fs) const {
  fs << "camera"
     << "{"
     << "width" << width << "height" << height << "fx" << fx << "fy" << fy << "cx" << cx << "cy" << cy;
  for (int i = 0; i < 5; ++i) fs << kDistortionKeys[i] << distortion[i];
  if (depth_scale > 0) fs << "depth_scale" << depth_scale;
  fs << "}";
}

void Camera::Check(const std::string& where) const {
  PDVO_THROW_CHECK(width > 0 && height > 0, InvalidArgument,
                   where << ": image size must be positive, got " << width << "x" << height);
  PDVO_THROW_CHECK(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0, InvalidArgument,
                   where << ": focal lengths must be positive and finite, got fx=" << fx << " fy=" << fy);
  PDVO_THROW_CHECK(std::isfinite(depth_scale) && depth_scale >= 0, InvalidArgument,
                   where << ": depth_scale must be positive, got " << depth_scale);
  PDVO_THROW_CHECK(std::isfinite(cx) && std::isfinite(cy), InvalidArgument, where << ": principal point is not finite");
  for (int i = 0; i < 5; ++i) {
    PDVO_THROW_CHECK(std::isfinite(distortion[i]), InvalidArgument,
                     where << ": distortion " << kDistortionKeys[i] << " is not finite");
  }
}

bool Camera::HasDistortion() const {
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

cv::Matx33d Camera::K() const { return cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1); }

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& p) const {
  if (!HasDistortion()) return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const auto& [k1, k2, p1, p2, k3] = distortion;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {fx * xd + cx, fy * yd + cy};
}

Eigen::Vector3d Camera::Unproject(const Eigen::Vector2d& pixel) const {
  const cv::Point2d u = UndistortPoints({cv::Point2d(pixel.x(), pixel.y())})[0];
  return {(u.x - cx) / fx, (u.y - cy) / fy, 1.0};
}

Eigen::Vector3d Camera::Ray(const Eigen::Vector2d& pixel) const { return Unproject(pixel).normalized(); }

std::vector<cv::Point2d> Camera::UndistortPoints(const std::vector<cv::Point2d>& pixels) const {
  if (!HasDistortion() || pixels.empty()) return pixels;
  std::vector<cv::Point2d> out;
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(distortion.data()));
  // More iterations than OpenCV's default 5: the TUM fr1 distortion is strong at the image corners.
  cv::undistortPoints(pixels, out, K(), dist, cv::noArray(), K(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-10));
  return out;
}

Camera Camera::Undistorted() const {
  Camera c = *this;
  c.distortion = {};
  return c;
}

Camera Camera::Rescaled(int new_width, int new_height) const {
  PDVO_THROW_CHECK(new_width > 0 && new_height > 0, InvalidArgument,
                   "camera rescale: size must be positive, got " << new_width << "x" << new_height);
  const double sx = static_cast<double>(new_width) / width, sy = static_cast<double>(new_height) / height;
  Camera c = *this;
  c.width = new_width;
  c.height = new_height;
  c.fx = fx * sx;
  c.fy = fy * sy;
  c.cx = (cx + 0.5) * sx - 0.5;
  c.cy = (cy + 0.5) * sy - 0.5;
  return c;
}

Camera Camera::Pinhole(int width, int height, double fx, double fy, double cx, double cy) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  c.Check("pinhole camera");
  return c;
}

Camera Camera::WithFieldOfView(int width, int height, double horizontal_fov_deg) {
  PDVO_THROW_CHECK(
      width > 0 && height > 0 && horizontal_fov_deg > 0 && horizontal_fov_deg < 180, InvalidArgument,
      "camera: a " << width << "x" << height << " image with a field of view of " << horizontal_fov_deg << " degrees");
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 0.5 * width / std::tan(0.5 * horizontal_fov_deg * (M_PI / 180));
  c.cx = (width - 1) / 2.0;
  c.cy = (height - 1) / 2.0;
  return c;
}

Undistorter::Undistorter(const Camera& camera) : camera_(camera) {
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.distortion.data()));
  cv::initUndistortRectifyMap(camera.K(), dist, cv::noArray(), camera.K(), cv::Size(camera.width, camera.height),
                              CV_16SC2, map1_, map2_);
}

cv::Mat Undistorter::Apply(const cv::Mat& image, int interpolation) const {
  PDVO_THROW_CHECK(image.cols == camera_.width && image.rows == camera_.height, InvalidArgument,
                   "undistort: image is " << image.cols << "x" << image.rows << " but the camera is " << camera_.width
                                          << "x" << camera_.height);
  cv::Mat out;
  cv::remap(image, out, map1_, map2_, interpolation, cv::BORDER_CONSTANT);
  return out;
}

}  // namespace pdvo
