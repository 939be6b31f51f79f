// Detection scores on hand-made annotations with known answers: a perfect detection; one plane over the whole
// image with a turned normal (half its area false, matched within 30 degrees but not 10); a plane detected as two
// halves (Rand index about one half, one bit of variation of information, covering one half); why planes are not
// matched, what a merged plane runs onto, and the pieces of one plane (one group_id) scored as one plane.
#include "pdvo/eval/detection.h"

#include <gtest/gtest.h>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

AnnotationShape Rect(const char* label, double x0, double y0, double x1, double y1,
                     std::optional<Eigen::Vector3d> normal = std::nullopt) {
  AnnotationShape s;
  s.label = label;
  s.points = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  s.normal = normal;
  return s;
}

Annotation Image(std::vector<AnnotationShape> shapes) {
  Annotation a;
  a.image_path = "x.png";
  a.image_width = 100;
  a.image_height = 80;
  a.shapes = std::move(shapes);
  return a;
}

const Eigen::Vector3d kFacing(0, 0, -1);

Annotation Reference() {
  return Image({Rect(kPlaneLabel, -0.5, -0.5, 49.5, 79.5, kFacing), Rect(kNonPlaneLabel, 49.5, -0.5, 99.5, 79.5)});
}

TEST(DetectionScore, APerfectDetection) {
  const DetectionSummary m = Summarise({ScoreDetection(Reference(), Reference())});
  EXPECT_DOUBLE_EQ(m.plane_f1, 1);
  EXPECT_DOUBLE_EQ(m.nonplane_f1, 1);
  EXPECT_DOUBLE_EQ(m.false_plane_area, 0);
  EXPECT_EQ(m.reference_planes, 1);
  EXPECT_DOUBLE_EQ(m.plane_recall_10, 1);
  EXPECT_NEAR(m.median_normal_error_deg, 0, 1e-6);
  EXPECT_EQ(m.spurious_planes, 0);
  EXPECT_DOUBLE_EQ(m.rand_index, 1);
  EXPECT_NEAR(m.variation_of_information, 0, 1e-12);
  EXPECT_DOUBLE_EQ(m.covering, 1);
}

TEST(DetectionScore, OnePlaneOverEverything) {
  const Eigen::Vector3d turned(std::sin(20 * M_PI / 180), 0, -std::cos(20 * M_PI / 180));
  const DetectionScore s = ScoreDetection(Reference(), Image({Rect(kPlaneLabel, -0.5, -0.5, 99.5, 79.5, turned)}));
  const DetectionSummary m = Summarise({s});
  EXPECT_NEAR(m.plane_precision, 0.5, 0.02);
  EXPECT_DOUBLE_EQ(m.plane_recall, 1);
  EXPECT_NEAR(m.false_plane_area, 0.5, 0.02);
  EXPECT_DOUBLE_EQ(m.nonplane_recall, 0);
  EXPECT_DOUBLE_EQ(m.plane_recall_10, 0);
  EXPECT_DOUBLE_EQ(m.plane_recall_30, 1);  // IoU 0.5 with the reference plane
  EXPECT_NEAR(m.median_normal_error_deg, 20, 1e-6);
}

TEST(DetectionScore, APlaneInTwoHalves) {
  const DetectionScore s = ScoreDetection(Reference(), Image({Rect(kPlaneLabel, -0.5, -0.5, 49.5, 39.5, kFacing),
                                                              Rect(kPlaneLabel, -0.5, 39.5, 49.5, 79.5, kFacing),
                                                              Rect(kNonPlaneLabel, 49.5, -0.5, 99.5, 79.5)}));
  EXPECT_DOUBLE_EQ(Summarise({s}).plane_f1, 1);
  EXPECT_EQ(s.matched_10, 1);       // each half has IoU 0.5: the first is the match
  EXPECT_EQ(s.spurious_planes, 1);  // and the other half spurious
  EXPECT_NEAR(s.rand_index, 0.5, 0.01);
  EXPECT_NEAR(s.variation_of_information, 1, 0.01);
  EXPECT_NEAR(s.covering, 0.5, 0.01);
  Annotation other = Reference();
  other.image_width = 50;
  EXPECT_THROW(ScoreDetection(Reference(), other), FormatError);
}

// A plane seen on both sides of a pole: its two pieces (columns 0-19 and 30-49) share a group_id and are one
// reference plane, which one detected plane over columns 0-49 matches (IoU 0.8); as two planes, each piece would
// hold under half of that detection (IoU 0.4) and neither would be matched. Detected pieces are grouped likewise.
TEST(DetectionScore, PiecesOfOnePlaneAreOnePlane) {
  AnnotationShape left = Rect(kPlaneLabel, -0.5, -0.5, 19.5, 79.5, kFacing);
  AnnotationShape right = Rect(kPlaneLabel, 29.5, -0.5, 49.5, 79.5, kFacing);
  const AnnotationShape pole = Rect(kNonPlaneLabel, 19.5, -0.5, 29.5, 79.5);
  const Annotation whole = Image({Rect(kPlaneLabel, -0.5, -0.5, 49.5, 79.5, kFacing)});
  const DetectionScore apart = ScoreDetection(Image({left, right, pole}), whole);
  EXPECT_EQ(apart.reference_planes, 2);
  EXPECT_EQ(apart.matched_30, 0);
  left.group_id = right.group_id = 7;
  const Annotation grouped = Image({left, right, pole});
  const DetectionScore together = ScoreDetection(grouped, whole);
  EXPECT_EQ(together.reference_planes, 1);
  EXPECT_EQ(together.matched_10, 1);
  EXPECT_EQ(together.spurious_planes, 0);
  const DetectionScore both_grouped = ScoreDetection(grouped, grouped);
  EXPECT_EQ(both_grouped.matched_10, 1);
  EXPECT_EQ(both_grouped.spurious_planes, 0);
  EXPECT_DOUBLE_EQ(both_grouped.covering, 1);
}

// Why a reference plane (the left half, 50 x 80) is not matched: a detection holding all of it and the non-plane
// beside it, and more (IoU 0.4): merged; four quarters of it (none half): fragmented; a quarter only: missed; the
// plane itself with a normal 40 degrees off: turned.
TEST(DetectionScore, SaysWhyAPlaneIsNotMatched) {
  const auto unmatched = [](const DetectionScore& s) {
    const Unmatched& u = s.unmatched;
    return std::vector<int>{u.merged(), u.fragmented, u.missed, u.turned};
  };
  const Eigen::Vector3d turned(std::sin(40 * M_PI / 180), 0, -std::cos(40 * M_PI / 180));
  Annotation wide = Image({Rect(kPlaneLabel, -0.5, -0.5, 124.5, 79.5, kFacing)});
  wide.image_width = 125;  // the whole image: the reference plane and 75 columns more, IoU 0.4
  Annotation reference = Reference();
  reference.image_width = 125;
  EXPECT_EQ(unmatched(ScoreDetection(reference, wide)), (std::vector<int>{1, 0, 0, 0}));
  EXPECT_EQ(unmatched(ScoreDetection(Reference(), Image({Rect(kPlaneLabel, -0.5, -0.5, 24.5, 39.5, kFacing),
                                                         Rect(kPlaneLabel, 24.5, -0.5, 49.5, 39.5, kFacing),
                                                         Rect(kPlaneLabel, -0.5, 39.5, 24.5, 79.5, kFacing),
                                                         Rect(kPlaneLabel, 24.5, 39.5, 49.5, 79.5, kFacing)}))),
            (std::vector<int>{0, 1, 0, 0}));
  EXPECT_EQ(unmatched(ScoreDetection(Reference(), Image({Rect(kPlaneLabel, -0.5, -0.5, 24.5, 39.5, kFacing)}))),
            (std::vector<int>{0, 0, 1, 0}));
  EXPECT_EQ(unmatched(ScoreDetection(Reference(), Image({Rect(kPlaneLabel, -0.5, -0.5, 49.5, 79.5, turned)}))),
            (std::vector<int>{0, 0, 0, 1}));
  EXPECT_EQ(unmatched(ScoreDetection(Reference(), Reference())), (std::vector<int>{0, 0, 0, 0}));
}

// Where a merged plane runs: the reference plane is columns 0-24 (facing the camera); the detected plane covers
// columns 0-74, whose columns 25-74 are, in turn, a plane of the same orientation, a plane turned 60 degrees, a
// non-plane, and not annotated.
TEST(DetectionScore, SaysWhatAMergedPlaneRunsOnto) {
  const Eigen::Vector3d angled(std::sin(60 * M_PI / 180), 0, -std::cos(60 * M_PI / 180));
  const AnnotationShape plane = Rect(kPlaneLabel, -0.5, -0.5, 24.5, 79.5, kFacing);
  const Annotation detection = Image({Rect(kPlaneLabel, -0.5, -0.5, 74.5, 79.5, kFacing)});
  const auto merged_with = [&](std::vector<AnnotationShape> rest) {
    rest.insert(rest.begin(), plane);
    const DetectionScore s = ScoreDetection(Image(rest), detection);
    const Unmatched& u = s.unmatched;
    EXPECT_EQ(u.merged(), 1);
    return std::vector<int>{u.merged_parallel, u.merged_angled, u.merged_nonplane, u.merged_unannotated};
  };
  EXPECT_EQ(merged_with({Rect(kPlaneLabel, 24.5, -0.5, 74.5, 79.5, kFacing)}), (std::vector<int>{1, 0, 0, 0}));
  EXPECT_EQ(merged_with({Rect(kPlaneLabel, 24.5, -0.5, 74.5, 79.5, angled)}), (std::vector<int>{0, 1, 0, 0}));
  EXPECT_EQ(merged_with({Rect(kNonPlaneLabel, 24.5, -0.5, 74.5, 79.5)}), (std::vector<int>{0, 0, 1, 0}));
  EXPECT_EQ(merged_with({}), (std::vector<int>{0, 0, 0, 1}));
  // Counted in the summary and the JSON.
  const DetectionScore s = ScoreDetection(Image({plane, Rect(kNonPlaneLabel, 24.5, -0.5, 74.5, 79.5)}), detection);
  EXPECT_EQ(Summarise({s, s}).unmatched.merged_nonplane, 2);
  EXPECT_EQ(ToJson({s}, {})["summary"]["unmatched"]["merged_with"]["nonplane"], 1);
}

}  // namespace
}  // namespace pdvo
