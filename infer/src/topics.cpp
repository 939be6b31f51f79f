#include "pdvo/infer/topics.h"

#include "pdvo/common/errors.h"

namespace pdvo {

Eigen::VectorXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::VectorXd& histogram, int iterations) {
  return ProjectOntoTopics(basis, basis.transpose() * basis, histogram, iterations).col(0);
}

Eigen::MatrixXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::MatrixXd& gram,
                                  const Eigen::MatrixXd& histograms, int iterations) {
  PDVO_THROW_CHECK(gram.rows() == basis.cols() && gram.cols() == basis.cols(), InvalidArgument,
                   "topic projection: a Gram matrix of the wrong size");
  PDVO_THROW_CHECK(
      basis.rows() == histograms.rows(), InvalidArgument,
      "topic projection: the basis has " << basis.rows() << " words but the histogram " << histograms.rows());
  PDVO_THROW_CHECK(basis.minCoeff() >= 0 && (histograms.size() == 0 || histograms.minCoeff() >= 0), InvalidArgument,
                   "topic projection: basis and histogram must be non-negative");
  constexpr double kEpsilon = 1e-12;
  const Eigen::MatrixXd numerator = basis.transpose() * histograms;  // W^T x
  Eigen::MatrixXd h = numerator.cwiseMax(0.0).array() + 1e-6;
  Eigen::MatrixXd denominator(h.rows(), h.cols());  // W^T W h, allocated once
  for (int k = 0; k < iterations; ++k) {
    denominator.noalias() = gram * h;
    h.array() = h.array() * numerator.array() / denominator.array().max(kEpsilon);
  }
  return h;
}

}  // namespace pdvo
