// The homography warp on real images: the Oxford graffiti pair (a painted wall seen from two viewpoints about
// 40 degrees apart) with its ground-truth homography. Patches of graf1 warped by it must match graf3 where
// the unwarped patches do not.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/test/support.h"
#include "pdvo/vo/patch.h"

namespace pdvo::vo {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(PatchData, GroundTruthHomographyWarpMatchesGraf3) {
  PDVO_REQUIRE_DATA(dir, "oxford_graf_pair");
  const cv::Mat graf1 = cv::imread(dir + "/graf1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat graf3 = cv::imread(dir + "/graf3.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(graf1.empty());
  ASSERT_FALSE(graf3.empty());
  cv::FileStorage fs(dir + "/H1to3p.xml", cv::FileStorage::READ);
  cv::Mat h_cv;
  fs["H13"] >> h_cv;
  ASSERT_EQ(h_cv.size(), cv::Size(3, 3));
  Eigen::Matrix3d h;
  cv::cv2eigen(h_cv, h);

  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(graf1, corners, 300, 0.01, 10);
  constexpr int kHalf = 7;
  std::vector<double> warped_ncc, plain_ncc;
  for (const cv::Point2f& c : corners) {
    const Eigen::Vector2d in3 = (h * Eigen::Vector3d(c.x, c.y, 1)).hnormalized();
    const cv::Rect window(cvRound(in3.x()) - kHalf, cvRound(in3.y()) - kHalf, 2 * kHalf + 1, 2 * kHalf + 1);
    const cv::Rect source(cvRound(c.x) - kHalf, cvRound(c.y) - kHalf, 2 * kHalf + 1, 2 * kHalf + 1);
    if ((window & cv::Rect(0, 0, graf3.cols, graf3.rows)) != window) continue;
    if ((source & cv::Rect(0, 0, graf1.cols, graf1.rows)) != source) continue;
    cv::Mat predicted;
    if (!WarpPatch(graf1, h, Eigen::Vector2d(window.x + kHalf, window.y + kHalf), kHalf, &predicted)) continue;
    warped_ncc.push_back(Ncc(predicted, graf3(window)));
    plain_ncc.push_back(Ncc(graf1(source), graf3(window)));
  }
  ASSERT_GT(warped_ncc.size(), 100u);
  const double warped = Median(warped_ncc), plain = Median(plain_ncc);
  RecordProperty("median_ncc_warped", std::to_string(warped));
  RecordProperty("median_ncc_unwarped", std::to_string(plain));
  EXPECT_GT(warped, 0.85) << "unwarped " << plain;
  EXPECT_LT(plain, warped - 0.2) << "warped " << warped;
}

}  // namespace
}  // namespace pdvo::vo
