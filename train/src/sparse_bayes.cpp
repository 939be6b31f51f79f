#include "pdvo/train/sparse_bayes.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "pdvo/common/errors.h"

namespace pdvo {

RvmFunction TrainSparseBayesRegression(const Eigen::MatrixXd& x, const Eigen::VectorXd& t,
                                       const SparseBayesOptions& o) {
  const Eigen::Index n = x.rows();
  PDVO_THROW_CHECK(n >= 2 && t.size() == n && o.gamma > 0 && o.max_iterations >= 1, InvalidArgument,
                   "sparse Bayesian regression: need at least 2 samples, one target each, gamma > 0");
  PDVO_THROW_CHECK(x.allFinite() && t.allFinite(), InvalidArgument, "sparse Bayesian regression: NaN in the data");
  // Basis: one RBF column per sample, then a constant column (the bias).
  const Eigen::Index m_all = n + 1;
  Eigen::MatrixXd phi(n, m_all);
  const Eigen::VectorXd norms = x.rowwise().squaredNorm();
  phi.leftCols(n) =
      (-o.gamma * ((norms.replicate(1, n) + norms.transpose().replicate(n, 1)) - 2 * x * x.transpose()).cwiseMax(0.0))
          .array()
          .exp()
          .matrix();
  phi.col(n).setOnes();
  const Eigen::MatrixXd gram = phi.transpose() * phi;
  const Eigen::VectorXd phi_t = phi.transpose() * t;
  const double t_var = (t.array() - t.mean()).square().mean();
  double beta = 1.0 / std::max(0.1 * t_var, 1e-12);

  std::vector<Eigen::Index> active;
  std::vector<double> alpha;
  {
    Eigen::Index best = n;
    double best_score = -1;
    for (Eigen::Index j = 0; j < m_all; ++j) {
      const double score = phi_t[j] * phi_t[j] / gram(j, j);
      if (score > best_score) best_score = score, best = j;
    }
    active.push_back(best);
    alpha.push_back(gram(best, best) / std::max(best_score - 1.0 / beta, 1e-12));
  }
  Eigen::MatrixXd sigma;
  Eigen::VectorXd mu;
  auto posterior = [&]() {
    const Eigen::Index m = static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd h(m, m);
    Eigen::VectorXd b(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index j = 0; j < m; ++j) h(i, j) = beta * gram(active[i], active[j]);
      h(i, i) += alpha[i];
      b[i] = phi_t[active[i]];
    }
    sigma = h.llt().solve(Eigen::MatrixXd::Identity(m, m));
    mu = beta * sigma * b;
  };
  auto update_noise = [&]() {
    Eigen::VectorXd fit = Eigen::VectorXd::Zero(n);
    double well_determined = 0;
    for (size_t i = 0; i < active.size(); ++i) {
      fit += mu[i] * phi.col(active[i]);
      well_determined += 1 - alpha[i] * sigma(i, i);
    }
    const double residual = (t - fit).squaredNorm();
    beta = std::max(n - well_determined, 1e-6) / std::max(residual, 1e-12 * n);
  };

  for (int it = 0; it < o.max_iterations; ++it) {
    posterior();
    if (it % 5 == 4) {
      update_noise();
      posterior();
    }
    const Eigen::Index m = static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd cross(m_all, m);  // gram columns of the active bases
    for (Eigen::Index i = 0; i < m; ++i) cross.col(i) = gram.col(active[i]);
    const Eigen::VectorXd s_all =
        beta * gram.diagonal() - beta * beta * (cross * sigma).cwiseProduct(cross).rowwise().sum();
    const Eigen::VectorXd q_all = beta * phi_t - beta * cross * mu;
    std::vector<Eigen::Index> slot(m_all, -1);
    for (Eigen::Index i = 0; i < m; ++i) slot[active[i]] = i;

    double best_gain = 0;
    Eigen::Index best = -1;
    double best_alpha = 0;
    for (Eigen::Index j = 0; j < m_all; ++j) {
      const double S = s_all[j], Q = q_all[j];
      const Eigen::Index k = slot[j];
      const double s = k < 0 ? S : alpha[k] * S / (alpha[k] - S);
      const double q = k < 0 ? Q : alpha[k] * Q / (alpha[k] - S);
      const double theta = q * q - s;
      double gain = 0, new_alpha = 0;
      if (theta > 0 && k < 0) {
        new_alpha = s * s / theta;
        gain = (Q * Q - S) / S + std::log(S / (Q * Q));
      } else if (theta > 0) {
        new_alpha = s * s / theta;
        const double delta = 1 / new_alpha - 1 / alpha[k];
        gain = Q * Q / (S + 1 / delta) - std::log(1 + S * delta);
      } else if (k >= 0 && m > 1) {
        new_alpha = std::numeric_limits<double>::infinity();
        gain = Q * Q / (S - alpha[k]) - std::log(1 - S / alpha[k]);
      }
      if (std::isfinite(gain) && gain > best_gain) best_gain = gain, best = j, best_alpha = new_alpha;
    }
    if (best < 0 || best_gain < o.tolerance) break;
    const Eigen::Index k = slot[best];
    if (k < 0) {
      active.push_back(best);
      alpha.push_back(best_alpha);
    } else if (std::isinf(best_alpha)) {
      active.erase(active.begin() + k);
      alpha.erase(alpha.begin() + k);
    } else {
      alpha[k] = best_alpha;
    }
  }
  posterior();

  RvmFunction f;
  f.gamma = o.gamma;
  f.bias = 0;
  std::vector<Eigen::Index> vectors;
  std::vector<double> weights;
  for (size_t i = 0; i < active.size(); ++i) {
    if (active[i] == n) {
      f.bias = -mu[i];
    } else {
      vectors.push_back(active[i]);
      weights.push_back(mu[i]);
    }
  }
  f.weights = Eigen::Map<const Eigen::VectorXd>(weights.data(), static_cast<Eigen::Index>(weights.size()));
  f.vectors.resize(static_cast<Eigen::Index>(vectors.size()), x.cols());
  for (size_t i = 0; i < vectors.size(); ++i) f.vectors.row(i) = x.row(vectors[i]);
  return f;
}

}  // namespace pdvo
