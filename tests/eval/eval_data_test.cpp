// Checks on the real data sets in ../shared/data. Labelled `data`; skips when they are absent.
#include <gtest/gtest.h>

#include <filesystem>

#include "pdvo/annotations/depth_planes.h"
#include "pdvo/common/dataset.h"
#include "pdvo/eval/plane_match.h"
#include "pdvo/eval/trajectory_error.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {
namespace fs = std::filesystem;

// The shipped camera file of the TUM Freiburg 1 sequences.
Camera TumFr1Camera() { return Camera::Read(PDVO_SOURCE_DIR "/config/cameras/tum_fr1.yaml"); }

TEST(EvalData, AteOfGroundTruthAgainstASimilarCopyOfItself) {
  for (const auto& [name, file, format] :
       {std::tuple{"tum_rgbd_fr1_rpy_excerpt", "groundtruth.txt", TrajectoryFormat::kTum},
        std::tuple{"kitti_odometry_06_excerpt", "poses.txt", TrajectoryFormat::kKitti}}) {
    const std::string dir = test::DataPath(name);
    if (dir.empty()) GTEST_SKIP() << name << " not found under " PDVO_TEST_DATA_DIR;
    const Trajectory gt = ReadTrajectory(dir + "/" + file, format);
    Trajectory copy = gt;
    Sim3d s;
    s.scale = 3.0;
    s.rotation = ExpSO3(Eigen::Vector3d(0.2, 0.4, -0.1));
    s.translation = Eigen::Vector3d(1, 2, 3);
    for (StampedPose& p : copy) p.world_from_cam = s * p.world_from_cam;
    const AteResult r = ComputeAte(gt, copy, Alignment::kSim3, 1e-3);
    EXPECT_EQ(r.matched, gt.size()) << name;
    EXPECT_LT(r.translation.rmse, 1e-6) << name;
    EXPECT_NEAR(r.gt_from_estimate.scale, 1 / 3.0, 1e-6) << name;
  }
}

// annotate-depth against the independent reference annotations of the TUM excerpt. Its options were chosen on
// the first 25 annotated frames; this checks the other 25, which they were not tuned on.
TEST(EvalData, AnnotateDepthMatchesTumReferenceOnHeldOutFrames) {
  PDVO_REQUIRE_DATA(dir, "tum_rgbd_fr1_rpy_excerpt");
  const DepthPlaneFinder finder(TumFr1Camera(), {});
  auto sequence = OpenSequence(dir);
  std::vector<std::string> references;
  for (const auto& e : fs::directory_iterator(dir + "/annotations")) references.push_back(e.path().string());
  std::sort(references.begin(), references.end());
  ASSERT_GE(references.size(), 50u);
  const std::set<std::string> held_out(references.begin() + 25, references.end());
  std::vector<PlaneComparison> comparisons;
  Frame frame;
  while (sequence->Next(&frame)) {
    const std::string ref = dir + "/annotations/" + fs::path(frame.image_path).stem().string() + ".json";
    if (!held_out.count(ref)) continue;
    comparisons.push_back(ComparePlanes(ReadAnnotation(ref), finder.Annotate(frame.depth, frame.image_path)));
  }
  ASSERT_EQ(comparisons.size(), 25u);
  const PlaneComparisonSummary s = Summarise(comparisons);
  EXPECT_GT(s.median_iou, 0.6);
  EXPECT_LT(s.median_normal_angle_deg, 5.0);
  // The large surfaces the reference marks (desk, monitors, walls) are found.
  EXPECT_GE(s.matched, 0.9 * s.reference_planes);
  std::printf("held-out TUM frames: %d, %d of %d reference planes matched, median IoU %.3f, median normal %.2f deg\n",
              s.frames, s.matched, s.reference_planes, s.median_iou, s.median_normal_angle_deg);
}

}  // namespace
}  // namespace pdvo
