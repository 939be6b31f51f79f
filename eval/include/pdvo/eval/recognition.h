// Region recognition metrics: plane / non-plane classification (accuracy, balanced accuracy, precision and
// recall of "plane", ROC AUC, confusion matrix) and normal errors (angles, in degrees).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

namespace pdvo {

struct RecognitionSample {
  bool planar = false;                                 // the truth
  double probability = 0;                              // predicted plane probability
  std::optional<Eigen::Vector3d> true_normal;          // planes with a reference normal
  Eigen::Vector3d normal = Eigen::Vector3d(0, 0, -1);  // predicted
};

struct RecognitionMetrics {
  int regions = 0;
  double accuracy = 0, balanced_accuracy = 0, precision = 0, recall = 0, roc_auc = 0;
  int confusion[2][2] = {{0, 0}, {0, 0}};                     // [truth: plane, non-plane][predicted: plane, non-plane]
  int normals = 0;                                            // planes with a reference normal
  double normal_mean = 0, normal_median = 0, normal_p90 = 0;  // degrees
};

// Angle between two directions in degrees (0 to 180).
double AngleDegrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// Area under the ROC curve by the rank statistic (ties count half); 0.5 if one class is absent.
double RocAuc(const std::vector<double>& scores, const std::vector<bool>& positive);

// Classified as plane when probability >= threshold. Precision is 0 when nothing is called plane.
RecognitionMetrics ComputeRecognitionMetrics(const std::vector<RecognitionSample>& samples, double threshold = 0.5);

nlohmann::json ToJson(const RecognitionMetrics& metrics);

}  // namespace pdvo
