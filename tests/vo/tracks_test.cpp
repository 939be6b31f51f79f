// Feature bookkeeping and frame preparation: features out of view leave the filter (what they mapped is kept,
// and a keyframe goes with its last feature's reference camera); features with a bad history leave; frames are
// undistorted, resized and converted to grey for the working camera, and frames of another size are refused.
#include "pdvo/vo/tracks.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277, 277, 159.5, 119.5);

TEST(Tracks, FeaturesOutOfViewLeave) {
  Filter filter(CameraState(), Matrix12d::Identity() * 1e-8);
  Tracks tracks;
  MapRecord record(4);
  const int first = filter.AddReference(true);
  tracks.keyframes[first] = {};
  const int in_view = filter.AddPoint(first, kCamera.Ray({160, 120}), 0.25, 0.01);  // known: mapped when it leaves
  const int near_border = filter.AddPoint(first, kCamera.Ray({315, 120}), 0.25, 0.01);
  tracks.points[in_view] = {{160, 120}, {}};
  tracks.points[near_border] = {{315, 120}, {}};
  const int second = filter.AddReference(true);
  tracks.keyframes[second] = {};
  const int alone = filter.AddPoint(second, kCamera.Ray({5, 5}), 0.25, 1.0);  // not known: not mapped
  tracks.points[alone] = {{5, 5}, {}};
  EXPECT_EQ(tracks.Visible(filter, kCamera, 10).size(), 1u);
  tracks.LeaveView(kCamera, 10, &filter, &record);
  EXPECT_EQ(filter.points().size(), 1u);
  EXPECT_TRUE(filter.points().count(in_view));
  EXPECT_EQ(tracks.points.size(), 1u);
  EXPECT_EQ(record.kept().points.size(), 1u);  // the known point near the border
  EXPECT_TRUE(tracks.keyframes.count(first));
  EXPECT_FALSE(tracks.keyframes.count(second));  // its reference camera left with its last point
  // A point missed more than max_misses times in a row leaves too.
  FeatureOptions options;
  tracks.points[in_view].history.misses = options.max_misses + 1;
  tracks.LeaveRejected(options, &filter, &record);
  EXPECT_TRUE(filter.points().empty());
  EXPECT_TRUE(tracks.keyframes.empty());
}

TEST(Tracks, HistoriesSayWhenAFeatureLeaves) {
  const FeatureOptions o;
  EXPECT_FALSE(Tracks::Gone({o.max_misses, 10, 0}, o));
  EXPECT_TRUE(Tracks::Gone({o.max_misses + 1, 10, 0}, o));
  EXPECT_FALSE(Tracks::Gone({0, 10, 4}, o));  // 4 of 10 rejected: not more than 0.4
  EXPECT_TRUE(Tracks::Gone({0, 10, 5}, o));
  EXPECT_FALSE(Tracks::Gone({0, 2, 2}, o));  // fewer than min_rejections
}

TEST(FramePreparer, MakesWorkingFramesForTheWorkingCamera) {
  Camera camera = Camera::Pinhole(640, 480, 520, 520, 319.5, 239.5);
  camera.distortion = {0.2, -0.5, 0, 0, 0};
  const FramePreparer preparer(camera, 320);
  const Camera& working = preparer.working_camera();
  EXPECT_FALSE(working.HasDistortion());
  EXPECT_EQ(working.width, 320);
  EXPECT_EQ(working.height, 240);
  EXPECT_DOUBLE_EQ(working.fx, 260);
  // A frame of a bright square on black: prepared, its centre stays bright and the corners dark.
  cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  frame(cv::Rect(280, 200, 80, 80)).setTo(cv::Scalar(200, 200, 200));
  const PreparedFrame p = preparer.Prepare(frame);
  EXPECT_EQ(p.grey.type(), CV_8UC1);
  EXPECT_EQ(p.grey.size(), cv::Size(320, 240));
  EXPECT_EQ(p.colour.type(), CV_8UC3);
  EXPECT_EQ(p.grey.at<uchar>(120, 160), 200);
  EXPECT_EQ(p.grey.at<uchar>(5, 5), 0);
  // Grey frames are taken too, and give the same grey image.
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(preparer.Prepare(grey).grey, p.grey, cv::NORM_INF), 0);
  EXPECT_THROW(preparer.Prepare(cv::Mat(240, 320, CV_8UC3)), InvalidArgument);
  EXPECT_THROW(preparer.Prepare(cv::Mat(480, 640, CV_32F)), InvalidArgument);
  // Without distortion and at the camera's width, frames pass unchanged but for the grey conversion.
  const FramePreparer same(kCamera, 0);
  cv::Mat texture(240, 320, CV_8U);
  cv::randu(texture, 0, 256);
  EXPECT_EQ(cv::norm(same.Prepare(texture).grey, texture, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace pdvo::vo
