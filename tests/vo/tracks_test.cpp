// Feature bookkeeping and frame preparation: features out of view leave the filter (what they mapped is kept,
// and a keyframe goes with its last feature's reference camera), or wait (points up to max_waiting, detected
// planes) to be measured again when they come back into view; features with
// a bad history leave; frames are undistorted, resized and converted to grey for the working camera, and frames
// of another size are refused.
#include "pdvo/vo/tracks.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/map.h"

namespace pdvo::vo {
namespace {

const Camera kCamera = Camera::Pinhole(320, 240, 277, 277, 159.5, 119.5);

// A filter at rest with one reference camera (fixed) and its keyframe; more references with AddKeyframe.
struct Scene {
  Filter filter{CameraState(), Matrix12d::Identity() * 1e-8};
  Tracks tracks;
  MapRecord record{4};
  int reference = AddKeyframe();
  int AddKeyframe() {
    const int id = filter.AddReference(true);
    tracks.keyframes[id] = {};
    return id;
  }
};

TEST(Tracks, FeaturesOutOfViewLeave) {
  Scene scene;
  auto& [filter, tracks, record, first] = scene;
  const int in_view = filter.AddPoint(first, kCamera.Ray({160, 120}), 0.25, 0.01);  // known: mapped when it leaves
  const int near_border = filter.AddPoint(first, kCamera.Ray({315, 120}), 0.25, 0.01);
  tracks.points[in_view] = {{160, 120}, {}};
  tracks.points[near_border] = {{315, 120}, {}};
  const int second = scene.AddKeyframe();
  const int alone = filter.AddPoint(second, kCamera.Ray({5, 5}), 0.25, 1.0);  // not known: not mapped
  tracks.points[alone] = {{5, 5}, {}};
  EXPECT_EQ(tracks.Visible(filter, kCamera, 10).size(), 1u);
  FeatureOptions leave_at_once;
  leave_at_once.max_waiting = 0;
  tracks.LeaveView(kCamera, leave_at_once, &filter, &record);
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

TEST(Tracks, PointsOutOfViewWaitUpToMaxWaitingAndComeBack) {
  Scene scene;
  auto& [filter, tracks, record, reference] = scene;
  auto point = [&](const Eigen::Vector2d& pixel, const Eigen::Vector3d& ray) {
    const int id = filter.AddPoint(reference, ray, 0.25, 0.01);
    tracks.points[id] = {pixel, {}};
    return id;
  };
  // Three points just right of the view (x 330-334 of 320), oldest first, and one behind the camera.
  std::vector<int> right;
  for (int k = 0; k < 3; ++k) right.push_back(point({330.0 + 2 * k, 120}, kCamera.Ray({330.0 + 2 * k, 120})));
  const int behind = point({160, 120}, -kCamera.Ray({160, 120}));
  FeatureOptions options;
  options.max_waiting = 2;
  tracks.LeaveView(kCamera, options, &filter, &record);
  EXPECT_FALSE(filter.points().count(behind));    // behind the camera: leaves at once
  EXPECT_FALSE(filter.points().count(right[0]));  // the oldest beyond max_waiting
  EXPECT_TRUE(filter.points().count(right[1]) && filter.points().count(right[2]));
  EXPECT_TRUE(tracks.Visible(filter, kCamera, options.border).empty());  // waiting, not in view
  // The camera turns right by 0.11 rad (about 30 px): the waiting points are in view again, and stay.
  Eigen::VectorXd turn = Eigen::VectorXd::Zero(filter.size());
  turn[4] = 0.11;
  filter.Apply(turn);
  EXPECT_EQ(tracks.Visible(filter, kCamera, options.border).size(), 2u);
  tracks.LeaveView(kCamera, options, &filter, &record);
  EXPECT_EQ(filter.points().size(), 2u);
}

TEST(Tracks, DetectedPlanesOutOfViewWaitBlindOnesLeave) {
  Scene scene;
  auto& [filter, tracks, record, reference] = scene;
  // Planes 5 m ahead whose members the camera sees only at the left border: out of view.
  auto plane = [&](bool detected, int members) {
    const int id = filter.AddPlane(reference, {Eigen::Vector3d(0, 0, -1), 0.2}, 0.1, 0.01);
    PlaneTrack& t = tracks.planes[id];
    t.detected = detected;
    for (int k = 0; k < members; ++k) {
      const Eigen::Vector2d pixel(4, 20 + 20 * k);
      t.members.push_back({pixel, kCamera.Ray(pixel), {}});
    }
    return id;
  };
  const int blind = plane(false, 5), small = plane(true, 3);
  std::vector<int> waiting;
  for (int k = 0; k < kMaxOutOfViewPlanes + 1; ++k) waiting.push_back(plane(true, 4));
  tracks.LeaveView(kCamera, FeatureOptions{}, &filter, &record);
  EXPECT_FALSE(filter.planes().count(blind));       // a blind seed leaves, as before
  EXPECT_FALSE(filter.planes().count(small));       // fewer than min_plane_points: no plane to carry on
  EXPECT_FALSE(filter.planes().count(waiting[0]));  // the oldest beyond kMaxOutOfViewPlanes
  for (size_t k = 1; k < waiting.size(); ++k) {
    ASSERT_TRUE(filter.planes().count(waiting[k]));
    EXPECT_TRUE(tracks.planes.at(waiting[k]).out_of_view);
  }
  EXPECT_EQ(record.kept().planes.size(), 2u);  // the blind plane and the oldest waiting one, mapped
  EXPECT_EQ(record.stats().planes, 1 + static_cast<int>(waiting.size()));  // all with 4 points, waiting or not
  // A waiting plane whose points come back into view measures again.
  PlanePoint& back = tracks.planes.at(waiting[1]).members[0];
  back.keyframe_pixel = {160, 120};
  back.ray = kCamera.Ray(back.keyframe_pixel);
  tracks.LeaveView(kCamera, FeatureOptions{}, &filter, &record);
  EXPECT_FALSE(tracks.planes.at(waiting[1]).out_of_view);
  tracks.RemoveOutOfView(&filter, &record);
  EXPECT_EQ(filter.planes().size(), 1u);
  EXPECT_EQ(record.kept().planes.size(), 5u);  // and the three still waiting
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
