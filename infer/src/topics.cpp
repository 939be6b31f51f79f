#include "pdvo/infer/topics.h"

#include "pdvo/common/errors.h"

namespace pdvo {

Eigen::VectorXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::VectorXd& histogram, int iterations) {
  return ProjectOntoTopics(basis, Eigen::MatrixXd(basis.transpose() * basis), histogram, iterations);
}

Eigen::VectorXd ProjectOntoTopics(const Eigen::MatrixXd& basis, const Eigen::MatrixXd& gram,
                                  const Eigen::VectorXd& histogram, int iterations) {
  PDVO_THROW_CHECK(gram.rows() == basis.cols() && gram.cols() == basis.cols(), InvalidArgument,
                   "topic projection: a Gram matrix of the wrong size");
  PDVO_THROW_CHECK(
      basis.rows() == histogram.size(), InvalidArgument,
      "topic projection: the basis has " << basis.rows() << " words but the histogram " << histogram.size());
  PDVO_THROW_CHECK(basis.minCoeff() >= 0 && histogram.minCoeff() >= 0, InvalidArgument,
                   "topic projection: basis and histogram must be non-negative");
  constexpr double kEpsilon = 1e-12;
  const Eigen::VectorXd numerator = basis.transpose() * histogram;  // W^T x
  Eigen::VectorXd h = numerator.cwiseMax(0.0).array() + 1e-6;
  for (int k = 0; k < iterations; ++k) {
    h = h.cwiseProduct(numerator).cwiseQuotient((gram * h).array().max(kEpsilon).matrix());
  }
  return h;
}

}  // namespace pdvo
