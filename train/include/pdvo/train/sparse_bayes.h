// Sparse Bayesian (relevance vector) regression by Tipping & Faul's fast marginal likelihood maximisation
// ("Fast marginal likelihood maximisation for sparse Bayesian models", AISTATS 2003), with an RBF kernel.
//
// dlib has an RVM regression trainer too (used as the reference in the tests), but its stopping test compares
// the hyperparameters alpha in absolute terms, and alpha of weakly relevant vectors runs to large values: on
// this project's region features it did not finish within minutes for 300 samples. Here each iteration picks
// the single add / re-estimate / delete step that raises the marginal likelihood most, the noise precision is
// re-estimated every few steps, and training stops when the best step gains less than a tolerance (or after
// a bounded number of steps).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pdvo/infer/model.h"

namespace pdvo {

struct SparseBayesOptions {
  double gamma = 1;           // RBF kernel exp(-gamma |x - y|^2)
  int max_iterations = 1000;  // add / re-estimate / delete steps
  double tolerance = 1e-6;    // stop when the best step raises the log marginal likelihood by less
};

// Rows of `x` are samples. The result predicts t(x) = sum_i w_i k(x, v_i) - bias (bias: a constant basis).
RvmFunction TrainSparseBayesRegression(const Eigen::MatrixXd& x, const Eigen::VectorXd& targets,
                                       const SparseBayesOptions& options);

}  // namespace pdvo
