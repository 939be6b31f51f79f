#include "pdvo/infer/mrf.h"

#include <algorithm>
// GCC 12 reports edge iterators inside Boost.Graph's max-flow as maybe uninitialized (a false positive of its
// inlining); this file holds no other code that the warning would guard. Clang has no such warning.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <cmath>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

using Traits = boost::adjacency_list_traits<boost::vecS, boost::vecS, boost::directedS>;
struct VertexData {
  boost::default_color_type color = boost::white_color;
  long distance = 0;
  Traits::edge_descriptor predecessor;
};
struct EdgeData {
  double capacity = 0;
  double residual = 0;
  Traits::edge_descriptor reverse;
};
using FlowGraph = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, VertexData, EdgeData>;

// An edge a -> b of capacity `forward` and its reverse of capacity `backward`.
void AddEdgePair(FlowGraph& g, int a, int b, double forward, double backward) {
  const auto ab = boost::add_edge(a, b, g).first, ba = boost::add_edge(b, a, g).first;
  g[ab].capacity = forward;
  g[ba].capacity = backward;
  g[ab].reverse = ba;
  g[ba].reverse = ab;
}

}  // namespace

BinaryEnergy::BinaryEnergy(int nodes) : unary_(std::max(0, nodes), {0.0, 0.0}) {
  PDVO_THROW_CHECK(nodes >= 0, InvalidArgument, "binary energy: a negative number of nodes");
}

void BinaryEnergy::AddUnary(int i, double cost0, double cost1) {
  PDVO_THROW_CHECK(i >= 0 && i < nodes() && std::isfinite(cost0) && std::isfinite(cost1), InvalidArgument,
                   "binary energy: bad unary term at node " << i);
  unary_[i][0] += cost0;
  unary_[i][1] += cost1;
}

void BinaryEnergy::AddPairwise(int i, int j, double e00, double e01, double e10, double e11) {
  PDVO_THROW_CHECK(i >= 0 && i < nodes() && j >= 0 && j < nodes() && i != j, InvalidArgument,
                   "binary energy: bad pairwise term between nodes " << i << " and " << j);
  const double scale = std::abs(e00) + std::abs(e01) + std::abs(e10) + std::abs(e11);
  PDVO_THROW_CHECK(std::isfinite(scale) && e00 + e11 <= e01 + e10 + 1e-9 * scale, InvalidArgument,
                   "binary energy: the term between nodes " << i << " and " << j << " is not submodular");
  pairs_.push_back({i, j, {e00, e01, e10, e11}});
}

double BinaryEnergy::Energy(const std::vector<int>& x) const {
  PDVO_THROW_CHECK(static_cast<int>(x.size()) == nodes(), InvalidArgument, "binary energy: labelling size");
  double e = 0;
  for (int i = 0; i < nodes(); ++i) e += unary_[i][x[i]];
  for (const Pair& p : pairs_) e += p.e[2 * x[p.i] + x[p.j]];
  return e;
}

std::vector<int> BinaryEnergy::Minimise(double* energy) const {
  // Reparametrised (Kolmogorov & Zabih): P(x_i, x_j) = e00 + (e10 - e00) x_i + (e11 - e10) x_j
  // + (e01 + e10 - e00 - e11) (1 - x_i) x_j. Label 0 is the source's side of the cut, label 1 the sink's: a node
  // on the sink's side cuts its source edge (paying its label-1 cost), and x_i = 0, x_j = 1 cuts i -> j.
  const int n = nodes(), source = n, sink = n + 1;
  std::vector<std::array<double, 2>> unary = unary_;
  FlowGraph g(n + 2);
  for (const Pair& p : pairs_) {
    const auto& [e00, e01, e10, e11] = p.e;
    unary[p.i][1] += e10 - e00;
    unary[p.j][1] += e11 - e10;
    AddEdgePair(g, p.i, p.j, std::max(0.0, e01 + e10 - e00 - e11), 0.0);
  }
  for (int i = 0; i < n; ++i) {
    const double low = std::min(unary[i][0], unary[i][1]);
    AddEdgePair(g, source, i, unary[i][1] - low, 0.0);
    AddEdgePair(g, i, sink, unary[i][0] - low, 0.0);
  }
  boost::boykov_kolmogorov_max_flow(g, boost::get(&EdgeData::capacity, g), boost::get(&EdgeData::residual, g),
                                    boost::get(&EdgeData::reverse, g), boost::get(&VertexData::predecessor, g),
                                    boost::get(&VertexData::color, g), boost::get(&VertexData::distance, g),
                                    boost::get(boost::vertex_index, g), source, sink);
  std::vector<int> labels(n);
  // The source's tree is black; the rest (the sink's tree and free nodes) is the sink's side.
  for (int i = 0; i < n; ++i) labels[i] = g[i].color == boost::black_color ? 0 : 1;
  if (energy) *energy = Energy(labels);
  return labels;
}

double PottsEnergy(const Eigen::MatrixXd& unary, const std::vector<PottsEdge>& edges, const std::vector<int>& x) {
  PDVO_THROW_CHECK(static_cast<Eigen::Index>(x.size()) == unary.rows(), InvalidArgument,
                   "Potts energy: labelling size");
  double e = 0;
  for (size_t i = 0; i < x.size(); ++i) e += unary(static_cast<Eigen::Index>(i), x[i]);
  for (const PottsEdge& edge : edges) e += x[edge.a] != x[edge.b] ? edge.weight : 0.0;
  return e;
}

std::vector<int> AlphaExpansion(const Eigen::MatrixXd& unary, const std::vector<PottsEdge>& edges, std::vector<int> x,
                                int max_sweeps) {
  const int n = static_cast<int>(unary.rows()), labels = static_cast<int>(unary.cols());
  PDVO_THROW_CHECK(static_cast<int>(x.size()) == n && unary.allFinite(), InvalidArgument,
                   "alpha-expansion: " << x.size() << " initial labels for " << n << " nodes, or non-finite costs");
  for (const int l : x) PDVO_THROW_CHECK(l >= 0 && l < labels, InvalidArgument, "alpha-expansion: a bad label");
  for (const PottsEdge& e : edges) {
    PDVO_THROW_CHECK(e.a >= 0 && e.a < n && e.b >= 0 && e.b < n && e.a != e.b && e.weight >= 0, InvalidArgument,
                     "alpha-expansion: a bad edge " << e.a << " - " << e.b);
  }
  double best = PottsEnergy(unary, edges, x);
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    bool improved = false;
    for (int alpha = 0; alpha < labels; ++alpha) {
      // Label 0: keep x_i; label 1: take alpha.
      BinaryEnergy move(n);
      for (int i = 0; i < n; ++i) move.AddUnary(i, unary(i, x[i]), unary(i, alpha));
      for (const PottsEdge& e : edges) {
        const double w = e.weight;
        move.AddPairwise(e.a, e.b, x[e.a] != x[e.b] ? w : 0, x[e.a] != alpha ? w : 0, alpha != x[e.b] ? w : 0, 0);
      }
      const std::vector<int> take = move.Minimise();
      std::vector<int> next = x;
      for (int i = 0; i < n; ++i) {
        if (take[i]) next[i] = alpha;
      }
      const double e = PottsEnergy(unary, edges, next);
      if (e < best - 1e-12 * std::max(1.0, std::abs(best))) {
        best = e;
        x = std::move(next);
        improved = true;
      }
    }
    if (!improved) break;
  }
  return x;
}

}  // namespace pdvo
