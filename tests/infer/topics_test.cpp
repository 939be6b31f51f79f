#include "pdvo/infer/topics.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/test/topics.h"

namespace pdvo {
namespace {

TEST(Topics, ProjectionRecoversKnownWeights) {
  const test::KnownTopics known(60, 5, 20, 7);
  for (int region = 0; region < 20; ++region) {
    const Eigen::VectorXd h = ProjectOntoTopics(known.basis, known.data.col(region));
    EXPECT_LT((h - known.weights.col(region)).cwiseAbs().maxCoeff(), 1e-6) << region;
  }
  // Noise that no topic explains does not make weights negative.
  Eigen::VectorXd noisy = known.data.col(0);
  noisy(0) += 3;
  EXPECT_GE(ProjectOntoTopics(known.basis, noisy).minCoeff(), 0.0);
  EXPECT_THROW(ProjectOntoTopics(known.basis, Eigen::VectorXd::Ones(7)), InvalidArgument);
}

TEST(Topics, ManyRegionsAtOnceEqualOneByOne) {
  const test::KnownTopics known(60, 5, 20, 7);
  const Eigen::MatrixXd gram = known.basis.transpose() * known.basis;
  const Eigen::MatrixXd all = ProjectOntoTopics(known.basis, gram, known.data, 50);
  ASSERT_EQ(all.rows(), 5);
  ASSERT_EQ(all.cols(), 20);
  for (int region = 0; region < 20; ++region) {
    const Eigen::VectorXd one = ProjectOntoTopics(known.basis, known.data.col(region), 50);
    EXPECT_LT((all.col(region) - one).cwiseAbs().maxCoeff(), 1e-12 * (1 + one.cwiseAbs().maxCoeff())) << region;
  }
  EXPECT_EQ(ProjectOntoTopics(known.basis, gram, Eigen::MatrixXd(60, 0), 50).cols(), 0);
}

TEST(Topics, MatchesBruteForceNonNegativeLeastSquaresOnAnOverlappingBasis) {
  // Two overlapping topics: the constrained optimum, found by brute force over a fine grid, must agree.
  Eigen::MatrixXd basis(3, 2);
  basis << 1.0, 0.2, 0.5, 0.5, 0.0, 1.0;
  const Eigen::Vector3d x(0.2, 0.9, 1.5);
  const Eigen::VectorXd h = ProjectOntoTopics(basis, x, 5000);
  double best = 1e18;
  Eigen::Vector2d best_h;
  for (double a = 0; a <= 3; a += 0.002) {
    for (double b = 0; b <= 3; b += 0.002) {
      const double e = (x - basis * Eigen::Vector2d(a, b)).squaredNorm();
      if (e < best) best = e, best_h = Eigen::Vector2d(a, b);
    }
  }
  EXPECT_LT((h - best_h).cwiseAbs().maxCoeff(), 0.005);
}

}  // namespace
}  // namespace pdvo
