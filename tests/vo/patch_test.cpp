// Patch warping and NCC on generated images: a pure shift gives the reference's pixels exactly, a general
// homography agrees with OpenCV's warpPerspective, and NCC is invariant to gain and offset.
#include "pdvo/vo/patch.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"

namespace pdvo::vo {
namespace {

cv::Mat Texture() {
  cv::Mat noise(240, 320, CV_8U), smooth;
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

TEST(Patch, IntegerShiftCopiesTheReference) {
  const cv::Mat image = Texture();
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  h(0, 2) = 3;
  h(1, 2) = -2;
  cv::Mat patch;
  ASSERT_TRUE(WarpPatch(image, h, Eigen::Vector2d(103, 48), 5, &patch));
  ASSERT_EQ(patch.size(), cv::Size(11, 11));
  cv::Mat expected;
  image(cv::Rect(100 - 5, 50 - 5, 11, 11)).convertTo(expected, CV_32F);
  EXPECT_EQ(cv::norm(patch, expected, cv::NORM_INF), 0);
}

TEST(Patch, AgreesWithWarpPerspective) {
  const cv::Mat image = Texture();
  Eigen::Matrix3d h;
  h << 0.9, 0.15, 12, -0.1, 1.05, 4, 2e-4, -1e-4, 1;
  cv::Mat h_cv(3, 3, CV_64F), warped;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) h_cv.at<double>(r, c) = h(r, c);
  cv::warpPerspective(image, warped, h_cv, image.size(), cv::INTER_LINEAR);
  cv::Mat patch, expected;
  ASSERT_TRUE(WarpPatch(image, h, Eigen::Vector2d(150, 110), 7, &patch));
  warped(cv::Rect(150 - 7, 110 - 7, 15, 15)).convertTo(expected, CV_32F);
  // OpenCV interpolates in fixed point (1/32 px, 8-bit result): within a grey level or so.
  EXPECT_LT(cv::norm(patch, expected, cv::NORM_INF), 2.0);
  EXPECT_GT(Ncc(patch, expected), 0.999);
}

TEST(Patch, OutsideOrSingularGivesNoPatch) {
  const cv::Mat image = Texture();
  cv::Mat patch(1, 1, CV_32F, cv::Scalar(42));
  EXPECT_FALSE(WarpPatch(image, Eigen::Matrix3d::Identity(), Eigen::Vector2d(3, 100), 5, &patch));
  EXPECT_FALSE(WarpPatch(image, Eigen::Matrix3d::Zero(), Eigen::Vector2d(100, 100), 5, &patch));
  EXPECT_EQ(patch.at<float>(0, 0), 42);  // untouched
  EXPECT_THROW(WarpPatch(cv::Mat(10, 10, CV_8UC3), Eigen::Matrix3d::Identity(), Eigen::Vector2d(5, 5), 1, &patch),
               InvalidArgument);
}

TEST(Patch, NccIsInvariantToGainAndOffset) {
  const cv::Mat image = Texture();
  const cv::Mat a = image(cv::Rect(40, 40, 9, 9));
  cv::Mat brighter, negative;
  a.convertTo(brighter, CV_32F, 0.5, 30);
  a.convertTo(negative, CV_32F, -1, 255);
  EXPECT_NEAR(Ncc(a, a), 1, 1e-12);
  EXPECT_NEAR(Ncc(a, brighter), 1, 1e-6);
  EXPECT_NEAR(Ncc(a, negative), -1, 1e-6);
  EXPECT_LT(std::abs(Ncc(a, image(cv::Rect(200, 150, 9, 9)))), 0.9);  // elsewhere in the texture
  EXPECT_EQ(Ncc(a, cv::Mat(9, 9, CV_8U, cv::Scalar(5))), 0);          // flat
  EXPECT_THROW(Ncc(a, image(cv::Rect(0, 0, 5, 5))), InvalidArgument);
}

// SearchPatch against known shifts: an integer shift is found exactly, sub-pixel shifts closer than the nearest
// whole pixel would be (on average over fractions of 0.1 to 0.9 px); a match far outside the search ellipse is not
// found; a patch of another texture is not found (no score reaches min_ncc).
TEST(SearchPatch, FindsKnownShifts) {
  const cv::Mat image = Texture();
  const Eigen::Vector2d centre(150, 110);
  cv::Mat patch;
  ASSERT_TRUE(WarpPatch(image, Eigen::Matrix3d::Identity(), centre, 5, &patch));
  const SearchOptions options;
  const Eigen::Matrix2d s = 9 * Eigen::Matrix2d::Identity();  // 3 px sigma: the ellipse reaches 9 px
  auto find = [&](const Eigen::Vector2d& shift, Eigen::Vector2d* found) {
    cv::Mat moved;
    cv::warpAffine(image, moved, cv::Matx23d(1, 0, shift.x(), 0, 1, shift.y()), image.size(), cv::INTER_CUBIC);
    return SearchPatch(moved, patch, centre, s, options, found);
  };
  Eigen::Vector2d found;
  ASSERT_TRUE(find({3, -2}, &found));
  EXPECT_LT((found - (centre + Eigen::Vector2d(3, -2))).norm(), 0.05);  // measured 0.035: the neighbours differ
  double subpixel = 0, whole = 0;
  int n = 0;
  for (double f = 0.1; f < 0.95; f += 0.1, ++n) {
    const Eigen::Vector2d shift(2 + f, -1 - f);
    ASSERT_TRUE(find(shift, &found)) << f;
    subpixel += (found - (centre + shift)).norm();
    whole += (shift.array().round() - shift.array()).matrix().norm();
  }
  // Measured: 0.16 px mean error against 0.39 px for the nearest whole pixel (the parabola is biased towards
  // the whole pixel on a texture this smooth).
  EXPECT_LT(subpixel / n, 0.7 * whole / n);
  EXPECT_LT(subpixel / n, 0.25);
  RecordProperty("mean_subpixel_error_px", std::to_string(subpixel / n));
  RecordProperty("mean_whole_pixel_error_px", std::to_string(whole / n));
  // Predicted 8 px from the match with a 0.5 px sigma: the ellipse (1.5 px) does not reach it.
  EXPECT_FALSE(
      SearchPatch(image, patch, centre + Eigen::Vector2d(8, 0), 0.25 * Eigen::Matrix2d::Identity(), options, &found));
  cv::Mat other(image.size(), CV_8U);
  cv::RNG rng(99);
  rng.fill(other, cv::RNG::UNIFORM, 0, 256);
  EXPECT_FALSE(SearchPatch(other, patch, centre, s, options, &found));
}

// SearchPatch scores by direct sums inside the ellipse only; a brute-force reference scores the whole window with
// OpenCV's matchTemplate (TM_CCOEFF_NORMED) and keeps the best inside the ellipse, with the same sub-pixel step.
// On random patches, predictions and elongated ellipses (near the border too), both find the same match, to float
// rounding, or both none.
TEST(SearchPatch, EqualsAnExhaustiveMatchTemplateSearch) {
  const cv::Mat image = Texture();
  SearchOptions options;
  options.min_ncc = 0.5;  // more matches to compare
  const int half = options.patch_half;
  auto reference = [&](const cv::Mat& patch, const Eigen::Vector2d& predicted, const Eigen::Matrix2d& s,
                       Eigen::Vector2d* found) {
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s).eigenvalues().maxCoeff();
    const int radius =
        std::min(static_cast<int>(std::ceil(options.search_sigmas * std::sqrt(largest))), options.max_search_radius);
    const cv::Point c(cvRound(predicted.x()), cvRound(predicted.y()));
    const cv::Rect window =
        cv::Rect(c.x - radius - half, c.y - radius - half, 2 * (radius + half) + 1, 2 * (radius + half) + 1) &
        cv::Rect(0, 0, image.cols, image.rows);
    cv::Mat region, score;
    image(window).convertTo(region, CV_32F);
    cv::matchTemplate(region, patch, score, cv::TM_CCOEFF_NORMED);
    double best = -2;
    cv::Point at;
    for (int y = 0; y < score.rows; ++y) {
      for (int x = 0; x < score.cols; ++x) {
        const Eigen::Vector2d d(window.x + x + half - predicted.x(), window.y + y + half - predicted.y());
        if (d.dot(s.inverse() * d) > options.search_sigmas * options.search_sigmas || score.at<float>(y, x) <= best)
          continue;
        best = score.at<float>(y, x);
        at = cv::Point(x, y);
      }
    }
    if (best < options.min_ncc) return false;
    auto offset = [](double l, double c, double r) {
      const double curvature = l - 2 * c + r;
      return curvature < 0 ? std::clamp(0.5 * (l - r) / curvature, -0.5, 0.5) : 0.0;
    };
    const double dx = at.x > 0 && at.x + 1 < score.cols
                          ? offset(score.at<float>(at.y, at.x - 1), best, score.at<float>(at.y, at.x + 1))
                          : 0;
    const double dy = at.y > 0 && at.y + 1 < score.rows
                          ? offset(score.at<float>(at.y - 1, at.x), best, score.at<float>(at.y + 1, at.x))
                          : 0;
    *found = Eigen::Vector2d(window.x + at.x + half + dx, window.y + at.y + half + dy);
    return true;
  };
  cv::RNG rng(3);
  int compared = 0, matched = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector2d source(rng.uniform(8.0, 312.0), rng.uniform(8.0, 232.0));
    cv::Mat patch;
    if (!WarpPatch(image, Eigen::Matrix3d::Identity(), source, half, &patch)) continue;
    const Eigen::Vector2d predicted = source + Eigen::Vector2d(rng.uniform(-6.0, 6.0), rng.uniform(-6.0, 6.0));
    const double angle = rng.uniform(0.0, M_PI), major = rng.uniform(0.5, 6.0), minor = rng.uniform(0.3, 2.0);
    const Eigen::Matrix2d r = Eigen::Rotation2Dd(angle).toRotationMatrix();
    const Eigen::Matrix2d s = r * Eigen::Vector2d(major * major, minor * minor).asDiagonal() * r.transpose();
    Eigen::Vector2d direct, brute;
    const bool a = SearchPatch(image, patch, predicted, s, options, &direct);
    const bool b = reference(patch, predicted, s, &brute);
    ASSERT_EQ(a, b) << "trial " << trial;
    ++compared;
    if (!a) continue;
    ++matched;
    EXPECT_LT((direct - brute).norm(), 1e-3) << "trial " << trial;
  }
  EXPECT_GT(compared, 250);
  EXPECT_GT(matched, 100);
  RecordProperty("matches_compared", std::to_string(matched));
}

// However uncertain the prediction (a huge, infinite or NaN covariance), the window is at most
// max_search_radius: a match farther away is not found, and nothing overflows.
TEST(SearchPatch, TheWindowIsBounded) {
  const cv::Mat image = Texture();
  cv::Mat patch;
  ASSERT_TRUE(WarpPatch(image, Eigen::Matrix3d::Identity(), Eigen::Vector2d(160, 120), 5, &patch));
  SearchOptions options;
  options.max_search_radius = 15;
  Eigen::Vector2d found;
  const Eigen::Matrix2d huge = 1e12 * Eigen::Matrix2d::Identity();
  EXPECT_TRUE(SearchPatch(image, patch, Eigen::Vector2d(172, 120), huge, options, &found));
  EXPECT_LT((found - Eigen::Vector2d(160, 120)).norm(), 0.1);
  EXPECT_FALSE(SearchPatch(image, patch, Eigen::Vector2d(180, 120), huge, options, &found));
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix2d infinite = inf * Eigen::Matrix2d::Identity(), unknown = nan * Eigen::Matrix2d::Identity();
  EXPECT_NO_THROW(SearchPatch(image, patch, Eigen::Vector2d(160, 120), infinite, options, &found));
  EXPECT_NO_THROW(SearchPatch(image, patch, Eigen::Vector2d(160, 120), unknown, options, &found));
  EXPECT_FALSE(SearchPatch(image, patch, Eigen::Vector2d(1e300, 120), Eigen::Matrix2d::Identity(), options, &found));
}

}  // namespace
}  // namespace pdvo::vo
