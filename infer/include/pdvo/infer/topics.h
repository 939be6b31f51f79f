// Topic weights of a new region: the non-negative projection of its visual-word histogram onto a learned topic
// basis (from orthogonal NMF, train/onmf.h). The paper's section III, after Haines & Calway.
#pragma once

#include <Eigen/Core>

namespace pdvo {

// The non-negative h minimising |histogram - basis * h|^2 (basis: words x topics, non-negative), by
// multiplicative updates started from max(basis^T histogram, 0) + epsilon. `iterations` bounds the work.
Eigen::VectorXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::VectorXd& histogram, int iterations = 200);
// The same for each column of `histograms` (words x regions) at once, with the basis's Gram matrix basis^T basis
// given: one column of topic weights per region.
Eigen::MatrixXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::MatrixXd& gram,
                                  const Eigen::MatrixXd& histograms, int iterations);

}  // namespace pdvo
