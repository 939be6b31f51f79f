#include "pdvo/eval/recognition.h"

#include <gtest/gtest.h>

#include <random>

namespace pdvo {
namespace {

TEST(Recognition, ConfusionAndRatesOfAKnownCase) {
  // 6 planes: 4 called plane; 4 non-planes: 1 called plane.
  std::vector<RecognitionSample> s;
  for (double p : {0.9, 0.8, 0.7, 0.6, 0.4, 0.1}) s.push_back({true, p, std::nullopt, {0, 0, -1}});
  for (double p : {0.55, 0.3, 0.2, 0.05}) s.push_back({false, p, std::nullopt, {0, 0, -1}});
  const RecognitionMetrics m = ComputeRecognitionMetrics(s);
  EXPECT_EQ(m.confusion[0][0], 4);
  EXPECT_EQ(m.confusion[0][1], 2);
  EXPECT_EQ(m.confusion[1][0], 1);
  EXPECT_EQ(m.confusion[1][1], 3);
  EXPECT_DOUBLE_EQ(m.accuracy, 0.7);
  EXPECT_DOUBLE_EQ(m.recall, 4.0 / 6);
  EXPECT_DOUBLE_EQ(m.precision, 4.0 / 5);
  EXPECT_DOUBLE_EQ(m.balanced_accuracy, (4.0 / 6 + 3.0 / 4) / 2);
  // Pairs (plane, non-plane) ordered correctly: 0.9,0.8,0.7,0.6 beat all 4 (16); 0.4 beats 3; 0.1 beats 1.
  EXPECT_DOUBLE_EQ(m.roc_auc, 20.0 / 24);
}

TEST(Recognition, RocAucMatchesBruteForcePairCounting) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> level(0, 9);  // coarse scores: many ties
  std::vector<double> scores;
  std::vector<bool> positive;
  for (int i = 0; i < 300; ++i) {
    positive.push_back(i % 3 == 0);
    scores.push_back(level(rng) + (positive.back() ? 2 : 0));
  }
  double wins = 0, pairs = 0;
  for (size_t i = 0; i < scores.size(); ++i) {
    for (size_t j = 0; j < scores.size(); ++j) {
      if (!positive[i] || positive[j]) continue;
      ++pairs;
      wins += scores[i] > scores[j] ? 1.0 : scores[i] == scores[j] ? 0.5 : 0.0;
    }
  }
  EXPECT_NEAR(RocAuc(scores, positive), wins / pairs, 1e-12);
  EXPECT_DOUBLE_EQ(RocAuc({0.1, 0.2}, {true, true}), 0.5);
}

TEST(Recognition, NormalErrorsOverPlanesWithReferenceNormals) {
  std::vector<RecognitionSample> s;
  const Eigen::Vector3d truth(0, 0, -1);
  for (int deg : {0, 10, 20, 30, 40, 50, 60, 70, 80, 90}) {
    const double r = deg * M_PI / 180;
    s.push_back({true, 0.9, truth, Eigen::Vector3d(std::sin(r), 0, -std::cos(r))});
  }
  s.push_back({true, 0.9, std::nullopt, Eigen::Vector3d(1, 0, 0)});  // no reference: not counted
  s.push_back({false, 0.1, truth, Eigen::Vector3d(1, 0, 0)});        // non-plane: not counted
  const RecognitionMetrics m = ComputeRecognitionMetrics(s);
  EXPECT_EQ(m.normals, 10);
  EXPECT_NEAR(m.normal_mean, 45, 1e-9);
  EXPECT_NEAR(m.normal_median, 50, 1e-9);
  EXPECT_NEAR(m.normal_p90, 90, 1e-9);
  EXPECT_NEAR(AngleDegrees({1, 0, 0}, {-1, 0, 0}), 180, 1e-12);
  EXPECT_NEAR(AngleDegrees({1, 0, 0}, {1, 1e-9, 0}), 0, 1e-6);
}

}  // namespace
}  // namespace pdvo
