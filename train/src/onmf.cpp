#include "pdvo/train/onmf.h"

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo {

bool OnmfOptions::Check() const {
  PDVO_CHECK_OPTION(topics >= 1);
  PDVO_CHECK_OPTION(max_iterations >= 1);
  PDVO_CHECK_OPTION(tolerance >= 0);
  return true;
}

OnmfResult FactoriseOrthogonal(const Eigen::MatrixXd& x, const OnmfOptions& options) {
  CheckOptionsOrThrow(options, "ONMF options");
  PDVO_THROW_CHECK(x.size() > 0 && x.allFinite() && x.minCoeff() >= 0, InvalidArgument,
                   "ONMF: the data must be non-empty, finite and non-negative");
  PDVO_THROW_CHECK(options.topics <= x.rows() && options.topics <= x.cols(), InvalidArgument,
                   "ONMF: " << options.topics << " topics for " << x.rows() << " words and " << x.cols() << " regions");
  constexpr double kEpsilon = 1e-12;
  const int k = options.topics;
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  OnmfResult r;
  r.basis = Eigen::MatrixXd::NullaryExpr(x.rows(), k, [&]() { return u(rng); });
  r.weights = Eigen::MatrixXd::NullaryExpr(k, x.cols(), [&]() { return u(rng); });
  const double norm = x.norm();
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it < options.max_iterations; ++it) {
    // W <- W .* (X H^T) ./ (W H X^T W): the Stiefel-manifold gradient keeps W's columns orthogonal.
    const Eigen::MatrixXd xht = x * r.weights.transpose();
    const Eigen::MatrixXd denominator_w = r.basis * (r.weights * (x.transpose() * r.basis));
    r.basis = r.basis.cwiseProduct(xht).cwiseQuotient(denominator_w.cwiseMax(kEpsilon));
    // H <- H .* (W^T X) ./ (W^T W H)
    const Eigen::MatrixXd wtx = r.basis.transpose() * x;
    const Eigen::MatrixXd denominator_h = (r.basis.transpose() * r.basis) * r.weights;
    r.weights = r.weights.cwiseProduct(wtx).cwiseQuotient(denominator_h.cwiseMax(kEpsilon));
    const double error = (x - r.basis * r.weights).norm() / norm;
    r.errors.push_back(error);
    if (std::abs(previous - error) <= options.tolerance * std::max(error, kEpsilon)) break;
    previous = error;
  }
  // Unit columns for W, the scale moved into H.
  for (int t = 0; t < k; ++t) {
    const double n = r.basis.col(t).norm();
    if (n <= 0) continue;
    r.basis.col(t) /= n;
    r.weights.row(t) *= n;
  }
  return r;
}

}  // namespace pdvo
