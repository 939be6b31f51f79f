#include "pdvo/infer/column_cuts.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

constexpr int kAzimuthSteps = 36;  // phi in [0, pi) in 5-degree steps

// Prefix sums over the columns of their median colours and of their squares: the colour cost of a run in O(1).
struct ColourTable {
  std::vector<Eigen::Vector3d> sum{Eigen::Vector3d::Zero()};
  std::vector<double> squares{0};
  double Cost(int i, int j) const {  // columns i..j-1
    const Eigen::Vector3d s = sum[j] - sum[i];
    return squares[j] - squares[i] - s.squaredNorm() / (j - i);
  }
};

// Per phi_k, prefix sums over the columns of their edges' robust losses: the turn cost of a run in O(steps).
struct AzimuthTable {
  Eigen::Matrix<double, kAzimuthSteps, Eigen::Dynamic> total;  // x (columns + 1); empty: the edges say nothing
  double Cost(int i, int j) const { return total.size() == 0 ? 0.0 : (total.col(j) - total.col(i)).minCoeff(); }
};

// The mask's columns with at least min_pixels of its pixels, and their median colours.
void ColumnColours(const cv::Mat& lab, const cv::Mat& mask, int min_pixels, std::vector<int>* column,
                   ColourTable* colours) {
  std::vector<float> channel[3];
  const cv::Rect box = cv::boundingRect(mask);  // the columns and rows outside it hold no pixel of the mask
  cv::Mat lab_columns, mask_columns;            // transposed: a column is a row, read in memory order
  cv::transpose(lab(box), lab_columns);
  cv::transpose(mask(box), mask_columns);
  for (int x = box.x; x < box.x + box.width; ++x) {
    for (auto& c : channel) c.clear();
    const uchar* in = mask_columns.ptr<uchar>(x - box.x);
    const cv::Vec3f* values = lab_columns.ptr<cv::Vec3f>(x - box.x);
    for (int y = 0; y < box.height; ++y) {
      if (!in[y]) continue;
      for (int k = 0; k < 3; ++k) channel[k].push_back(values[y][k]);
    }
    if (static_cast<int>(channel[0].size()) < min_pixels) continue;
    Eigen::Vector3d median;
    for (int k = 0; k < 3; ++k) {
      std::nth_element(channel[k].begin(), channel[k].begin() + channel[k].size() / 2, channel[k].end());
      median[k] = channel[k][channel[k].size() / 2];
    }
    column->push_back(x);
    colours->sum.push_back(colours->sum.back() + median);
    colours->squares.push_back(colours->squares.back() + median.squaredNorm());
  }
}

AzimuthTable ColumnAzimuths(const EdgePlanes& edges, const cv::Mat& mask, const std::vector<int>& column,
                            const VanishingOptions& o) {
  AzimuthTable table;
  if (!edges.up_found) return table;
  const int m = static_cast<int>(column.size());
  std::vector<int> index(mask.cols, -1);
  for (int i = 0; i < m; ++i) index[column[i]] = i;
  // The mask's edges off the vertical as constraints on phi (AzimuthLikelihood), and each one's column.
  AzimuthLikelihood edges_phi = AzimuthBasis(edges, o);
  std::vector<int> edge_column;
  const cv::Rect box = cv::boundingRect(mask);
  for (int y = box.y; y < box.y + box.height; ++y) {
    const uchar* in = mask.ptr<uchar>(y);
    const cv::Vec3f* normal = edges.normals.ptr<cv::Vec3f>(y);
    const float* strength = edges.strength.ptr<float>(y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (!in[x] || strength[x] <= 0 || index[x] < 0) continue;
      if (edges_phi.Add(Eigen::Vector3f(normal[x][0], normal[x][1], normal[x][2]), strength[x])) {
        edge_column.push_back(index[x]);
      }
    }
  }
  if (static_cast<int>(edge_column.size()) < o.min_edges) return table;
  double mean_strength = 0;
  for (const float w : edges_phi.weights) mean_strength += w;
  mean_strength /= static_cast<double>(edge_column.size());
  std::vector<double> phis(kAzimuthSteps);
  for (int k = 0; k < kAzimuthSteps; ++k) phis[k] = (k + 0.5) * M_PI / kAzimuthSteps;
  const Eigen::ArrayXXf losses = edges_phi.Losses(phis);  // edges x phis
  table.total = Eigen::Matrix<double, kAzimuthSteps, Eigen::Dynamic>::Zero(kAzimuthSteps, m + 1);
  for (size_t e = 0; e < edge_column.size(); ++e) {
    const double weight = edges_phi.weights[e] / mean_strength;
    table.total.col(edge_column[e] + 1) +=
        (losses.row(static_cast<Eigen::Index>(e)).transpose().cast<double>() * weight).matrix();
  }
  for (int i = 0; i < m; ++i) table.total.col(i + 1) += table.total.col(i);
  return table;
}

// A run between two runs whose mean colours are within `join_colour` of each other, and no wider than either, is a
// pulse of another colour in one facade (its windows, a door): the three become one, until none is left.
void JoinPulses(const ColourTable& colours, const std::vector<int>& column, double join_colour,
                std::vector<int>* start) {
  if (join_colour <= 0) return;
  std::vector<int>& s = *start;
  auto mean = [&](size_t k) -> Eigen::Vector3d {
    return (colours.sum[s[k + 1]] - colours.sum[s[k]]) / (s[k + 1] - s[k]);
  };
  auto width = [&](size_t k) { return column[s[k + 1] - 1] - column[s[k]] + 1; };
  for (size_t k = 0; k + 3 < s.size();) {
    if ((mean(k) - mean(k + 2)).norm() <= join_colour && width(k + 1) <= std::min(width(k), width(k + 2))) {
      s.erase(s.begin() + static_cast<long>(k) + 1, s.begin() + static_cast<long>(k) + 3);
      k = k >= 2 ? k - 2 : 0;  // the joined run may now be a pulse, or frame one
    } else {
      ++k;
    }
  }
}

}  // namespace

std::vector<int> FacadeColumnCuts(const cv::Mat& lab, const EdgePlanes& edges, const cv::Mat& mask,
                                  const ColumnCutOptions& cut, const VanishingOptions& o) {
  PDVO_THROW_CHECK(lab.type() == CV_32FC3 && mask.type() == CV_8U && lab.size() == mask.size() &&
                       (edges.normals.empty() || edges.normals.size() == mask.size()),
                   InvalidArgument,
                   "facade columns: expected a CV_32FC3 image and a CV_8U mask (and edges) of its size");
  PDVO_THROW_CHECK(cut.colour_penalty >= 0 && cut.azimuth_penalty >= 0, InvalidArgument,
                   "facade columns: negative penalty");
  if (cut.colour_penalty == 0 && cut.azimuth_penalty == 0) return {};
  std::vector<int> column;
  ColourTable colours;
  ColumnColours(lab, mask, cut.min_pixels, &column, &colours);
  const AzimuthTable azimuths = cut.azimuth_penalty > 0 ? ColumnAzimuths(edges, mask, column, o) : AzimuthTable();
  const double colour_weight = cut.colour_penalty > 0 ? 1 / cut.colour_penalty : 0;
  const double azimuth_weight = cut.azimuth_penalty > 0 ? 1 / cut.azimuth_penalty : 0;
  auto cost = [&](int i, int j) { return colour_weight * colours.Cost(i, j) + azimuth_weight * azimuths.Cost(i, j); };
  // best[j]: the least cost of columns 0..j-1 as runs; from[j]: where its last run starts.
  const int m = static_cast<int>(column.size());
  if (m == 0) return {};
  std::vector<double> best(m + 1, std::numeric_limits<double>::infinity());
  std::vector<int> from(m + 1, 0);
  best[0] = 0;
  for (int j = 1; j <= m; ++j) {
    for (int i = 0; i < j; ++i) {
      const bool wide = column[j - 1] - column[i] + 1 >= cut.min_width;
      if (!wide && !(i == 0 && j == m)) continue;  // too narrow a run, unless it is the whole
      const double c = best[i] + cost(i, j) + 1;
      if (c < best[j]) best[j] = c, from[j] = i;
    }
  }
  std::vector<int> start{m};  // each run's first column (as an index into `column`), and m after the last
  for (int j = m; j > 0; j = from[j]) start.push_back(from[j]);
  std::reverse(start.begin(), start.end());
  JoinPulses(colours, column, cut.join_colour, &start);
  std::vector<int> cuts;
  for (size_t k = 1; k + 1 < start.size(); ++k) cuts.push_back(column[start[k]]);
  return cuts;
}

}  // namespace pdvo
