#include "pdvo/eval/plane_match.h"

#include <gtest/gtest.h>

#include "pdvo/common/errors.h"
#include "pdvo/test/annotations.h"

namespace pdvo {
namespace {

AnnotationShape Rect(double x0, double y0, double x1, double y1, Eigen::Vector3d normal) {
  return test::RectShape(kPlaneLabel, x0, y0, x1, y1, normal.normalized());
}

Annotation Frame(std::vector<AnnotationShape> shapes) { return test::ImageAnnotation("", 200, 100, std::move(shapes)); }

TEST(PlaneMatch, IouAndNormalAngleOfKnownShapes) {
  // Reference: two 40x40 squares. Estimate: the first shifted by 20 px (IoU 1/3) and turned by 10 degrees;
  // the second exact; a third estimate overlaps nothing.
  const Eigen::Vector3d n(0, 0, -1);
  const Eigen::Vector3d turned(std::sin(10 * M_PI / 180), 0, -std::cos(10 * M_PI / 180));
  const Annotation ref = Frame({Rect(0, 0, 39, 39, n), Rect(100, 0, 139, 39, n)});
  const Annotation est = Frame({Rect(100, 0, 139, 39, n), Rect(20, 0, 59, 39, turned), Rect(0, 60, 30, 90, n)});
  const PlaneComparison c = ComparePlanes(ref, est);
  EXPECT_EQ(c.reference_planes, 2);
  EXPECT_EQ(c.estimated_planes, 3);
  ASSERT_EQ(c.matches.size(), 2u);
  EXPECT_EQ(c.matches[0].reference_shape, 1);  // the best pair first
  EXPECT_EQ(c.matches[0].estimated_shape, 0);
  EXPECT_NEAR(c.matches[0].iou, 1.0, 1e-12);
  EXPECT_NEAR(c.matches[0].normal_angle_deg, 0.0, 1e-6);
  EXPECT_EQ(c.matches[1].reference_shape, 0);
  EXPECT_NEAR(c.matches[1].iou, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.matches[1].normal_angle_deg, 10.0, 1e-9);
  const PlaneComparisonSummary s = Summarise({c});
  EXPECT_EQ(s.matched, 2);
  EXPECT_NEAR(s.median_iou, (1.0 + 1.0 / 3.0) / 2, 1e-12);
}

TEST(PlaneMatch, OneToOneAndUnmatchedCountAsZero) {
  const Eigen::Vector3d n(0, 0, -1);
  // One estimate covers both references; only one of them may take it.
  const Annotation ref = Frame({Rect(0, 0, 49, 49, n), Rect(50, 0, 99, 49, n)});
  const Annotation est = Frame({Rect(0, 0, 99, 49, n)});
  const PlaneComparison c = ComparePlanes(ref, est);
  ASSERT_EQ(c.matches.size(), 1u);
  EXPECT_NEAR(c.matches[0].iou, 0.5, 1e-12);
  const PlaneComparisonSummary s = Summarise({c});
  EXPECT_EQ(s.reference_planes, 2);
  EXPECT_NEAR(s.median_iou, 0.25, 1e-12);  // median of {0.5, 0}
  EXPECT_NEAR(s.median_matched_iou, 0.5, 1e-12);
  Annotation other = est;
  other.image_width = 300;
  EXPECT_THROW(ComparePlanes(ref, other), FormatError);
  // The two references as pieces of one plane (one group_id): one plane, which the estimate matches whole.
  Annotation grouped = ref;
  grouped.shapes[0].group_id = grouped.shapes[1].group_id = 0;
  grouped.shapes[1].points[0].x() -= 1;  // the second piece a column wider: the largest, which names the plane
  grouped.shapes[1].points[3].x() -= 1;
  const PlaneComparison g = ComparePlanes(grouped, est);
  EXPECT_EQ(g.reference_planes, 1);
  ASSERT_EQ(g.matches.size(), 1u);
  EXPECT_EQ(g.matches[0].reference_shape, 1);
  EXPECT_NEAR(g.matches[0].iou, 1.0, 1e-12);
}

TEST(PlanePurity, ShareOfPointsOnTheirPlanesMainLabel) {
  PlanePurity purity;
  // Frame 0: plane 1 has 3 points on surface 7 and 1 on surface 8; plane 2 has 2 points only (too few).
  for (int label : {7, 7, 8, 7}) purity.Add(0, 1, label);
  for (int label : {5, 6}) purity.Add(0, 2, label);
  // Frame 1: plane 1 again, 4 points on 4 surfaces.
  for (int label : {1, 2, 3, 4}) purity.Add(1, 1, label);
  long points = 0;
  EXPECT_DOUBLE_EQ(purity.Share(4, &points), (3.0 + 1.0) / 8.0);
  EXPECT_EQ(points, 8);
  EXPECT_DOUBLE_EQ(purity.Share(1), (3.0 + 1.0 + 1.0) / 10.0);
  EXPECT_DOUBLE_EQ(PlanePurity().Share(1, &points), 0.0);
  EXPECT_EQ(points, 0);
  EXPECT_EQ(purity.MainLabel(0, 1, 4), 7);
  EXPECT_EQ(purity.MainLabel(0, 2, 4), std::nullopt);  // too few
  EXPECT_EQ(purity.MainLabel(0, 2, 2), 5);             // a tie: the smallest label
  EXPECT_EQ(purity.MainLabel(2, 1, 1), std::nullopt);  // no such group
}

}  // namespace
}  // namespace pdvo
