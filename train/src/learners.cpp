#include "pdvo/train/learners.h"

#include <cmath>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/train/sparse_bayes.h"
#include "rvm.h"

namespace pdvo::internal {
namespace {

cv::Mat FloatRows(const Eigen::MatrixXd& x) {
  cv::Mat m, out;
  cv::eigen2cv(x, m);
  m.convertTo(out, CV_32F);
  return out;
}

cv::Ptr<cv::ml::SVM> Svm(int type, const LearnerSetting& s, double epsilon) {
  cv::Ptr<cv::ml::SVM> svm = cv::ml::SVM::create();
  svm->setType(type);
  svm->setKernel(cv::ml::SVM::RBF);
  svm->setGamma(s.gamma);
  svm->setC(s.c);
  svm->setP(epsilon);
  svm->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER + cv::TermCriteria::EPS, 100000, 1e-6));
  return svm;
}

cv::Ptr<cv::ml::RTrees> Trees(const TreesOptions& o, const LearnerSetting& s) {
  cv::Ptr<cv::ml::RTrees> trees = cv::ml::RTrees::create();
  trees->setMaxDepth(s.depth);
  trees->setMinSampleCount(o.min_samples);
  trees->setCVFolds(0);
  trees->setUseSurrogates(false);
  trees->setCalculateVarImportance(false);
  trees->setRegressionAccuracy(0);
  trees->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, o.trees, 0));
  return trees;
}

// log(1 + exp(z)) without overflow.
double Softplus(double z) { return z > 0 ? z + std::log1p(std::exp(-z)) : std::log1p(std::exp(z)); }

}  // namespace

std::string LearnerSetting::Describe(double dims) const {
  std::ostringstream out;
  if (k > 0) {
    out << "k " << k;
  } else if (depth > 0) {
    out << "depth " << depth;
  } else {
    out << "gamma " << gamma * dims << "/D";
    if (c > 0) out << ", C " << c;
  }
  return out.str();
}

std::vector<LearnerSetting> Settings(const TrainOptions& o, double dims) {
  std::vector<LearnerSetting> out;
  switch (o.classifier) {
    case LearnerKind::kRvm:
      for (double g : o.rvm.gammas) out.push_back({g / dims, 0, 0, 0});
      break;
    case LearnerKind::kSvm:
      for (double g : o.svm.gammas) {
        for (double c : o.svm.c) out.push_back({g / dims, c, 0, 0});
      }
      break;
    case LearnerKind::kKnn:
      for (double k : o.knn.k) out.push_back({0, 0, static_cast<int>(k), 0});
      break;
    case LearnerKind::kTrees:
      for (double d : o.trees.max_depth) out.push_back({0, 0, 0, static_cast<int>(d)});
      break;
  }
  return out;
}

Learned TrainClassifier(const TrainOptions& o, const LearnerSetting& s, const Eigen::MatrixXd& x,
                        const std::vector<double>& labels) {
  if (o.classifier == LearnerKind::kRvm) {
    return Learned::Rvm(TrainRvmClassifier(x, labels, s.gamma, o.rvm.epsilon, o.rvm.max_iterations), true);
  }
  Learned f;
  f.kind = o.classifier;
  f.classifier = true;
  const cv::Mat samples = FloatRows(x);
  cv::Mat classes(samples.rows, 1, CV_32S), zero_one(samples.rows, 1, CV_32F);
  for (int i = 0; i < samples.rows; ++i) {
    classes.at<int>(i) = labels[i] > 0 ? 1 : 0;
    zero_one.at<float>(i) = labels[i] > 0 ? 1.0f : 0.0f;
  }
  if (o.classifier == LearnerKind::kSvm) {
    cv::Ptr<cv::ml::SVM> svm = Svm(cv::ml::SVM::C_SVC, s, o.svm.epsilon);
    svm->train(samples, cv::ml::ROW_SAMPLE, classes);
    cv::Mat raw;
    svm->predict(samples, raw, cv::ml::StatModel::RAW_OUTPUT);
    std::vector<double> values(raw.begin<float>(), raw.end<float>());
    FitPlatt(values, labels, &f.platt_a, &f.platt_b);
    f.size = svm->getSupportVectors().rows;
    f.ml = svm;
  } else if (o.classifier == LearnerKind::kKnn) {
    cv::Ptr<cv::ml::KNearest> knn = cv::ml::KNearest::create();
    knn->setDefaultK(s.k);
    knn->setIsClassifier(true);
    knn->train(samples, cv::ml::ROW_SAMPLE, zero_one);
    f.size = samples.rows;
    f.ml = knn;
  } else {
    cv::Ptr<cv::ml::RTrees> trees = Trees(o.trees, s);
    trees->train(cv::ml::TrainData::create(samples, cv::ml::ROW_SAMPLE, classes));
    f.size = static_cast<int>(trees->getNodes().size());
    f.ml = trees;
  }
  return f;
}

Learned TrainRegressor(const TrainOptions& o, const LearnerSetting& s, const Eigen::MatrixXd& x,
                       const Eigen::VectorXd& targets) {
  if (o.classifier == LearnerKind::kRvm) {
    return Learned::Rvm(TrainSparseBayesRegression(x, targets, {s.gamma, o.rvm.max_iterations, 1e-6}), false);
  }
  Learned f;
  f.kind = o.classifier;
  f.classifier = false;
  const cv::Mat samples = FloatRows(x);
  cv::Mat t;
  cv::eigen2cv(targets, t);
  t.convertTo(t, CV_32F);
  if (o.classifier == LearnerKind::kSvm) {
    cv::Ptr<cv::ml::SVM> svm = Svm(cv::ml::SVM::EPS_SVR, s, o.svm.epsilon);
    svm->train(samples, cv::ml::ROW_SAMPLE, t);
    f.size = svm->getSupportVectors().rows;
    f.ml = svm;
  } else if (o.classifier == LearnerKind::kKnn) {
    cv::Ptr<cv::ml::KNearest> knn = cv::ml::KNearest::create();
    knn->setDefaultK(std::min(s.k, samples.rows));
    knn->setIsClassifier(false);
    knn->train(samples, cv::ml::ROW_SAMPLE, t);
    f.size = samples.rows;
    f.ml = knn;
  } else {
    cv::Ptr<cv::ml::RTrees> trees = Trees(o.trees, s);
    trees->train(cv::ml::TrainData::create(samples, cv::ml::ROW_SAMPLE, t));
    f.size = static_cast<int>(trees->getNodes().size());
    f.ml = trees;
  }
  return f;
}

void FitPlatt(const std::vector<double>& f, const std::vector<double>& labels, double* a, double* b) {
  double positives = 0;
  for (double y : labels) positives += y > 0;
  const double negatives = static_cast<double>(labels.size()) - positives;
  const double high = (positives + 1) / (positives + 2), low = 1 / (negatives + 2);
  std::vector<double> t(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) t[i] = labels[i] > 0 ? high : low;
  // The negative log-likelihood of p_i = 1 / (1 + exp(z_i)), z_i = a f_i + b: sum t_i z_i + log(1 + exp(-z_i)).
  auto loss = [&](double a_, double b_) {
    double sum = 0;
    for (size_t i = 0; i < f.size(); ++i) {
      const double z = a_ * f[i] + b_;
      sum += t[i] * z + Softplus(-z);
    }
    return sum;
  };
  *a = 0;
  *b = std::log((negatives + 1) / (positives + 1));
  double current = loss(*a, *b);
  for (int iteration = 0; iteration < 100; ++iteration) {
    double ga = 0, gb = 0, haa = 1e-12, hab = 0, hbb = 1e-12;
    for (size_t i = 0; i < f.size(); ++i) {
      const double z = *a * f[i] + *b;
      const double p = 1 / (1 + std::exp(z));  // the probability of a plane
      const double g = t[i] - p, h = p * (1 - p);
      ga += g * f[i];
      gb += g;
      haa += h * f[i] * f[i];
      hab += h * f[i];
      hbb += h;
    }
    if (std::abs(ga) < 1e-9 && std::abs(gb) < 1e-9) break;
    const double det = haa * hbb - hab * hab;
    const double da = -(hbb * ga - hab * gb) / det, db = -(-hab * ga + haa * gb) / det;
    double step = 1;
    while (step > 1e-10 && loss(*a + step * da, *b + step * db) >= current) step /= 2;
    if (step <= 1e-10) break;
    *a += step * da;
    *b += step * db;
    current = loss(*a, *b);
  }
}

}  // namespace pdvo::internal
