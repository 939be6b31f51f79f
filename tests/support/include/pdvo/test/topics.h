// A known topic factorisation for the topic tests: topics with disjoint sets of words (so exactly orthogonal unit
// columns) and random non-negative weights, some zero.
#pragma once

#include <Eigen/Core>
#include <random>

namespace pdvo::test {

struct KnownTopics {
  Eigen::MatrixXd basis, weights, data;  // data = basis * weights
  KnownTopics(int words, int topics, int regions, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    basis = Eigen::MatrixXd::Zero(words, topics);
    for (int w = 0; w < words; ++w) basis(w, w % topics) = 0.2 + u(rng);
    for (int t = 0; t < topics; ++t) basis.col(t).normalize();
    weights = Eigen::MatrixXd::NullaryExpr(topics, regions, [&]() { return u(rng) < 0.3 ? 0.0 : 5 * u(rng); });
    data = basis * weights;
  }
};

}  // namespace pdvo::test
