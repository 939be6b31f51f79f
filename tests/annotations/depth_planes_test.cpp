#include "pdvo/annotations/depth_planes.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/mask_polygons.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"
#include "pdvo/test/scenes.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

struct Recovered {
  double iou = 0, worst_angle_deg = 0;
};

// For ground-truth plane `id`: the found plane shapes lying mostly on it (an occluder may split a plane into
// several), the IoU of their union with the plane, and the largest angle between their normals and the truth.
// Pixels within 10 px of the bush are left out: floor seen through gaps in foliage belongs to the bush's blob.
Recovered Recover(const Annotation& a, const test::RenderedDepth& truth, int id, const Eigen::Vector3d& normal) {
  cv::Mat near_bush;
  cv::dilate(truth.label >= 1000, near_bush, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(21, 21)));
  const cv::Mat want = (truth.label == id) & ~near_bush;
  cv::Mat got(want.size(), CV_8U, cv::Scalar(0));
  Recovered r;
  for (const AnnotationShape& s : a.shapes) {
    if (!s.IsPlane()) continue;
    const cv::Mat mask = RasteriseShape(s, a);
    if (cv::countNonZero(mask & want) < 0.5 * cv::countNonZero(mask)) continue;
    got |= mask & ~near_bush;
    r.worst_angle_deg = std::max(r.worst_angle_deg, AngleDeg(*s.normal, normal));
  }
  r.iou = cv::countNonZero(want & got) / static_cast<double>(cv::countNonZero(want | got));
  return r;
}

TEST(DepthPlanes, RecoversTheRoomsPlanesAndMarksTheBush) {
  std::vector<test::ScenePlane> planes;
  std::vector<test::SceneSphere> spheres;
  test::RoomScene(&planes, &spheres);
  const Camera camera = test::SceneCamera();
  const DepthPlaneOptions options;
  const test::RenderedDepth truth = test::RenderDepth(camera, planes, spheres, options.noise_a, options.noise_b, 7);
  const DepthPlaneFinder finder(camera, options);
  const Annotation a = finder.Annotate(truth.depth, "rgb.png");
  EXPECT_TRUE(std::none_of(Validate(a).begin(), Validate(a).end(), [](const auto& i) { return i.is_error; }));
  for (int id = 0; id < 3; ++id) {
    const Recovered r = Recover(a, truth, id, planes[id].normal);
    EXPECT_GT(r.iou, 0.9) << "plane " << id << " covers " << cv::countNonZero(truth.label == id) << " px";
    EXPECT_LT(r.worst_angle_deg, 0.5) << "plane " << id;
  }
  // The bush of small spheres is non-planar: mostly covered by non-plane shapes, hardly by planes.
  const AnnotationMasks m = Rasterise(a);
  const cv::Mat bush = truth.label >= 1000;
  EXPECT_GT(cv::countNonZero(bush & (m.label == kMaskNonPlane)), 0.7 * cv::countNonZero(bush));
  EXPECT_LT(cv::countNonZero(bush & (m.label == kMaskPlane)), 0.05 * cv::countNonZero(bush));
}

TEST(DepthPlanes, PlaneParametersMatchTheTruthWithoutNoise) {
  std::vector<test::ScenePlane> planes;
  std::vector<test::SceneSphere> spheres;
  test::RoomScene(&planes, &spheres);
  const Camera camera = test::SceneCamera();
  const test::RenderedDepth truth = test::RenderDepth(camera, planes, {}, 0, 0, 1);
  const std::vector<DepthPlane> found = DepthPlaneFinder(camera, {}).FindPlanes(truth.depth);
  ASSERT_EQ(found.size(), 3u);
  for (const DepthPlane& f : found) {
    double best = 1e9;
    for (const auto& p : planes)
      best = std::min(best, (f.normal - p.normal).norm() + std::abs(f.distance - p.distance));
    EXPECT_LT(best, 1e-4);
  }
}

TEST(DepthPlanes, EmptyOrWrongDepthIsHandled) {
  const Camera camera = test::SceneCamera();
  const DepthPlaneFinder finder(camera, {});
  const Annotation a = finder.Annotate(cv::Mat(240, 320, CV_32F, cv::Scalar(0)), "x.png");
  EXPECT_TRUE(a.shapes.empty());
  EXPECT_THROW(finder.Annotate(cv::Mat(10, 10, CV_32F, cv::Scalar(1)), "x.png"), InvalidArgument);
  EXPECT_THROW(finder.Annotate(cv::Mat(240, 320, CV_16U, cv::Scalar(1)), "x.png"), InvalidArgument);
  DepthPlaneOptions bad;
  bad.max_normal_angle_deg = 95;
  EXPECT_THROW(DepthPlaneFinder(camera, bad), InvalidArgument);
}

TEST(DepthPlanes, OptionsRoundTripThroughYaml) {
  test::TempDir dir;
  DepthPlaneOptions o;
  o.inlier_sigmas = 2.5;
  o.working_width = 160;
  SaveOptions(dir / "o.yaml", o, "annotate_depth");
  EXPECT_EQ(LoadOptions<DepthPlaneOptions>(dir / "o.yaml", "annotate_depth"), o);
  EXPECT_NE(o, DepthPlaneOptions());
}

TEST(MaskToPolygons, LargeHolesAreCutOutSmallOnesFilled) {
  cv::Mat mask(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(10, 10, 80, 80), cv::Scalar(255), cv::FILLED);
  cv::rectangle(mask, cv::Rect(30, 40, 30, 30), cv::Scalar(0), cv::FILLED);  // large hole
  cv::rectangle(mask, cv::Rect(70, 20, 3, 3), cv::Scalar(0), cv::FILLED);    // small hole
  const auto polygons = MaskToPolygons(mask, 100, 50, 1.0, 0.5);
  ASSERT_EQ(polygons.size(), 1u);
  EXPECT_FALSE(PolygonSelfIntersects(polygons[0]));
  AnnotationShape s;
  s.label = kPlaneLabel;
  s.points = polygons[0];
  Annotation a;
  a.image_width = a.image_height = 100;
  const cv::Mat filled = RasteriseShape(s, a);
  EXPECT_EQ(filled.at<uchar>(55, 45), 0);    // inside the large hole
  EXPECT_EQ(filled.at<uchar>(21, 71), 255);  // the small hole is filled
  EXPECT_EQ(filled.at<uchar>(80, 80), 255);
  // Everything but the large hole and the keyhole cut is covered.
  EXPECT_NEAR(cv::countNonZero(filled), 80 * 80 - 30 * 30, 80 * 80 * 0.03);
}

TEST(MaskToPolygons, ScalesToFullResolutionAndDropsSmallRegions) {
  cv::Mat mask(50, 50, CV_8U, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(10, 10, 20, 20), cv::Scalar(255), cv::FILLED);
  cv::rectangle(mask, cv::Rect(40, 40, 4, 4), cv::Scalar(255), cv::FILLED);
  const auto polygons = MaskToPolygons(mask, 50, 10, 2.0, 1.0);
  ASSERT_EQ(polygons.size(), 1u);
  // Pixel centres 10..29 at half resolution are 20.5..59.5 at full resolution.
  double min_x = 1e9, max_x = -1e9;
  for (const auto& p : polygons[0]) min_x = std::min(min_x, p.x()), max_x = std::max(max_x, p.x());
  EXPECT_DOUBLE_EQ(min_x, 20.5);
  EXPECT_DOUBLE_EQ(max_x, 58.5);
}

// A plane whose (estimated) normal points away from the camera at its polygon is kept, its normal turned just past
// edge-on, where the annotation's rules would have dropped it; a normal that faces the camera is kept as it is.
TEST(AddShapesFromMasks, TurnsANormalThatPointsAwayToFaceTheCamera) {
  Annotation a;
  a.image_width = 100, a.image_height = 100;
  a.camera = Camera::Pinhole(100, 100, 100, 100, 49.5, 49.5);
  cv::Mat mask(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(60, 40, 30, 20), cv::Scalar(255), cv::FILLED);  // right of the centre
  const Eigen::Vector3d away = Eigen::Vector3d(1, 0, 0.2).normalized(), facing(0, 0, -1);
  AddShapesFromMasks({{mask, away, 0.7}, {mask.t(), facing, 0.9}}, cv::Mat::zeros(100, 100, CV_8U), {}, &a);
  ASSERT_EQ(a.shapes.size(), 2u);
  for (const ValidationIssue& issue : Validate(a)) EXPECT_FALSE(issue.is_error) << issue.message;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : a.shapes[0].points) centroid += p;
  const Eigen::Vector3d ray = a.camera->Unproject(centroid / a.shapes[0].points.size()).normalized();
  const Eigen::Vector3d turned = *a.shapes[0].normal;
  EXPECT_NEAR(turned.dot(ray), -0.01, 1e-9);  // just past edge-on
  // The nearest such normal: only its component along the ray changed.
  const Eigen::Vector3d across = away - away.dot(ray) * ray;
  EXPECT_LT(AngleDeg(turned - turned.dot(ray) * ray, across), 1e-6);
  EXPECT_EQ(*a.shapes[1].normal, facing);
  EXPECT_NE(a.shapes[0].group_id, a.shapes[1].group_id);  // two planes
}

// A plane in two pieces (a pole in front of it) gives two polygons of one group_id, after the groups already there.
TEST(AddShapesFromMasks, PiecesOfOnePlaneShareAGroup) {
  Annotation a;
  a.image_width = 100, a.image_height = 100;
  AnnotationShape earlier;
  earlier.label = kPlaneLabel;
  earlier.points = {{0, 0}, {5, 0}, {5, 5}};
  earlier.group_id = 4;
  a.shapes.push_back(earlier);
  cv::Mat wall(100, 100, CV_8U, cv::Scalar(0)), ground(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(wall, cv::Rect(10, 10, 30, 40), cv::Scalar(255), cv::FILLED);
  cv::rectangle(wall, cv::Rect(50, 10, 30, 40), cv::Scalar(255), cv::FILLED);
  cv::rectangle(ground, cv::Rect(10, 70, 80, 20), cv::Scalar(255), cv::FILLED);
  const Eigen::Vector3d facing(0, 0, -1);
  AddShapesFromMasks({{wall, facing, {}}, {ground, facing, {}}}, cv::Mat::zeros(100, 100, CV_8U), {}, &a);
  ASSERT_EQ(a.shapes.size(), 4u);
  EXPECT_EQ(a.shapes[1].group_id, 5);
  EXPECT_EQ(a.shapes[2].group_id, 5);
  EXPECT_EQ(a.shapes[3].group_id, 6);
  EXPECT_EQ(PlanesOf(a).of_shape, (std::vector<int>{0, 1, 1, 2}));
}

}  // namespace
}  // namespace pdvo

namespace pdvo {
namespace {

TEST(DepthPlanes, ShippedDefaultConfigEqualsTheDefaults) {
  EXPECT_EQ(LoadOptions<DepthPlaneOptions>(PDVO_SOURCE_DIR "/annotations/config/default.yaml", "annotate_depth"),
            DepthPlaneOptions());
}

}  // namespace
}  // namespace pdvo
