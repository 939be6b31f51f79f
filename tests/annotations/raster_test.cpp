#include "pdvo/annotations/raster.h"

#include <gtest/gtest.h>

#include "pdvo/common/errors.h"
#include "pdvo/test/annotations.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

Annotation TwoShapes() {
  return test::ImageAnnotation("x.png", 200, 100,
                               {test::RectShape(kPlaneLabel, 10, 10, 89, 89, Eigen::Vector3d(0.6, 0, -0.8)),  // 80x80
                                test::RectShape(kNonPlaneLabel, 120, 20, 159, 59),                            // 40x40
                                test::Shape("sky", {{0, 0}, {199, 0}, {199, 5}})});
}

TEST(Raster, MasksCoverExactlyTheShapes) {
  const AnnotationMasks m = Rasterise(TwoShapes());
  EXPECT_EQ(cv::countNonZero(m.label == kMaskPlane), 80 * 80);
  EXPECT_EQ(cv::countNonZero(m.label == kMaskNonPlane), 40 * 40);
  EXPECT_EQ(m.shape_index.at<int>(50, 50), 0);
  EXPECT_EQ(m.shape_index.at<int>(40, 140), 1);
  EXPECT_EQ(m.shape_index.at<int>(2, 100), -1);  // unknown labels are skipped
  EXPECT_EQ(m.label.at<uchar>(95, 5), kMaskUnknown);
  const cv::Vec3f n = m.normal.at<cv::Vec3f>(50, 50);
  EXPECT_FLOAT_EQ(n[0], 0.6f);
  EXPECT_FLOAT_EQ(n[2], -0.8f);
  EXPECT_EQ(m.normal.at<cv::Vec3f>(40, 140), cv::Vec3f(0, 0, 0));
}

TEST(Raster, PointsFarOutsideTheImageAreBoundedNotOverflowed) {
  // A triangle with corners at 1e300: it covers the whole image (its far edges are far outside it).
  const Annotation a =
      test::ImageAnnotation("x.png", 200, 100, {test::Shape(kPlaneLabel, {{-1, -1}, {1e300, -1}, {-1, 1e300}})});
  const AnnotationMasks m = Rasterise(a);
  EXPECT_EQ(cv::countNonZero(m.label == kMaskPlane), 200 * 100);
  EXPECT_EQ(RasteriseShape(a.shapes[0], a, {}).size(), cv::Size(200, 100));
}

TEST(Raster, HalfResolutionMasksScaleWithPixelCentres) {
  const AnnotationMasks m = Rasterise(TwoShapes(), cv::Size(100, 50));
  // 80 full pixels are 40 half pixels (the edges may round either way).
  EXPECT_NEAR(cv::countNonZero(m.label == kMaskPlane), 40 * 40, 2 * 41);
  EXPECT_EQ(m.shape_index.at<int>(25, 25), 0);
}

TEST(Raster, LaterShapesWin) {
  Annotation a = TwoShapes();
  a.shapes[1].points = {{50, 50}, {70, 50}, {70, 70}, {50, 70}};
  const AnnotationMasks m = Rasterise(a);
  EXPECT_EQ(m.shape_index.at<int>(60, 60), 1);
  EXPECT_EQ(m.label.at<uchar>(60, 60), kMaskNonPlane);
}

TEST(Raster, NormalColourMapsAxes) {
  const cv::Scalar facing = NormalColour(Eigen::Vector3d(0, 0, -1));
  EXPECT_NEAR(facing[0], 0, 1e-9);      // blue from z = -1
  EXPECT_NEAR(facing[1], 127.5, 1e-9);  // green from y = 0
  EXPECT_NEAR(facing[2], 127.5, 1e-9);  // red from x = 0
  EXPECT_NEAR(NormalColour(Eigen::Vector3d(1, 0, 0))[2], 255, 1e-9);
}

TEST(Raster, OverlayTintsPlanesByNormalAndAddsALegend) {
  const Annotation a = TwoShapes();
  const cv::Mat image(100, 200, CV_8UC3, cv::Scalar(128, 128, 128));
  OverlayOptions options;
  options.alpha = 1.0;
  const cv::Mat out = DrawOverlay(image, a, options);
  EXPECT_GT(out.cols, 200);  // the legend panel
  EXPECT_GE(out.rows, 100);
  // Inside the plane, away from the arrow and outline: the normal's colour.
  const cv::Scalar expected = NormalColour(Eigen::Vector3d(0.6, 0, -0.8));
  const cv::Vec3b px = out.at<cv::Vec3b>(80, 20);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(px[c], expected[c], 1.0);
  // Unknown pixels are untouched.
  EXPECT_EQ(out.at<cv::Vec3b>(95, 180), cv::Vec3b(128, 128, 128));
  // Without a legend the size is the image's.
  options.legend = false;
  EXPECT_EQ(DrawOverlay(image, a, options).size(), image.size());
  EXPECT_THROW(DrawOverlay(cv::Mat(10, 10, CV_8UC3), a), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
