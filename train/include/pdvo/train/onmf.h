// Orthogonal non-negative matrix factorisation (Choi, "Algorithms for orthogonal nonnegative matrix
// factorization", IJCNN 2008): X ~ W H with W, H >= 0 and W^T W = I, by multiplicative updates that follow the
// gradient on the Stiefel manifold. Here X holds the training regions' visual-word histograms as columns
// (words x regions), W the topics (words x topics, unit orthogonal columns) and H the regions' topic weights.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace pdvo {

struct OnmfOptions {
  int topics = 20;  // columns of W
  int max_iterations = 500;
  double tolerance = 1e-6;  // stop when the relative change of the error falls below this
  uint64_t seed = 1;        // random non-negative initialisation

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("topics", self.topics);
    visit("max_iterations", self.max_iterations);
    visit("tolerance", self.tolerance);
  }
  bool Check() const;
  bool operator==(const OnmfOptions&) const = default;
};

struct OnmfResult {
  Eigen::MatrixXd basis;       // W: words x topics, non-negative, unit columns, near-orthogonal
  Eigen::MatrixXd weights;     // H: topics x regions, non-negative
  std::vector<double> errors;  // |X - W H|_F / |X|_F after each iteration
};

// Throws InvalidArgument for negative or non-finite data, or more topics than words or regions.
OnmfResult FactoriseOrthogonal(const Eigen::MatrixXd& data, const OnmfOptions& options);

}  // namespace pdvo
