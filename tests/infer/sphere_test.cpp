// Directions on the sphere: mean shift recovers known clusters of normals (three planes' orientations with
// noise and scattered outliers), ordered by their weight, and gives the same from repeated directions as from
// their weighted set; the robust mean ignores outliers that pull the plain mean away.
#include "pdvo/infer/sphere.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"

namespace pdvo {
namespace {

// `n` directions within about `sigma_deg` of `centre`.
void Scatter(const Eigen::Vector3d& centre, int n, double sigma_deg, double weight, std::mt19937& rng,
             std::vector<Eigen::Vector3d>* d, std::vector<double>* w) {
  std::normal_distribution<double> g(0, sigma_deg * M_PI / 180);
  for (int i = 0; i < n; ++i) {
    d->push_back((centre.normalized() + Eigen::Vector3d(g(rng), g(rng), g(rng))).normalized());
    w->push_back(weight);
  }
}

TEST(Sphere, MeanShiftRecoversKnownClusters) {
  std::mt19937 rng(5);
  const Eigen::Vector3d ground(0, -1, 0), left(1, 0, -0.2), ahead(0, 0, -1);
  std::vector<Eigen::Vector3d> d;
  std::vector<double> w;
  Scatter(ground, 60, 4, 1.0, rng, &d, &w);
  Scatter(left, 40, 4, 1.0, rng, &d, &w);
  Scatter(ahead, 25, 4, 1.0, rng, &d, &w);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 5; ++i) {  // scattered, light outliers
    d.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
    w.push_back(0.05);
  }
  const std::vector<DirectionMode> modes = MeanShiftModes(d, w, 10, 5);
  ASSERT_GE(modes.size(), 3u);
  EXPECT_LT(AngleDeg(modes[0].direction, ground), 2);
  EXPECT_LT(AngleDeg(modes[1].direction, left), 2);
  EXPECT_LT(AngleDeg(modes[2].direction, ahead), 2);
  EXPECT_NEAR(modes[0].support, 60, 1);
  EXPECT_NEAR(modes[1].support, 40, 1);
  for (size_t k = 3; k < modes.size(); ++k) EXPECT_LT(modes[k].support, 1) << k;  // only the outliers
}

// The detector's points share their cell's normal: repeated directions are summed once with their weights added,
// which must give the modes and supports of the directions given once with those weights.
TEST(Sphere, MeanShiftOfRepeatedDirectionsEqualsTheirWeightedSet) {
  std::mt19937 rng(7);
  std::vector<Eigen::Vector3d> once, repeated;
  std::vector<double> weight_once, weight_repeated;
  Scatter(Eigen::Vector3d(0, -1, 0), 12, 5, 1.0, rng, &once, &weight_once);
  Scatter(Eigen::Vector3d(1, 0, -0.3), 8, 5, 1.0, rng, &once, &weight_once);
  std::uniform_int_distribution<int> copies(1, 4);
  for (size_t i = 0; i < once.size(); ++i) {
    const int c = copies(rng);
    weight_once[i] = 0.5 * c;
    for (int k = 0; k < c; ++k) {
      repeated.push_back(once[i]);
      weight_repeated.push_back(0.5);
    }
  }
  // Starts from every direction in both cases.
  const std::vector<DirectionMode> a = MeanShiftModes(once, weight_once, 10, 5, 1000);
  const std::vector<DirectionMode> b = MeanShiftModes(repeated, weight_repeated, 10, 5, 1000);
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_LT(AngleDeg(a[k].direction, b[k].direction), 1e-6) << k;
    EXPECT_NEAR(a[k].support, b[k].support, 1e-9) << k;
  }
}

TEST(Sphere, RobustMeanIgnoresOutliers) {
  std::mt19937 rng(9);
  std::vector<Eigen::Vector3d> d;
  std::vector<double> w;
  const Eigen::Vector3d truth = Eigen::Vector3d(0.3, -0.2, -1).normalized();
  Scatter(truth, 40, 3, 1.0, rng, &d, &w);
  Scatter(Eigen::Vector3d(1, 0, 0), 15, 3, 1.0, rng, &d, &w);  // another plane's normals
  Eigen::Vector3d plain = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : d) plain += x;
  EXPECT_GT(AngleDeg(plain, truth), 10);  // the plain mean is pulled away
  EXPECT_LT(AngleDeg(RobustMeanDirection(d, w, 5), truth), 1.5);
  EXPECT_EQ(RobustMeanDirection({Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX()}, {1, 1}, 5),
            Eigen::Vector3d::Zero());
  EXPECT_THROW(RobustMeanDirection(d, {1.0}, 5), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
