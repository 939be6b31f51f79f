// A small plane model for the model and learner tests: 12 gradient words, 5 colour words, 3 topics, the words'
// plane log-odds and a feature standardisation, all random; no classifiers or regressors yet.
#pragma once

#include <opencv2/core.hpp>
#include <random>

#include "pdvo/infer/model.h"
#include "pdvo/infer/recogniser.h"

namespace pdvo::test {

inline PlaneModel RandomModelWithoutLearners(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  cv::Mat g(12, kGradientDims, CV_32F), c(5, kColourDims, CV_32F);
  cv::randu(g, 0, 100);
  cv::randu(c, 0, 1);
  PlaneModel m;
  m.gradient_words = Vocabulary(g);
  m.colour_words = Vocabulary(c);
  m.topics = Eigen::MatrixXd::NullaryExpr(17, 3, [&]() { return u(rng); });
  const int dims = RegionFeatureDims(3);
  m.feature_mean = Eigen::VectorXd::NullaryExpr(dims, [&]() { return u(rng); });
  m.feature_scale = Eigen::VectorXd::NullaryExpr(dims, [&]() { return 0.5 + u(rng); });
  std::mt19937 own(5);  // the caller's draws stay as they were before the word log-odds
  m.word_plane_log_odds = Eigen::VectorXd::NullaryExpr(17, [&]() { return 4 * u(own) - 2; });
  return m;
}

}  // namespace pdvo::test
