// The vanishing-direction cue (vanishing.h), checked on drawn images of a lined vertical plane seen by a camera
// of known intrinsics, pitch and roll, against the plane's true normal and the true vertical.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"
#include "pdvo/infer/vanishing.h"

namespace pdvo {
namespace {

constexpr double kDegree = M_PI / 180;
const Camera kCamera = [] {
  Camera c = Camera::WithFieldOfView(320, 240, 60);
  c.fx = c.fy = 277.0;
  return c;
}();

// A vertical plane 6 m ahead whose normal points `azimuth_deg` from the optical axis, lined with horizontal
// and vertical lines, seen by a camera pitched and rolled by the given angles (the world's y axis is down).
struct Scene {
  cv::Mat image;
  Region region;           // the plane's image
  Eigen::Vector3d normal;  // camera frame, towards the camera
  Eigen::Vector3d up;      // camera frame: the world's y axis
};

// Which lines: a grid (crossing each other), or horizontal lines on one half of the plane and vertical ones
// on the other, or only one family.
enum class Lines { kGrid, kApart, kHorizontal, kVertical };

Scene DrawScene(double azimuth_deg, double pitch_deg, double roll_deg, Lines lines = Lines::kGrid) {
  const double az = azimuth_deg * kDegree;
  const Eigen::Matrix3d cam_from_world = (Eigen::AngleAxisd(roll_deg * kDegree, Eigen::Vector3d::UnitZ()) *
                                          Eigen::AngleAxisd(pitch_deg * kDegree, Eigen::Vector3d::UnitX()))
                                             .toRotationMatrix();
  const Eigen::Vector3d origin(0, 0, 6), along(std::cos(az), 0, std::sin(az)), down(0, 1, 0);
  auto project = [&](const Eigen::Vector3d& world) {
    const Eigen::Vector3d c = cam_from_world * world;
    const Eigen::Vector2d p = kCamera.Project(c);
    return cv::Point2d(p.x(), p.y());
  };
  // Drawn 4x larger and reduced by area, so that the lines' anti-aliasing keeps their sub-pixel slopes.
  constexpr int kSuper = 4;
  cv::Mat canvas(240 * kSuper, 320 * kSuper, CV_8UC3, cv::Scalar(230, 230, 230));
  constexpr double kHalfWidth = 2.5, kHalfHeight = 2.0;
  auto line = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    constexpr double kShift = 16;  // cv::line's 4 fractional bits
    auto big = [&](const cv::Point2d& p) {
      return cv::Point(static_cast<int>(std::lround(((p.x + 0.5) * kSuper - 0.5) * kShift)),
                       static_cast<int>(std::lround(((p.y + 0.5) * kSuper - 0.5) * kShift)));
    };
    cv::line(canvas, big(project(a)), big(project(b)), cv::Scalar(40, 50, 60), 2 * kSuper, cv::LINE_AA, 4);
  };
  const bool apart = lines == Lines::kApart;
  for (int i = -5; i <= 5 && lines != Lines::kVertical; ++i) {
    line(origin + 0.4 * i * down - kHalfWidth * along, origin + 0.4 * i * down + (apart ? -0.1 : kHalfWidth) * along);
  }
  for (int j = apart ? 1 : -5; j <= 5 && lines != Lines::kHorizontal; ++j) {
    line(origin + 0.5 * j * along - kHalfHeight * down, origin + 0.5 * j * along + kHalfHeight * down);
  }
  Scene s;
  cv::resize(canvas, s.image, cv::Size(320, 240), 0, 0, cv::INTER_AREA);
  std::vector<cv::Point> corners;
  for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const cv::Point2d p = project(origin + u * kHalfWidth * along + v * kHalfHeight * down);
    corners.emplace_back(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
  }
  s.region.box = cv::boundingRect(corners);
  s.region.mask = cv::Mat::zeros(s.region.box.size(), CV_8U);
  for (cv::Point& c : corners) c -= s.region.box.tl();
  cv::fillConvexPoly(s.region.mask, corners, cv::Scalar(255));
  s.normal = cam_from_world * Eigen::Vector3d(std::sin(az), 0, -std::cos(az));
  s.up = cam_from_world * down;
  return s;
}

// A 0.1-degree grid of phi over [0, pi).
std::vector<double> FineGrid() {
  std::vector<double> phis;
  for (int i = 0; i < 1800; ++i) phis.push_back((i + 0.5) * 0.1 * kDegree);
  return phis;
}

// The phi maximising the likelihood alone, on that grid.
double BestPhi(const AzimuthLikelihood& l) {
  const std::vector<double> phis = FineGrid(), v = l.MeanLogLikelihoods(phis);
  return phis[std::max_element(v.begin(), v.end()) - v.begin()];
}

TEST(Vanishing, FindsTheVerticalOfATiltedCamera) {
  for (const auto& [pitch, roll] : {std::pair{0.0, 0.0}, {8.0, 0.0}, {-6.0, 4.0}, {12.0, -3.0}}) {
    const Scene s = DrawScene(50, pitch, roll);
    const EdgePlanes e = FindEdgePlanes(s.image, kCamera, VanishingOptions());
    ASSERT_TRUE(e.up_found) << "pitch " << pitch << " roll " << roll;
    EXPECT_LT(AngleDeg(e.up, s.up), 0.5) << "pitch " << pitch << " roll " << roll;
  }
}

TEST(Vanishing, HorizontalLinesGiveTheNormalOfAVerticalPlane) {
  for (const double azimuth : {-70.0, -35.0, 0.0, 20.0, 60.0, 75.0}) {
    for (const Lines lines : {Lines::kApart, Lines::kGrid}) {
      const Scene s = DrawScene(azimuth, 7, -2, lines);
      const EdgePlanes e = FindEdgePlanes(s.image, kCamera, VanishingOptions());
      const AzimuthLikelihood l = RegionAzimuthLikelihood(e, s.region, VanishingOptions());
      ASSERT_FALSE(l.empty()) << azimuth;
      // Where lines cross, the structure tensor mixes their directions. At a grazing view all the crossings of a
      // region lean the same way, and the normal moves by up to 3 degrees (measured: 2.8 at -70, 1.6 at 60, 2.7 at
      // 75, at most 0.5 from -35 to 20); without crossings it stays within 1 (measured: at most 0.74).
      const double tolerance = lines == Lines::kApart || std::abs(azimuth) < 50 ? 1.0 : 3.0;
      EXPECT_LT(AngleDeg(l.Normal(BestPhi(l), s.normal), s.normal), tolerance)
          << "azimuth " << azimuth << (lines == Lines::kGrid ? ", grid" : ", apart");
    }
  }
}

TEST(Vanishing, WithoutTheCameraANominalFieldOfViewIsUsed) {
  const Scene s = DrawScene(40, 5, 0);
  VanishingOptions o;
  o.field_of_view_deg = 2 * std::atan(160 / kCamera.fx) / kDegree;  // kCamera's own
  const EdgePlanes with = FindEdgePlanes(s.image, kCamera, o), without = FindEdgePlanes(s.image, std::nullopt, o);
  EXPECT_LT(AngleDeg(with.up, without.up), 1e-6);
  EXPECT_NEAR(cv::norm(with.normals, without.normals, cv::NORM_INF), 0, 1e-5);
  // A camera given is used: with a 90-degree nominal view the same edges give other planes and another vertical.
  o.field_of_view_deg = 90;
  const EdgePlanes wide = FindEdgePlanes(s.image, std::nullopt, o);
  EXPECT_GT(cv::norm(with.normals, wide.normals, cv::NORM_INF), 0.05);
  EXPECT_GT(AngleDeg(with.up, wide.up), 0.5);
  EXPECT_NEAR(cv::norm(FindEdgePlanes(s.image, kCamera, o).normals, with.normals, cv::NORM_INF), 0, 1e-12);
  const Camera k = Camera::WithFieldOfView(320, 240, 90);
  EXPECT_NEAR(k.fx, 160, 1e-9);
  EXPECT_EQ(k.fy, k.fx);
  EXPECT_DOUBLE_EQ(k.cx, 159.5);
  EXPECT_DOUBLE_EQ(k.cy, 119.5);
}

TEST(Vanishing, LikelihoodIsTheMeanCauchyLogLikelihood) {
  AzimuthLikelihood l;
  l.up = Eigen::Vector3d::UnitY();
  l.e1 = Eigen::Vector3d::UnitX();
  l.e2 = l.e1.cross(l.up);
  l.residual_scale = 0.5;
  l.constraints = {{0.3f, -0.2f}, {0.0f, 0.8f}, {-0.5f, 0.1f}};
  l.weights = {1.0f, 2.0f, 0.5f};
  const std::vector<double> phis = {0.0, 0.7, 1.5, 2.9};
  const std::vector<double> batch = l.MeanLogLikelihoods(phis);
  ASSERT_EQ(batch.size(), phis.size());
  for (size_t k = 0; k < phis.size(); ++k) {
    double sum = 0;
    for (size_t i = 0; i < 3; ++i) {
      const double r = (l.constraints[i].x() * std::cos(phis[k]) + l.constraints[i].y() * std::sin(phis[k])) / 0.5;
      sum -= l.weights[i] * std::log(1 + r * r);
    }
    EXPECT_NEAR(l.MeanLogLikelihoods({phis[k]}).front(), sum / 3.5, 1e-6) << phis[k];
    EXPECT_NEAR(batch[k], sum / 3.5, 1e-6) << phis[k];
  }
  // Normal and Phi are inverse: the normal is horizontal, on the side asked for, and d(phi) lies in its plane.
  for (const double p : {0.1, 1.0, 2.0, 3.0}) {
    const Eigen::Vector3d towards(0.2, 0, -1), n = l.Normal(p, towards);
    EXPECT_NEAR(n.norm(), 1, 1e-12);
    EXPECT_NEAR(n.dot(l.up), 0, 1e-12);
    EXPECT_GT(n.dot(towards), 0);
    EXPECT_NEAR(l.Phi(n), p, 1e-9);
  }
  AzimuthLikelihood empty;
  EXPECT_THROW(empty.MeanLogLikelihoods({0.0}), InvalidArgument);
}

TEST(Vanishing, FusionMovesTheModelsAzimuthToTheEdges) {
  const Scene s = DrawScene(55, 6, 1);
  const EdgePlanes e = FindEdgePlanes(s.image, kCamera, VanishingOptions());
  // The model 25 degrees off in azimuth and 10 in elevation: the fused normal is the plane's.
  const Eigen::Vector3d model =
      (Eigen::AngleAxisd(25 * kDegree, s.up) * Eigen::AngleAxisd(10 * kDegree, Eigen::Vector3d::UnitX()) * s.normal)
          .normalized();
  ASSERT_GT(AngleDeg(model, s.normal), 20);
  const VanishingOptions o;
  const Eigen::Vector3d fused = FuseNormal(model, e, s.region, o);
  // The maximum of the posterior, against a brute-force search on a 0.1-degree grid.
  const AzimuthLikelihood l = RegionAzimuthLikelihood(e, s.region, o);
  const double prior_phi = l.Phi(model);
  const std::vector<double> phis = FineGrid(), likelihoods = l.MeanLogLikelihoods(phis);
  double best_phi = 0, best = -1e300;
  for (size_t i = 0; i < phis.size(); ++i) {
    const double p = o.prior_weight * std::cos(2 * (phis[i] - prior_phi)) + likelihoods[i];
    if (p > best) best = p, best_phi = phis[i];
  }
  const Eigen::Vector3d ray = RegionRay(kCamera, s.region);
  EXPECT_LT(AngleDeg(fused, l.Normal(best_phi, -ray)), 0.6);
  EXPECT_LT(fused.dot(ray), 0);
  // The prior pulls towards the model, the edges to the plane: much nearer the plane.
  EXPECT_LT(AngleDeg(fused, s.normal), AngleDeg(model, s.normal) / 3);
  // A strong prior keeps the model's azimuth (within the width of the likelihood's peak): a prior of 100
  // against a likelihood bounded by its range (about 1) leaves phi within a few degrees of the model's.
  VanishingOptions stubborn;
  stubborn.prior_weight = 100;
  const Eigen::Vector3d kept = FuseNormal(model, e, s.region, stubborn);
  EXPECT_GT(AngleDeg(kept, s.normal), 20);
  EXPECT_NEAR(kept.dot(e.up), 0, 1e-9);  // still snapped to a vertical plane
  // The fused plane faces the camera whichever way the model's normal points.
  EXPECT_LT(AngleDeg(FuseNormal(-model, e, s.region, o), fused), 1e-9);
  // Disabled: the model's normal as it is, if it faces the camera; else the nearest normal that does, edge-on
  // to the ray and on the model's side of it.
  VanishingOptions off;
  off.fuse_normals = false;
  ASSERT_LT(model.dot(ray), 0);
  EXPECT_EQ(FuseNormal(model, e, s.region, off), model);
  const Eigen::Vector3d away = -model, edge_on = FuseNormal(away, e, s.region, off);
  EXPECT_NEAR(edge_on.norm(), 1, 1e-12);
  EXPECT_NEAR(edge_on.dot(ray), 0, 1e-12);
  EXPECT_NEAR(AngleDeg(edge_on, away), 90 - AngleDeg(ray, away), 1e-9);
}

TEST(Vanishing, HorizontalPlanesSnapToTheVertical) {
  const Scene s = DrawScene(30, 9, 2);
  const EdgePlanes e = FindEdgePlanes(s.image, kCamera, VanishingOptions());
  const Eigen::Vector3d ground_like = (-e.up + Eigen::Vector3d(0.2, 0, -0.3)).normalized();  // about 20 deg off -up
  ASSERT_GT(std::abs(ground_like.dot(e.up)), VanishingOptions().horizontal_cos);
  // Below the horizon a horizontal plane is seen from above (a floor), above it from below (a ceiling): the
  // side that faces the camera, whichever way the model's normal points.
  const Region floor{cv::Rect(100, 200, 60, 30), cv::Mat()}, ceiling{cv::Rect(100, 5, 60, 30), cv::Mat()};
  for (const Eigen::Vector3d& model : {ground_like, Eigen::Vector3d(-ground_like)}) {
    EXPECT_EQ(FuseNormal(model, e, floor, VanishingOptions()), -e.up);
    EXPECT_EQ(FuseNormal(model, e, ceiling, VanishingOptions()), e.up);
  }
}

TEST(Vanishing, WithoutEdgesTheModelsNormalStays) {
  const cv::Mat blank(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  const EdgePlanes e = FindEdgePlanes(blank, kCamera, VanishingOptions());
  EXPECT_FALSE(e.up_found);
  EXPECT_EQ(cv::countNonZero(e.strength), 0);
  const Region region{cv::Rect(100, 60, 80, 80), cv::Mat()};
  const Eigen::Vector3d model(0.6, 0, -0.8);
  EXPECT_EQ(FuseNormal(model, e, region, VanishingOptions()), model);
  EXPECT_TRUE(RegionAzimuthLikelihood(e, region, VanishingOptions()).empty());
  EXPECT_EQ(EdgeStructure(e, region, VanishingOptions()), Eigen::Vector2d::Zero());
  // Edges only outside the region: the image has a vertical, the region nothing to say.
  const Scene s = DrawScene(30, 0, 0);
  const EdgePlanes lined = FindEdgePlanes(s.image, kCamera, VanishingOptions());
  const Region corner{cv::Rect(0, 0, 30, 30), cv::Mat()};
  ASSERT_TRUE(lined.up_found);
  EXPECT_EQ(FuseNormal(model, lined, corner, VanishingOptions()), model);
}

TEST(Vanishing, EdgeStructureCountsEdgePixelsAndVerticalStrength) {
  const Scene both = DrawScene(40, 4, 0), vertical = DrawScene(40, 4, 0, Lines::kVertical),
              horizontal = DrawScene(40, 4, 0, Lines::kHorizontal);
  const VanishingOptions o;
  const Eigen::Vector2d b = EdgeStructure(FindEdgePlanes(both.image, kCamera, o), both.region, o);
  const EdgePlanes vertical_edges = FindEdgePlanes(vertical.image, kCamera, o);
  const Eigen::Vector2d v = EdgeStructure(vertical_edges, vertical.region, o);
  // Horizontal lines alone leave no vertical to find: the image's y axis stands in for it.
  const Eigen::Vector2d h = EdgeStructure(FindEdgePlanes(horizontal.image, kCamera, o), horizontal.region, o);
  EXPECT_GT(v[1], 0.97);
  EXPECT_LT(h[1], 0.03);
  EXPECT_GT(b[1], 0.2);
  EXPECT_LT(b[1], 0.8);
  // The density is the share of the region's pixels that hold an edge, counted here directly.
  int edge_pixels = 0;
  for (int y = 0; y < vertical.region.box.height; ++y) {
    for (int x = 0; x < vertical.region.box.width; ++x) {
      const cv::Point p = vertical.region.box.tl() + cv::Point(x, y);
      const bool in_image = p.x >= 0 && p.y >= 0 && p.x < 320 && p.y < 240;
      edge_pixels += in_image && vertical.region.mask.at<uchar>(y, x) && vertical_edges.strength.at<float>(p) > 0;
    }
  }
  EXPECT_DOUBLE_EQ(v[0], edge_pixels / vertical.region.Area());
  EXPECT_GT(v[0], 0.05);
  EXPECT_GT(b[0], v[0]);
}

TEST(Vanishing, BadInputsThrow) {
  EXPECT_THROW(FindEdgePlanes(cv::Mat(), kCamera, VanishingOptions()), InvalidArgument);
  EXPECT_THROW(FindEdgePlanes(cv::Mat(10, 10, CV_32F, cv::Scalar(0)), kCamera, VanishingOptions()), InvalidArgument);
  const cv::Mat small(10, 10, CV_8U, cv::Scalar(0));
  Camera bad = Camera::WithFieldOfView(small.cols, small.rows, 60);
  bad.fx = 0;
  EXPECT_THROW(FindEdgePlanes(small, bad, VanishingOptions()), InvalidArgument);
  bad.fx = bad.fy, bad.cx = NAN;
  EXPECT_THROW(FindEdgePlanes(small, bad, VanishingOptions()), InvalidArgument);
  EXPECT_THROW(FindEdgePlanes(small, kCamera, VanishingOptions()), InvalidArgument);  // 320x240, not 10x10
  Camera distorted = Camera::WithFieldOfView(small.cols, small.rows, 60);
  distorted.distortion[0] = 0.1;
  EXPECT_THROW(FindEdgePlanes(small, distorted, VanishingOptions()), InvalidArgument);
  VanishingOptions o;
  EXPECT_TRUE(o.Check());
  o.residual_scale = 0;
  EXPECT_FALSE(o.Check());
  o = VanishingOptions();
  o.max_edges = o.min_edges - 1;
  EXPECT_FALSE(o.Check());
}

}  // namespace
}  // namespace pdvo
