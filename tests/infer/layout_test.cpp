// LayoutFeature: a region's place in the image and the fit of its edge angles over it, checked on the exact
// images of families of parallel 3D lines and on a known linear angle field.
#include <gtest/gtest.h>

#include <cmath>

#include "pdvo/common/errors.h"
#include "pdvo/infer/recogniser.h"

namespace pdvo {
namespace {

constexpr double kWidth = 320, kHeight = 240;  // the layout's camera: focal length = width, centred

Eigen::Vector2d Project(const Eigen::Vector3d& p) {
  return {kWidth * p.x() / p.z() + kWidth / 2, kWidth * p.y() / p.z() + kHeight / 2};
}

// Points along 7 lines of each family on the plane through `origin` spanned by the unit directions a (lines
// near horizontal in the image) and b (near vertical). Each point's gradient direction is across its line's
// image, coherence 1.
RegionWords LinesOnPlane(const Eigen::Vector3d& origin, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  RegionWords r;
  r.image_size = cv::Size(static_cast<int>(kWidth), static_cast<int>(kHeight));
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (int family = 0; family < 2; ++family) {
    const Eigen::Vector3d along = family == 0 ? a : b, across = family == 0 ? b : a;
    for (int k = -3; k <= 3; ++k) {
      for (int t = -4; t <= 4; ++t) {
        const Eigen::Vector3d p = origin + 0.1 * k * across + 0.08 * t * along;
        const Eigen::Vector2d q = Project(p), dq = Project(p + 1e-4 * along) - q;
        double angle = std::atan2(dq.y(), dq.x()) + M_PI / 2;  // the gradient is across the edge
        angle = std::fmod(angle + 2 * M_PI, M_PI);
        r.points.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
        r.angle.push_back(static_cast<float>(angle));
        r.coherence.push_back(1.0f);
        x0 = std::min(x0, q.x()), y0 = std::min(y0, q.y()), x1 = std::max(x1, q.x()), y1 = std::max(y1, q.y());
      }
    }
  }
  r.box = cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
  return r;
}

// The angle of an edge through `p` pointing at the vanishing point `v` (pixels), folded into (-pi/2, pi/2].
double AngleTowards(const Eigen::Vector2d& p, const Eigen::Vector2d& v) {
  double angle = std::atan2(v.y() - p.y(), v.x() - p.x());
  if (angle > M_PI / 2) angle -= M_PI;
  if (angle <= -M_PI / 2) angle += M_PI;
  return angle;
}

TEST(Layout, PlaceAndSizeInImageWidths) {
  const RegionWords r = LinesOnPlane({0.1, -0.05, 3}, {1, 0, 0}, {0, 1, 0});
  const Eigen::VectorXd f = LayoutFeature(r);
  ASSERT_EQ(f.size(), kLayoutDims);
  EXPECT_NEAR(f[0], (r.box.x + r.box.width / 2 - kWidth / 2) / kWidth, 1e-12);
  EXPECT_NEAR(f[1], (r.box.y + r.box.height / 2 - kHeight / 2) / kWidth, 1e-12);
  EXPECT_NEAR(f[2], r.box.width / kWidth, 1e-12);
  EXPECT_NEAR(f[3], r.box.height / kWidth, 1e-12);
  EXPECT_NEAR(f[10], 0.5, 1e-9);  // as many points in each family, all of coherence 1
}

TEST(Layout, FrontalFacadeHasStraightParallelEdges) {
  const Eigen::VectorXd f = LayoutFeature(LinesOnPlane({0.1, -0.05, 3}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_LT(f.segment<6>(4).cwiseAbs().maxCoeff(), 1e-6) << f.transpose();
}

// An oblique facade on the right: its level lines converge at the vanishing point of their direction; the fit
// gives the edge angle at the region's centre and its rate of change, as the exact angle field has them (the
// field is not linear across the region: within 15%).
TEST(Layout, ObliqueFacadeEdgesTurnTowardsTheirVanishingPoint) {
  const Eigen::Vector3d a = Eigen::Vector3d(0.6, 0, 0.8), b(0, 1, 0);
  const RegionWords r = LinesOnPlane({0.8, -0.1, 3}, a, b);
  const Eigen::VectorXd f = LayoutFeature(r);
  const Eigen::Vector2d v = Project(a), c(r.box.x + r.box.width / 2, r.box.y + r.box.height / 2);
  const double h = 1e-3 * kWidth;  // a step of 1/1000 image width
  const double along_x =
      (AngleTowards(c + Eigen::Vector2d(h, 0), v) - AngleTowards(c - Eigen::Vector2d(h, 0), v)) / 2e-3;
  const double along_y =
      (AngleTowards(c + Eigen::Vector2d(0, h), v) - AngleTowards(c - Eigen::Vector2d(0, h), v)) / 2e-3;
  EXPECT_NEAR(f[4], AngleTowards(c, v), 0.02);
  EXPECT_NEAR(f[5], along_x, 0.15 * std::abs(along_y));  // ~0 here: the centre is level with the vanishing point
  EXPECT_NEAR(f[6], along_y, 0.15 * std::abs(along_y));
  EXPECT_GT(std::abs(f[6]), 1.0);  // clearly converging: a radian per image width
  // The vertical edges stay parallel (b is the image's vertical).
  EXPECT_LT(f.segment<3>(7).cwiseAbs().maxCoeff(), 1e-6);
}

// Points on a grid whose edge angles are a known linear function of position are fitted exactly (up to the
// ridge), in both families, with coherence as the weight.
TEST(Layout, RecoversALinearAngleField) {
  RegionWords r;
  r.image_size = cv::Size(static_cast<int>(kWidth), static_cast<int>(kHeight));
  r.box = cv::Rect2d(100, 60, 80, 64);
  const Eigen::Vector2d c(140, 92);
  const Eigen::Vector3d horizontal(0.1, 0.4, -0.3), vertical(-0.2, 0.25, 0.5);  // (a, b, c) per image width
  for (int y = 62; y < 124; y += 4) {
    for (int x = 102; x < 180; x += 4) {
      for (int family = 0; family < 2; ++family) {
        const Eigen::Vector3d& m = family == 0 ? horizontal : vertical;
        const double edge = m[0] + m[1] * (x - c.x()) / kWidth + m[2] * (y - c.y()) / kWidth;
        const double gradient = family == 0 ? edge + M_PI / 2 : std::fmod(edge + M_PI, M_PI);
        r.points.emplace_back(static_cast<float>(x), static_cast<float>(y));
        r.angle.push_back(static_cast<float>(gradient));
        r.coherence.push_back(family == 0 ? 1.0f : 0.5f);
      }
    }
  }
  const Eigen::VectorXd f = LayoutFeature(r);
  EXPECT_LT((f.segment<3>(4) - horizontal).cwiseAbs().maxCoeff(), 2e-3) << f.segment<3>(4).transpose();
  EXPECT_LT((f.segment<3>(7) - vertical).cwiseAbs().maxCoeff(), 2e-3) << f.segment<3>(7).transpose();
  EXPECT_NEAR(f[10], 1 / 1.25, 1e-9);  // weights 1 and 0.25
}

TEST(Layout, WithoutEdgesTheFitsAreZero) {
  RegionWords r = LinesOnPlane({0, 0, 3}, {1, 0, 0}, {0, 1, 0});
  for (float& c : r.coherence) c = 0;  // isotropic patches say nothing about edges
  const Eigen::VectorXd f = LayoutFeature(r);
  EXPECT_EQ(f.segment<6>(4).norm(), 0);
  EXPECT_EQ(f[10], 0.5);
  r.image_size = cv::Size();
  EXPECT_THROW(LayoutFeature(r), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
