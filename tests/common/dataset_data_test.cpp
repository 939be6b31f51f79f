// Reads the real data sets in ../shared/data as they are. Labelled `data`; skips when they are absent.
#include <gtest/gtest.h>

#include "pdvo/common/dataset.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

TEST(DatasetData, TumFr1RpyExcerpt) {
  PDVO_REQUIRE_DATA(path, "tum_rgbd_fr1_rpy_excerpt");
  auto seq = OpenSequence(path);
  EXPECT_EQ(seq->size(), 100u);
  Frame f;
  size_t n = 0, with_gt = 0;
  while (seq->Next(&f)) {
    ++n;
    EXPECT_EQ(f.image.size(), cv::Size(640, 480));
    ASSERT_EQ(f.depth.type(), CV_32F);
    with_gt += f.world_from_cam.has_value();
    if (n == 1) {
      // The README: 78 % valid pixels, median 0.91 m on the first frame.
      cv::Mat valid = f.depth > 0;
      EXPECT_NEAR(cv::countNonZero(valid) / double(640 * 480), 0.78, 0.02);
      std::vector<float> d;
      for (int y = 0; y < 480; ++y)
        for (int x = 0; x < 640; ++x)
          if (f.depth.at<float>(y, x) > 0) d.push_back(f.depth.at<float>(y, x));
      std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
      EXPECT_NEAR(d[d.size() / 2], 0.91, 0.02);
    }
  }
  EXPECT_EQ(n, 100u);
  EXPECT_EQ(with_gt, 100u);  // the nearest pose is within 4 ms of every image
}

TEST(DatasetData, TumFr3LongOffice1Hz) {
  PDVO_REQUIRE_DATA(path, "tum_rgbd_fr3_long_office_1hz");
  auto seq = OpenSequence(path);
  Frame f;
  size_t n = 0, with_gt = 0;
  while (seq->Next(&f)) {
    ++n;
    EXPECT_TRUE(f.depth.empty());
    with_gt += f.world_from_cam.has_value();
  }
  EXPECT_EQ(n, 17u);
  EXPECT_EQ(with_gt, 16u);  // the first image is 67 ms before the first pose
}

TEST(DatasetData, KittiOdometry06Excerpt) {
  PDVO_REQUIRE_DATA(path, "kitti_odometry_06_excerpt");
  auto seq = OpenSequence(path);
  ASSERT_TRUE(seq->camera().has_value());
  EXPECT_EQ(seq->camera()->width, 1226);
  EXPECT_EQ(seq->camera()->height, 370);
  EXPECT_NEAR(seq->camera()->fx, 707.0912, 1e-9);
  Frame f;
  Trajectory gt;
  while (seq->Next(&f)) {
    ASSERT_TRUE(f.world_from_cam.has_value());
    gt.push_back({f.timestamp, *f.world_from_cam});
  }
  EXPECT_EQ(gt.size(), 51u);
  EXPECT_NEAR(gt[1].timestamp, 0.1044989, 1e-9);
  EXPECT_NEAR(PathLength(gt), 60.0, 5.0);  // "about 60 m of driving"
}

}  // namespace
}  // namespace pdvo
