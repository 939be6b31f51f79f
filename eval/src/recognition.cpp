#include "pdvo/eval/recognition.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace pdvo {

double AngleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

double RocAuc(const std::vector<double>& scores, const std::vector<bool>& positive) {
  const size_t n = scores.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return scores[a] < scores[b]; });
  // Mid-ranks (1-based) with ties averaged; AUC = (sum of positive ranks - P(P+1)/2) / (P N).
  double positive_rank_sum = 0;
  size_t positives = 0;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && scores[order[j]] == scores[order[i]]) ++j;
    const double rank = (i + 1 + j) / 2.0;
    for (size_t k = i; k < j; ++k) {
      if (positive[order[k]]) positive_rank_sum += rank, ++positives;
    }
    i = j;
  }
  const size_t negatives = n - positives;
  if (positives == 0 || negatives == 0) return 0.5;
  return (positive_rank_sum - positives * (positives + 1) / 2.0) / (static_cast<double>(positives) * negatives);
}

RecognitionMetrics ComputeRecognitionMetrics(const std::vector<RecognitionSample>& samples, double threshold) {
  RecognitionMetrics m;
  m.regions = static_cast<int>(samples.size());
  std::vector<double> scores;
  std::vector<bool> positive;
  std::vector<double> angles;
  for (const RecognitionSample& s : samples) {
    const bool called_plane = s.probability >= threshold;
    ++m.confusion[s.planar ? 0 : 1][called_plane ? 0 : 1];
    scores.push_back(s.probability);
    positive.push_back(s.planar);
    if (s.planar && s.true_normal) angles.push_back(AngleDegrees(*s.true_normal, s.normal));
  }
  const int tp = m.confusion[0][0], fn = m.confusion[0][1], fp = m.confusion[1][0], tn = m.confusion[1][1];
  auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  m.accuracy = ratio(tp + tn, m.regions);
  m.recall = ratio(tp, tp + fn);
  m.precision = ratio(tp, tp + fp);
  const double specificity = ratio(tn, tn + fp);
  const bool both = tp + fn > 0 && tn + fp > 0;
  m.balanced_accuracy = both ? (m.recall + specificity) / 2 : (tp + fn > 0 ? m.recall : specificity);
  m.roc_auc = RocAuc(scores, positive);
  m.normals = static_cast<int>(angles.size());
  if (!angles.empty()) {
    std::sort(angles.begin(), angles.end());
    m.normal_mean = std::accumulate(angles.begin(), angles.end(), 0.0) / angles.size();
    auto quantile = [&](double q) {
      return angles[std::min(angles.size() - 1, static_cast<size_t>(q * angles.size()))];
    };
    m.normal_median = quantile(0.5);
    m.normal_p90 = quantile(0.9);
  }
  return m;
}

nlohmann::json ToJson(const RecognitionMetrics& m) {
  return {{"regions", m.regions},
          {"accuracy", m.accuracy},
          {"balanced_accuracy", m.balanced_accuracy},
          {"precision", m.precision},
          {"recall", m.recall},
          {"roc_auc", m.roc_auc},
          {"confusion",
           {{"rows", "truth plane, non-plane"},
            {"columns", "predicted plane, non-plane"},
            {"matrix", {{m.confusion[0][0], m.confusion[0][1]}, {m.confusion[1][0], m.confusion[1][1]}}}}},
          {"normal_error_deg",
           {{"regions", m.normals}, {"mean", m.normal_mean}, {"median", m.normal_median}, {"p90", m.normal_p90}}}};
}

}  // namespace pdvo
