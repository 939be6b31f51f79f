#include "pdvo/common/trajectory.h"

#include <gtest/gtest.h>

#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

Trajectory RandomTrajectory(int n) {
  std::mt19937 rng(6);
  std::normal_distribution<double> g(0, 1);
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    t.push_back({100.0 + 0.1 * i, Rigid3d(ExpSO3({g(rng), g(rng), g(rng)}), {g(rng), g(rng), g(rng)})});
  }
  return t;
}

void ExpectSamePoses(const Trajectory& a, const Trajectory& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_LT((a[i].world_from_cam.translation - b[i].world_from_cam.translation).norm(), tol);
    EXPECT_LT(AngularDistance(a[i].world_from_cam.rotation, b[i].world_from_cam.rotation), tol);
  }
}

TEST(Trajectory, TumRoundTrip) {
  test::TempDir dir;
  const Trajectory t = RandomTrajectory(20);
  WriteTrajectory(dir / "t.txt", t, TrajectoryFormat::kTum);
  const Trajectory r = ReadTrajectory(dir / "t.txt", TrajectoryFormat::kTum);
  ExpectSamePoses(t, r, 1e-7);
  for (size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(r[i].timestamp, t[i].timestamp, 1e-6);
}

TEST(Trajectory, KittiRoundTripWithTimes) {
  test::TempDir dir;
  const Trajectory t = RandomTrajectory(10);
  WriteTrajectory(dir / "poses.txt", t, TrajectoryFormat::kKitti);
  std::string times;
  for (const auto& p : t) times += std::to_string(p.timestamp) + "\n";
  WriteFileAtomically(dir / "times.txt", times);
  const Trajectory r = ReadTrajectory(dir / "poses.txt", TrajectoryFormat::kKitti, dir / "times.txt");
  ExpectSamePoses(t, r, 1e-7);
  EXPECT_NEAR(r[3].timestamp, t[3].timestamp, 1e-6);
  // Without times, the index is the time.
  EXPECT_EQ(ReadTrajectory(dir / "poses.txt", TrajectoryFormat::kKitti)[4].timestamp, 4.0);
}

TEST(Trajectory, PathLength) {
  Trajectory t(3);
  t[1].world_from_cam.translation = {3, 4, 0};
  t[2].world_from_cam.translation = {3, 4, 2};
  EXPECT_DOUBLE_EQ(PathLength(t), 7.0);
}

std::string ErrorOf(const std::string& content, TrajectoryFormat format = TrajectoryFormat::kTum) {
  test::TempDir dir;
  WriteFileAtomically(dir / "t.txt", content);
  try {
    ReadTrajectory(dir / "t.txt", format);
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

TEST(Trajectory, BadFilesGiveOneLineErrorsWithFileAndLine) {
  EXPECT_NE(ErrorOf("# only a comment\n").find("contains no poses"), std::string::npos);
  EXPECT_NE(ErrorOf("").find("contains no poses"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n").find("t.txt:2: timestamp 1 does not increase"),
            std::string::npos);
  EXPECT_NE(ErrorOf("2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n").find("does not increase"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 0 0 0 0 1\n").find("t.txt:1: expected 8 numbers, found 7"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 nan 0 0 0 0 1\n").find("not finite"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 x 0 0 0 0 1\n").find("'x' is not a number"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 0 0 0 0 0 0\n").find("zero quaternion"), std::string::npos);
  EXPECT_NE(ErrorOf("1 0 0 0 0 1 0 0 0 0 0 0\n", TrajectoryFormat::kKitti).find("not a rotation"), std::string::npos);
  EXPECT_THROW(ReadTrajectory("/nonexistent.txt", TrajectoryFormat::kTum), IoError);
  EXPECT_THROW(ParseTrajectoryFormat("euroc"), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
