// Frame preparation for the visual odometry: a camera's images undistorted, resized to the working width and
// converted to 8-bit grey, with the camera that sees them (no distortion, at the working size). `pdvo vo`,
// vo_bench and any program that links pdvo_vo prepare frames here, so that the same images give the same
// trajectory.
#pragma once

#include <opencv2/core.hpp>
#include <optional>

#include "pdvo/common/camera.h"

namespace pdvo::vo {

struct PreparedFrame {
  cv::Mat colour;  // CV_8UC3 (BGR) at the working size, undistorted (for overlays); grey input gives grey-as-BGR
  cv::Mat grey;    // CV_8UC1 at the working size, undistorted: what Odometry::Track takes
};

class FramePreparer {
 public:
  // `camera`: the images' camera (any distortion, their full size). `working_width` in px: the width frames
  // are resized to (0: the camera's own; the height keeps the aspect ratio, rounded).
  FramePreparer(const Camera& camera, int working_width);

  // The camera of the prepared frames: camera.Undistorted() rescaled to the working size.
  const Camera& working_camera() const { return working_; }

  // Undistorts (bilinear), resizes (area averaging when shrinking, bilinear when growing) and converts to grey
  // (OpenCV's BGR weights). `image`: 8-bit BGR or grey, of the camera's size; throws InvalidArgument otherwise.
  PreparedFrame Prepare(const cv::Mat& image) const;

 private:
  Camera camera_, working_;
  std::optional<Undistorter> undistorter_;  // none without distortion
};

}  // namespace pdvo::vo
