#include "pdvo/train/onmf.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/test/topics.h"

namespace pdvo {
namespace {

TEST(Onmf, RecoversAKnownOrthogonalFactorisation) {
  const test::KnownTopics known(60, 5, 200, 3);
  OnmfOptions options;
  options.topics = 5;
  options.max_iterations = 3000;
  options.tolerance = 1e-10;
  const OnmfResult r = FactoriseOrthogonal(known.data, options);
  EXPECT_LT(r.errors.back(), 1e-3);
  EXPECT_LT(r.errors.back(), r.errors.front() / 100);  // the error falls
  // W^T W = I (unit columns, orthogonal).
  const Eigen::MatrixXd gram = r.basis.transpose() * r.basis;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(5, 5)).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GE(r.basis.minCoeff(), 0.0);
  EXPECT_GE(r.weights.minCoeff(), 0.0);
  // Each true topic is found, up to the order.
  for (int t = 0; t < 5; ++t) {
    const double best = (r.basis.transpose() * known.basis.col(t)).maxCoeff();
    EXPECT_GT(best, 0.999) << "topic " << t;
  }
}

TEST(Onmf, ErrorNeverRisesMuchAndSeedsRepeat) {
  const test::KnownTopics known(40, 4, 100, 5);
  OnmfOptions options;
  options.topics = 4;
  options.max_iterations = 300;
  options.tolerance = 0;
  const OnmfResult a = FactoriseOrthogonal(known.data, options), b = FactoriseOrthogonal(known.data, options);
  EXPECT_EQ(a.basis, b.basis);  // the same seed, the same result
  // Multiplicative updates on the manifold are not strictly monotone; they must not go back by more than a
  // sliver, and they must end far below where they started.
  for (size_t i = 1; i < a.errors.size(); ++i) EXPECT_LE(a.errors[i], a.errors[i - 1] * 1.01) << i;
  EXPECT_LT(a.errors.back(), 0.05 * a.errors.front());
}

TEST(Onmf, BadInputIsRejected) {
  OnmfOptions options;
  options.topics = 3;
  Eigen::MatrixXd x = Eigen::MatrixXd::Ones(10, 10);
  x(2, 3) = -1;
  EXPECT_THROW(FactoriseOrthogonal(x, options), InvalidArgument);
  options.topics = 20;
  EXPECT_THROW(FactoriseOrthogonal(Eigen::MatrixXd::Ones(10, 10), options), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
