// Pairwise Markov random fields over a graph, minimised by graph cuts (the detector's segmentation, the paper's
// section III). A binary energy with submodular pairwise terms is minimised exactly by a minimum s-t cut
// (Kolmogorov & Zabih 2004), computed by Boost.Graph's Boykov-Kolmogorov max-flow. A multi-label energy with
// Potts pairwise terms is minimised by alpha-expansion (Boykov, Veksler & Zabih 2001): repeated binary cuts,
// each letting every node keep its label or take label alpha; the result is within a factor 2 of the optimum.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace pdvo {

// E(x) = sum_i U_i(x_i) + sum_(i,j) P_ij(x_i, x_j) over labels x_i in {0, 1}.
class BinaryEnergy {
 public:
  explicit BinaryEnergy(int nodes);
  int nodes() const { return static_cast<int>(unary_.size()); }
  // Adds cost0 to node i taking label 0 and cost1 to label 1 (finite; any sign).
  void AddUnary(int i, double cost0, double cost1);
  // Adds the pairwise term P(x_i, x_j) = {e00, e01, e10, e11}; throws InvalidArgument unless submodular
  // (e00 + e11 <= e01 + e10, to a relative 1e-9) and i != j.
  void AddPairwise(int i, int j, double e00, double e01, double e10, double e11);
  // The energy of a labelling.
  double Energy(const std::vector<int>& labels) const;
  // The labelling of least energy (exact); `energy` (if given) becomes its energy.
  std::vector<int> Minimise(double* energy = nullptr) const;

 private:
  struct Pair {
    int i, j;
    std::array<double, 4> e;  // e00, e01, e10, e11
  };
  std::vector<std::array<double, 2>> unary_;
  std::vector<Pair> pairs_;
};

// An edge of a Potts term: `weight` (>= 0) is paid when its nodes take different labels.
struct PottsEdge {
  int a = 0, b = 0;
  double weight = 0;
};

// sum_i unary(i, x_i) + sum_edges weight [x_a != x_b].
double PottsEnergy(const Eigen::MatrixXd& unary, const std::vector<PottsEdge>& edges, const std::vector<int>& labels);

// Alpha-expansion from `initial` (nodes x labels `unary`, finite): sweeps over the labels until no expansion
// lowers the energy (or `max_sweeps` sweeps). Deterministic: labels are expanded in order.
std::vector<int> AlphaExpansion(const Eigen::MatrixXd& unary, const std::vector<PottsEdge>& edges,
                                std::vector<int> initial, int max_sweeps = 10);

}  // namespace pdvo
