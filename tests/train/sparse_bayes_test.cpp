#include "pdvo/train/sparse_bayes.h"

#include <gtest/gtest.h>

#include <dlib/svm.h>
#include <cmath>
#include <random>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

double Sinc(double v) { return v == 0 ? 1 : std::sin(v) / v; }

// Tipping's classic example: noisy samples of sinc on [-10, 10].
void SincData(int n, double noise, unsigned seed, Eigen::MatrixXd* x, Eigen::VectorXd* t) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10, 10);
  std::normal_distribution<double> g(0, noise);
  x->resize(n, 1);
  t->resize(n);
  for (int i = 0; i < n; ++i) {
    (*x)(i, 0) = u(rng);
    (*t)[i] = Sinc((*x)(i, 0)) + g(rng);
  }
}

TEST(SparseBayes, RecoversSincSparselyFromNoisySamples) {
  Eigen::MatrixXd x;
  Eigen::VectorXd t;
  SincData(200, 0.1, 1, &x, &t);
  const RvmFunction f = TrainSparseBayesRegression(x, t, {0.2, 1000, 1e-6});
  double se = 0;
  int count = 0;
  for (double v = -9.5; v <= 9.5; v += 0.05, ++count) se += std::pow(f(Eigen::VectorXd::Constant(1, v)) - Sinc(v), 2);
  const double rmse = std::sqrt(se / count);
  EXPECT_LT(rmse, 0.05) << "the noise is 0.1";
  EXPECT_LT(f.size(), 20) << "sparse: few relevance vectors for 200 samples";
  EXPECT_GE(f.size(), 4);
}

TEST(SparseBayes, AgreesWithDlibsRvmRegression) {
  // dlib's trainer (the reference) on a problem small enough for its stopping test.
  Eigen::MatrixXd x;
  Eigen::VectorXd t;
  SincData(60, 0.05, 4, &x, &t);
  using Sample = dlib::matrix<double, 1, 1>;
  using Kernel = dlib::radial_basis_kernel<Sample>;
  std::vector<Sample> samples(60);
  std::vector<double> targets(t.data(), t.data() + 60);
  for (int i = 0; i < 60; ++i) samples[i](0) = x(i, 0);
  dlib::rvm_regression_trainer<Kernel> trainer;
  trainer.set_kernel(Kernel(0.2));
  const auto reference = trainer.train(samples, targets);
  const RvmFunction f = TrainSparseBayesRegression(x, t, {0.2, 1000, 1e-6});
  double worst = 0;
  for (double v = -9.5; v <= 9.5; v += 0.1) {
    Sample s;
    s(0) = v;
    worst = std::max(worst, std::abs(reference(s) - f(Eigen::VectorXd::Constant(1, v))));
  }
  EXPECT_LT(worst, 0.05);
}

TEST(SparseBayes, ConstantTargetsAndBadInput) {
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(20, 3);
  const RvmFunction f = TrainSparseBayesRegression(x, Eigen::VectorXd::Constant(20, 0.7), {0.5, 100, 1e-6});
  EXPECT_NEAR(f(Eigen::VectorXd::Zero(3)), 0.7, 1e-3);
  EXPECT_THROW(TrainSparseBayesRegression(x, Eigen::VectorXd::Zero(19), {}), InvalidArgument);
  x(3, 1) = std::nan("");
  EXPECT_THROW(TrainSparseBayesRegression(x, Eigen::VectorXd::Zero(20), {}), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
