// The recogniser's learners (RVM, SVM, kNN, random trees) on generated data: each classifier beats chance by a
// wide margin on held-out rows and gives probabilities, each regressor follows a smooth target, Platt's sigmoid
// recovers a known one, and a model of each kind goes through the file byte for byte with the same predictions.
#include "pdvo/train/learners.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"
#include "pdvo/infer/recogniser.h"
#include "pdvo/infer/topics.h"
#include "pdvo/test/models.h"

namespace pdvo {
namespace {

constexpr LearnerKind kKinds[] = {LearnerKind::kRvm, LearnerKind::kSvm, LearnerKind::kKnn, LearnerKind::kTrees};

// Two classes as two Gaussian clouds whose means differ by 2 in each of the first three dimensions (the best
// possible accuracy is about 0.96), in alternation.
void Clouds(int n, int dims, unsigned seed, Eigen::MatrixXd* x, std::vector<double>* labels) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  *x = Eigen::MatrixXd::NullaryExpr(n, dims, [&]() { return g(rng); });
  labels->clear();
  for (int i = 0; i < n; ++i) {
    labels->push_back(i % 2 ? 1.0 : -1.0);
    x->row(i).head(3).array() += i % 2 ? 1.0 : -1.0;
  }
}

TrainOptions OptionsFor(LearnerKind kind) {
  TrainOptions o;
  o.classifier = kind;
  return o;
}

TEST(Learners, EachClassifierBeatsChanceByAWideMargin) {
  Eigen::MatrixXd train, test;
  std::vector<double> train_labels, test_labels;
  Clouds(400, 10, 1, &train, &train_labels);
  Clouds(400, 10, 2, &test, &test_labels);
  for (LearnerKind kind : kKinds) {
    SCOPED_TRACE(OptionName(kind));
    const TrainOptions o = OptionsFor(kind);
    const std::vector<internal::LearnerSetting> settings = internal::Settings(o, 10);
    ASSERT_FALSE(settings.empty());
    const Learned f = internal::TrainClassifier(o, settings.front(), train, train_labels);
    EXPECT_EQ(f.kind, kind);
    EXPECT_GT(f.size, 0);
    const Eigen::VectorXd p = f.Evaluate(test);
    int right = 0;
    for (int i = 0; i < 400; ++i) {
      EXPECT_GE(p[i], 0.0);
      EXPECT_LE(p[i], 1.0);
      right += (p[i] >= 0.5) == (test_labels[i] > 0);
    }
    EXPECT_GT(right / 400.0, 0.85);  // chance: 0.5
    // One row alone gives what the batch gives it.
    EXPECT_NEAR(f(test.row(7).transpose()), p[7], 1e-9);
  }
}

TEST(Learners, EachRegressorFollowsASmoothTarget) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  const auto target = [](const Eigen::RowVectorXd& r) { return std::sin(r[0]) + 0.5 * r[1]; };
  const Eigen::MatrixXd train = Eigen::MatrixXd::NullaryExpr(300, 4, [&]() { return g(rng); });
  const Eigen::MatrixXd test = Eigen::MatrixXd::NullaryExpr(200, 4, [&]() { return g(rng); });
  Eigen::VectorXd t(300), truth(200);
  for (int i = 0; i < 300; ++i) t[i] = target(train.row(i));
  for (int i = 0; i < 200; ++i) truth[i] = target(test.row(i));
  const double variance = (truth.array() - truth.mean()).square().mean();
  for (LearnerKind kind : kKinds) {
    SCOPED_TRACE(OptionName(kind));
    const TrainOptions o = OptionsFor(kind);
    const Learned f = internal::TrainRegressor(o, internal::Settings(o, 4).front(), train, t);
    const double mse = (f.Evaluate(test) - truth).array().square().mean();
    EXPECT_LT(mse, 0.3 * variance);  // explains over 70% of the variance on rows it never saw
  }
}

TEST(Learners, PlattRecoversAKnownSigmoid) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> f, labels;
  for (int i = 0; i < 20000; ++i) {
    const double v = 6 * u(rng) - 3;
    f.push_back(v);
    labels.push_back(u(rng) < 1 / (1 + std::exp(-2 * v + 0.5)) ? 1.0 : -1.0);  // a = -2, b = 0.5
  }
  double a = 0, b = 0;
  internal::FitPlatt(f, labels, &a, &b);
  EXPECT_NEAR(a, -2.0, 0.1);
  EXPECT_NEAR(b, 0.5, 0.1);
}

// A model whose classifiers and regressors are all of `kind`, trained on generated rows of its feature size.
PlaneModel ModelOf(LearnerKind kind) {
  std::mt19937 rng(5);
  PlaneModel m = test::RandomModelWithoutLearners(rng);
  const int dims = RegionFeatureDims(3);
  m.feature_mean = Eigen::VectorXd::Zero(dims);
  m.feature_scale = Eigen::VectorXd::Ones(dims);
  Eigen::MatrixXd x;
  std::vector<double> labels;
  Clouds(120, dims, 6, &x, &labels);
  const TrainOptions o = OptionsFor(kind);
  const internal::LearnerSetting s = internal::Settings(o, dims).back();
  for (int k = 0; k < 2; ++k) m.classifiers.push_back(internal::TrainClassifier(o, s, x, labels));
  for (int k = 0; k < 3; ++k) {
    m.normal[k] = internal::TrainRegressor(o, s, x, x.col(k) * (k == 2 ? -1.0 : 0.3));
  }
  return m;
}

TEST(Learners, AModelOfEachKindRoundTripsByteForByte) {
  for (LearnerKind kind : kKinds) {
    SCOPED_TRACE(OptionName(kind));
    const PlaneModel m = ModelOf(kind);
    const std::string yaml = m.ToYaml();
    EXPECT_NE(yaml.find("learner: " + OptionName(kind)), std::string::npos);
    const PlaneModel back = PlaneModel::FromYaml(yaml, "m.yml");
    EXPECT_EQ(back.learner(), kind);
    EXPECT_EQ(back.ToYaml(), yaml);
    ASSERT_EQ(back.classifiers.size(), 2u);
    EXPECT_EQ(back.classifiers[1].size, m.classifiers[1].size);
    std::mt19937 rng(7);
    std::normal_distribution<double> g(0, 1);
    const Eigen::MatrixXd rows = Eigen::MatrixXd::NullaryExpr(20, m.feature_mean.size(), [&]() { return g(rng); });
    const std::vector<RegionPrediction> a = Recogniser(m).PredictRows(rows), b = Recogniser(back).PredictRows(rows);
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a[i].plane_probability, b[i].plane_probability, 1e-6);
      EXPECT_LT((a[i].normal - b[i].normal).norm(), 1e-5);
    }
    // A classifier of another kind in the file is refused, naming it.
    if (kind != LearnerKind::kRvm) {
      std::string other = yaml;
      const std::string first = "kind: " + OptionName(kind);
      other.replace(other.find(first), first.size(), kind == LearnerKind::kSvm ? "kind: knn" : "kind: svm");
      EXPECT_THROW(PlaneModel::FromYaml(other, "m.yml"), FormatError);
    }
  }
}

}  // namespace
}  // namespace pdvo
