#include "pdvo/annotations/regions.h"

#include <gtest/gtest.h>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/test/annotations.h"

namespace pdvo {
namespace {

// A 400x200 image: an L-shaped plane on the left, a non-plane square on the right, an unknown-label strip.
Annotation Scene() {
  return test::ImageAnnotation(
      "x.png", 400, 200,
      {test::Shape(kPlaneLabel, {{0, 0}, {199, 0}, {199, 79}, {79, 79}, {79, 199}, {0, 199}},
                   Eigen::Vector3d(0, 0, -1)),
       test::RectShape(kNonPlaneLabel, 250, 50, 349, 149), test::Shape("sky", {{200, 0}, {399, 0}, {399, 20}})});
}

TEST(Regions, WholeShapesAndPureWindowsAtTheWorkingSize) {
  const Annotation a = Scene();
  const std::vector<std::pair<double, cv::Size>> cases = {
      {1.0, {400, 200}}, {1.0, {200, 100}}, {4.0, {400, 200}}, {4.0, {200, 100}}};
  for (const auto& [aspect, size] : cases) {
    SCOPED_TRACE(aspect);
    const double s = size.width / 400.0;
    RegionSamplingOptions o;
    o.min_window = 10;
    o.min_shape_area = 0;
    o.windows_per_shape = 40;
    o.max_window_aspect = aspect;
    std::mt19937_64 rng(3);
    const std::vector<LabelledRegion> regions = SampleRegions(a, size, o, rng);
    const AnnotationMasks masks = Rasterise(a, size);
    int whole = 0, windows = 0, wide = 0, tall = 0;
    for (const LabelledRegion& r : regions) {
      ASSERT_GE(r.shape, 0);
      ASSERT_LT(r.shape, 2) << "the unknown label is skipped";
      EXPECT_EQ(r.planar, r.shape == 0);
      EXPECT_EQ(r.normal.has_value(), r.shape == 0);
      if (r.whole_shape) {
        ++whole;
        const double expected = r.shape == 0 ? 200 * 80 + 80 * 120 : 100 * 100;
        EXPECT_NEAR(r.region.Area(), expected * s * s, expected * s * s * 0.02);
        continue;
      }
      ++windows;
      EXPECT_TRUE(r.region.mask.empty());
      const cv::Rect& box = r.region.box;
      if (aspect == 1) {
        EXPECT_EQ(box.width, box.height);
      }
      // Sides are truncated to whole pixels: the aspect ratio and the size are within a pixel of their bounds.
      EXPECT_LE(box.width, aspect * (box.height + 1));
      EXPECT_LE(box.height, aspect * (box.width + 1));
      EXPECT_GE((box.width + 1) * (box.height + 1), o.min_window * o.min_window);
      wide += box.width > 1.5 * box.height;
      tall += box.height > 1.5 * box.width;
      // Pure: every pixel of the window carries the shape's label.
      const cv::Mat labels = masks.label(r.region.box);
      const uchar want = r.planar ? kMaskPlane : kMaskNonPlane;
      EXPECT_EQ(cv::countNonZero(labels != want), 0) << r.region.box;
    }
    EXPECT_EQ(whole, 2);
    EXPECT_EQ(windows, 2 * o.windows_per_shape);
    if (aspect > 1) {  // of 80 windows, log-uniform aspect ratios in [1/4, 4]: about 28 wider than 1.5, 28 taller
      EXPECT_GE(wide, 10);
      EXPECT_GE(tall, 10);
    }
  }
}

TEST(Regions, SameSeedSameRegionsAndContainsFollowsTheMask) {
  const Annotation a = Scene();
  RegionSamplingOptions o;
  std::mt19937_64 r1(9), r2(9), r3(10);
  const auto a1 = SampleRegions(a, {400, 200}, o, r1), a2 = SampleRegions(a, {400, 200}, o, r2),
             a3 = SampleRegions(a, {400, 200}, o, r3);
  ASSERT_EQ(a1.size(), a2.size());
  bool differs = a1.size() != a3.size();
  for (size_t i = 0; i < a1.size(); ++i) {
    EXPECT_EQ(a1[i].region.box, a2[i].region.box);
    differs = differs || (i < a3.size() && a1[i].region.box != a3[i].region.box);
  }
  EXPECT_TRUE(differs);
  const Region& l = a1.front().region;  // the L-shaped plane
  ASSERT_TRUE(a1.front().whole_shape);
  EXPECT_TRUE(l.Contains({10, 150}));
  EXPECT_TRUE(l.Contains({150, 10}));
  EXPECT_FALSE(l.Contains({150, 150}));  // inside the box, outside the L
  EXPECT_FALSE(l.Contains({300, 100}));
}

TEST(Regions, SmallShapesAreSkippedAndBadOptionsThrow) {
  const Annotation a = Scene();
  RegionSamplingOptions o;
  o.min_shape_area = 30000;  // larger than both shapes (25600 and 10000 px) at 400x200
  std::mt19937_64 rng(1);
  EXPECT_TRUE(SampleRegions(a, {400, 200}, o, rng).empty());
  o.min_window = 2;
  EXPECT_THROW(SampleRegions(a, {400, 200}, o, rng), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
