// Cutting a facade's columns (FacadeColumnCuts): by colour, where a facade changes colour under a window pattern; by
// its edges, where they turn to another vanishing direction (a building's corner) and not where they do not; both
// against brute force over every set of cuts; a facade's windows joined to it.
#include "pdvo/infer/column_cuts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

ColumnCutOptions Colour(double penalty, int min_width, int min_pixels) { return {penalty, 0, min_width, min_pixels}; }

// Columns of two colours, each with a window pattern of a third colour in a minority of every column: one cut, at
// the change; one colour with the same windows: none; a change too near the edge to pay for a run of min_width: none.
TEST(FacadeColumnCuts, FindWhereAFacadeChangesColour) {
  const auto facade = [](int change) {
    cv::Mat lab(60, 100, CV_32FC3);
    for (int y = 0; y < lab.rows; ++y) {
      for (int x = 0; x < lab.cols; ++x) {
        const bool window = (y % 20) < 8 && (x % 10) < 6;  // 40% of a window column's pixels
        lab.at<cv::Vec3f>(y, x) = window       ? cv::Vec3f(30, 0, -30)
                                  : x < change ? cv::Vec3f(70, 20, 10)
                                               : cv::Vec3f(70, -20, 10);
      }
    }
    return lab;
  };
  const cv::Mat mask(60, 100, CV_8U, cv::Scalar(255));
  const EdgePlanes none;  // no edges: colour alone
  const VanishingOptions v;
  EXPECT_EQ(FacadeColumnCuts(facade(37), none, mask, Colour(3000, 12, 8), v), std::vector<int>{37});
  EXPECT_TRUE(FacadeColumnCuts(facade(100), none, mask, Colour(3000, 12, 8), v).empty());
  // 3 columns cannot pay for a run of 12.
  EXPECT_TRUE(FacadeColumnCuts(facade(97), none, mask, Colour(3000, 12, 8), v).empty());
  EXPECT_TRUE(FacadeColumnCuts(facade(37), none, mask, {0, 0, 12, 8}, v).empty());  // both cues off
  // Only the mask's pixels count: the change lies outside it.
  cv::Mat left = cv::Mat::zeros(60, 100, CV_8U);
  left.colRange(0, 30).setTo(255);
  EXPECT_TRUE(FacadeColumnCuts(facade(37), none, left, Colour(3000, 12, 8), v).empty());
  EXPECT_THROW(FacadeColumnCuts(facade(37), none, cv::Mat(60, 99, CV_8U), Colour(3000, 12, 8), v), InvalidArgument);
}

// A facade of one colour with a shop window filling most of columns 40-59, then another facade from column 80:
// cut at 40, 60 and 80 by colour alone; with join_colour the window joins the wall on both sides of it, and the
// change to the other facade stays. A wide run of another colour between two narrow ones of one colour is no pulse.
TEST(FacadeColumnCuts, JoinAFacadesWindowsToIt) {
  const auto facade = [](int from, int to, int other) {
    cv::Mat lab(60, 120, CV_32FC3);
    for (int y = 0; y < lab.rows; ++y) {
      for (int x = 0; x < lab.cols; ++x) {
        const bool window = x >= from && x < to && y >= 10;  // 5 of 6 of the column
        lab.at<cv::Vec3f>(y, x) = window      ? cv::Vec3f(40, 0, -10)
                                  : x < other ? cv::Vec3f(50, 45, 25)
                                              : cv::Vec3f(60, 35, -8);
      }
    }
    return lab;
  };
  const cv::Mat mask(60, 120, CV_8U, cv::Scalar(255));
  const EdgePlanes none;
  const VanishingOptions v;
  ColumnCutOptions join = Colour(3000, 12, 8);
  EXPECT_EQ(FacadeColumnCuts(facade(40, 60, 80), none, mask, join, v), (std::vector<int>{40, 60, 80}));
  join.join_colour = 6;
  EXPECT_EQ(FacadeColumnCuts(facade(40, 60, 80), none, mask, join, v), std::vector<int>{80});
  EXPECT_EQ(FacadeColumnCuts(facade(20, 100, 120), none, mask, join, v), (std::vector<int>{20, 100}));
}

// A facade of one colour whose horizontal edges run along one direction left of column `turn` and along another,
// 90 degrees round, right of it: every fourth row an edge whose line's plane through the camera contains that
// direction (and is off the vertical band). With the vertical straight up, the horizontal directions are
// d(phi) = cos(phi) x + sin(phi) z.
EdgePlanes TurningEdges(int turn, double phi_left, double phi_right) {
  EdgePlanes e;
  e.up = Eigen::Vector3d::UnitY();
  e.up_found = true;
  e.normals = cv::Mat::zeros(60, 100, CV_32FC3);
  e.strength = cv::Mat::zeros(60, 100, CV_32F);
  for (int y = 0; y < 60; y += 4) {
    for (int x = 0; x < 100; ++x) {
      const double phi = x < turn ? phi_left : phi_right;
      // Perpendicular to d(phi) and 0.6 along the vertical (outside the 30-degree vertical band).
      const Eigen::Vector3d m = 0.6 * e.up + 0.8 * Eigen::Vector3d(-std::sin(phi), 0, std::cos(phi));
      e.normals.at<cv::Vec3f>(y, x) = cv::Vec3f(m.x(), m.y(), m.z());
      e.strength.at<float>(y, x) = 10;
    }
  }
  return e;
}

TEST(FacadeColumnCuts, FindWhereAFacadesEdgesTurn) {
  const cv::Mat lab(60, 100, CV_32FC3, cv::Scalar(70, 0, 0)), mask(60, 100, CV_8U, cv::Scalar(255));
  const VanishingOptions v;
  const ColumnCutOptions turn{3000, 80, 12, 8};
  EXPECT_EQ(FacadeColumnCuts(lab, TurningEdges(41, 0.5, 0.5 + M_PI / 2), mask, turn, v), std::vector<int>{41});
  EXPECT_TRUE(FacadeColumnCuts(lab, TurningEdges(41, 0.5, 0.5), mask, turn, v).empty());
  // Colour alone does not see the corner; nor do the edges without a vertical.
  EXPECT_TRUE(FacadeColumnCuts(lab, TurningEdges(41, 0.5, 0.5 + M_PI / 2), mask, Colour(3000, 12, 8), v).empty());
  EdgePlanes no_vertical = TurningEdges(41, 0.5, 0.5 + M_PI / 2);
  no_vertical.up_found = false;
  EXPECT_TRUE(FacadeColumnCuts(lab, no_vertical, mask, turn, v).empty());
}

// The dynamic programme against brute force: on random rows of up to 12 one-pixel columns with random colours and
// random edge directions, the cuts it returns cost as little as the best of every set of cuts whose runs are at
// least min_width wide (or one run).
TEST(FacadeColumnCuts, AreOptimal) {
  cv::RNG rng(7);
  VanishingOptions v;
  v.min_edges = 1;  // a row of one-pixel columns holds few edges
  for (int trial = 0; trial < 300; ++trial) {
    const int m = rng.uniform(1, 13), min_width = rng.uniform(1, 4);
    const ColumnCutOptions cut{rng.uniform(1.0, 400.0), trial % 2 ? rng.uniform(0.5, 5.0) : 0.0, min_width, 1};
    cv::Mat lab(1, m, CV_32FC3);
    EdgePlanes edges;
    edges.up = Eigen::Vector3d::UnitY();
    edges.up_found = true;
    edges.normals = cv::Mat(1, m, CV_32FC3);
    edges.strength = cv::Mat(1, m, CV_32F);
    std::vector<double> phi(m);
    for (int x = 0; x < m; ++x) {
      lab.at<cv::Vec3f>(0, x) = cv::Vec3f(rng.uniform(0.f, 100.f), rng.uniform(-20.f, 20.f), rng.uniform(-20.f, 20.f));
      phi[x] = rng.uniform(0.0, M_PI);
      const Eigen::Vector3d n = 0.6 * edges.up + 0.8 * Eigen::Vector3d(-std::sin(phi[x]), 0, std::cos(phi[x]));
      edges.normals.at<cv::Vec3f>(0, x) = cv::Vec3f(n.x(), n.y(), n.z());
      edges.strength.at<float>(0, x) = 10;  // all of mean strength
    }
    const bool edges_count = cut.azimuth_penalty > 0;
    const auto cost =
        [&](const std::vector<int>& cuts) {  // per run: colour / colour_penalty + turn / azimuth_penalty + 1
          std::vector<int> bounds = {0};
          bounds.insert(bounds.end(), cuts.begin(), cuts.end());
          bounds.push_back(m);
          double total = 0;
          for (size_t r = 0; r + 1 < bounds.size(); ++r) {
            cv::Vec3d mean(0, 0, 0);
            for (int x = bounds[r]; x < bounds[r + 1]; ++x) mean += cv::Vec3d(lab.at<cv::Vec3f>(0, x));
            mean /= bounds[r + 1] - bounds[r];
            double colour = 0, turn = std::numeric_limits<double>::infinity();
            for (int x = bounds[r]; x < bounds[r + 1]; ++x) {
              const cv::Vec3d d = cv::Vec3d(lab.at<cv::Vec3f>(0, x)) - mean;
              colour += d.dot(d);
            }
            for (int k = 0; k < 36; ++k) {  // the directions it tries
              const double p = (k + 0.5) * M_PI / 36;
              double loss = 0;
              for (int x = bounds[r]; x < bounds[r + 1]; ++x) {
                const double residual = 0.8 * std::sin(phi[x] - p) / v.residual_scale;  // m . d(p)
                loss += std::log1p(residual * residual);
              }
              turn = std::min(turn, loss);
            }
            total += colour / cut.colour_penalty + (edges_count ? turn / cut.azimuth_penalty : 0) + 1;
          }
          return total;
        };
    double best = std::numeric_limits<double>::infinity();
    for (int set = 0; set < (1 << std::max(0, m - 1)); ++set) {  // bit k: a cut before column k + 1
      std::vector<int> cuts;
      for (int k = 0; k + 1 < m; ++k) {
        if (set >> k & 1) cuts.push_back(k + 1);
      }
      bool wide = true;
      for (size_t r = 0; r <= cuts.size(); ++r) {
        const int from = r == 0 ? 0 : cuts[r - 1], to = r == cuts.size() ? m : cuts[r];
        wide = wide && (to - from >= min_width || cuts.empty());
      }
      if (wide) best = std::min(best, cost(cuts));
    }
    const std::vector<int> cuts = FacadeColumnCuts(lab, edges, cv::Mat(1, m, CV_8U, cv::Scalar(255)), cut, v);
    EXPECT_NEAR(cost(cuts), best, 1e-4 * (1 + best)) << "trial " << trial << ", " << m << " columns";
  }
}

}  // namespace
}  // namespace pdvo
