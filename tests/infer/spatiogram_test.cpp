#include "pdvo/infer/spatiogram.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

TEST(Spatiogram, OneWordOneTopicGivesTheSampleMeanAndCovariance) {
  // Word 0 belongs to topic 0 only; topic 1 has no support in the region.
  Eigen::MatrixXd basis(2, 2);
  basis << 1, 0, 0, 1;
  const std::vector<cv::Point2f> points = {{10, 20}, {30, 20}, {30, 60}, {10, 60}, {20, 40}};
  const std::vector<int> words(points.size(), 0);
  const cv::Rect2d region(10, 20, 20, 40);  // corners (10, 20) and (30, 60)
  const Spatiogram s = ComputeSpatiogram(basis, words, points, region, Eigen::Vector2d(0.7, 0.3));
  // Normalised, the points are the box's corners and centre: mean 0, variance (4 * 1 + 0) / 5 on each axis.
  EXPECT_LT(s.means[0].norm(), 1e-12);
  EXPECT_NEAR(s.covariances[0](0, 0), 0.8, 1e-12);
  EXPECT_NEAR(s.covariances[0](1, 1), 0.8, 1e-12);
  EXPECT_NEAR(s.covariances[0](0, 1), 0.0, 1e-12);
  EXPECT_EQ(s.means[1], Eigen::Vector2d::Zero());
  EXPECT_EQ(s.covariances[1], Eigen::Matrix2d::Zero());
  const Eigen::VectorXd v = s.ToVector();
  ASSERT_EQ(v.size(), 12);
  EXPECT_DOUBLE_EQ(v[0], 0.7);
  EXPECT_DOUBLE_EQ(v[3], 0.8);
  EXPECT_DOUBLE_EQ(v[6], 0.3);
}

TEST(Spatiogram, WeightedByWordMembershipLikeABruteForceSum) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::MatrixXd basis = Eigen::MatrixXd::NullaryExpr(6, 3, [&]() { return u(rng); });
  std::vector<cv::Point2f> points;
  std::vector<int> words;
  for (int i = 0; i < 40; ++i) {
    points.emplace_back(static_cast<float>(100 + 50 * u(rng)), static_cast<float>(200 + 80 * u(rng)));
    words.push_back(static_cast<int>(rng() % 6));
  }
  const cv::Rect2d region(100, 200, 50, 80);
  const Spatiogram s = ComputeSpatiogram(basis, words, points, region, Eigen::Vector3d(1, 2, 3));
  for (int t = 0; t < 3; ++t) {
    // E[x x^T] - mean mean^T, by the one-pass formula, must equal the two-pass result.
    double m = 0;
    Eigen::Vector2d first = Eigen::Vector2d::Zero();
    Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d p((points[i].x - 125.0) / 25.0, (points[i].y - 240.0) / 40.0);
      const double w = basis(words[i], t);
      m += w;
      first += w * p;
      second += w * p * p.transpose();
    }
    const Eigen::Vector2d mean = first / m;
    EXPECT_LT((s.means[t] - mean).norm(), 1e-12);
    EXPECT_LT((s.covariances[t] - (second / m - mean * mean.transpose())).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(Spatiogram, BadInputIsRejected) {
  const Eigen::MatrixXd basis = Eigen::MatrixXd::Ones(3, 2);
  const cv::Rect2d region(0, 0, 10, 10);
  EXPECT_THROW(ComputeSpatiogram(basis, {0, 1}, {{1, 1}}, region, Eigen::Vector2d(1, 1)), InvalidArgument);
  EXPECT_THROW(ComputeSpatiogram(basis, {5}, {{1, 1}}, region, Eigen::Vector2d(1, 1)), InvalidArgument);
  EXPECT_THROW(ComputeSpatiogram(basis, {0}, {{1, 1}}, cv::Rect2d(0, 0, 0, 5), Eigen::Vector2d(1, 1)), InvalidArgument);
  EXPECT_THROW(ComputeSpatiogram(basis, {0}, {{1, 1}}, region, Eigen::Vector3d(1, 1, 1)), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
