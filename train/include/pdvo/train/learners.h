// The classifiers and regressors the trainer can make (LearnerKind), behind one interface: the settings to
// cross-validate, and training on rows of standardised features.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pdvo/infer/model.h"
#include "pdvo/train/trainer.h"

namespace pdvo::internal {

// One setting of a learner: the RBF width (already divided by the feature dimensions) and, by kind, the SVM's
// C, kNN's k or the trees' depth.
struct LearnerSetting {
  double gamma = 0;
  double c = 0;  // 0: not an SVM
  int k = 0;
  int depth = 0;
  std::string Describe(double dims) const;  // "gamma 0.2/D", "gamma 0.2/D, C 10", "k 15", "depth 8"
};

// Every setting cross-validation tries for the options' learner, in order.
std::vector<LearnerSetting> Settings(const TrainOptions& options, double dims);

// `labels`: +1 plane, -1 not. The result gives the plane probability.
Learned TrainClassifier(const TrainOptions& options, const LearnerSetting& setting, const Eigen::MatrixXd& x,
                        const std::vector<double>& labels);
Learned TrainRegressor(const TrainOptions& options, const LearnerSetting& setting, const Eigen::MatrixXd& x,
                       const Eigen::VectorXd& targets);

// Platt's sigmoid p = 1 / (1 + exp(a f + b)) fitted to decision values `f` and labels (+1 / -1) by Newton's
// method, with Platt's smoothed targets (Lin, Lin & Weng 2007 for the method's numerics).
void FitPlatt(const std::vector<double>& f, const std::vector<double>& labels, double* a, double* b);

}  // namespace pdvo::internal
