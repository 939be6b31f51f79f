#include "pdvo/vo/frames.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"

namespace pdvo::vo {

FramePreparer::FramePreparer(const Camera& camera, int working_width) : camera_(camera) {
  camera.Check("frame preparation");
  PDVO_THROW_CHECK(working_width >= 0, InvalidArgument, "frame preparation: negative working width");
  const int width = working_width > 0 ? working_width : camera.width;
  const int height = static_cast<int>(std::lround(camera.height * static_cast<double>(width) / camera.width));
  PDVO_THROW_CHECK(height >= 1, InvalidArgument,
                   "frame preparation: a " << camera.width << "x" << camera.height << " camera at " << width
                                           << " px wide has no rows");
  working_ = camera.Undistorted().Rescaled(width, height);
  if (camera.HasDistortion()) undistorter_.emplace(camera);
}

PreparedFrame FramePreparer::Prepare(const cv::Mat& image) const {
  PDVO_THROW_CHECK(image.depth() == CV_8U && (image.channels() == 3 || image.channels() == 1), InvalidArgument,
                   "frame preparation: frames must be 8-bit BGR or grey");
  PDVO_THROW_CHECK(image.cols == camera_.width && image.rows == camera_.height, InvalidArgument,
                   "frame preparation: the frame is " << image.cols << "x" << image.rows << ", the camera is "
                                                      << camera_.width << "x" << camera_.height);
  cv::Mat colour = image;
  if (image.channels() == 1) cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  if (undistorter_) colour = undistorter_->Apply(colour);
  PreparedFrame out;
  cv::resize(colour, out.colour, cv::Size(working_.width, working_.height), 0, 0,
             working_.width < camera_.width ? cv::INTER_AREA : cv::INTER_LINEAR);
  cv::cvtColor(out.colour, out.grey, cv::COLOR_BGR2GRAY);
  return out;
}

}  // namespace pdvo::vo
