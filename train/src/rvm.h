// dlib's RVM classifier trainer (Tipping & Faul's fast marginal likelihood maximisation) with an RBF kernel,
// returning the project's RvmFunction. Private to the train library. (Regression: sparse_bayes.h.)
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pdvo/infer/model.h"

namespace pdvo::internal {

// Rows of `x` are samples; `labels` are +1 / -1. The result's output is the logit of P(label = +1).
RvmFunction TrainRvmClassifier(const Eigen::MatrixXd& x, const std::vector<double>& labels, double gamma,
                               double epsilon, int max_iterations);

}  // namespace pdvo::internal
