// The map as PLY: header counts, vertex order (points, plane corners, camera path), faces (with their plane
// numbers) and path edges.
#include "pdvo/vo/map.h"

#include <gtest/gtest.h>

#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {
namespace {

TEST(Map, WritesPointsPlanesAndPathAsPly) {
  Map map;
  map.points = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-1, 0, 5)};
  MapPlane plane;
  plane.polygon = {Eigen::Vector3d(0, 0, 4), Eigen::Vector3d(1, 0, 4), Eigen::Vector3d(1, 1, 4)};
  plane.normal = Eigen::Vector3d(0, 0, -1);
  plane.filter = 2;
  plane.plane = 7;
  map.planes = {plane};
  Trajectory path;
  for (int k = 0; k < 3; ++k)
    path.push_back({k * 0.1, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(k, 0, 0))});
  const test::TempDir dir;
  WritePly(dir / "map.ply", map, path);
  std::istringstream in(ReadFile(dir / "map.ply"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const auto header_end = std::find(lines.begin(), lines.end(), "end_header");
  ASSERT_NE(header_end, lines.end());
  EXPECT_NE(std::find(lines.begin(), header_end, "element vertex 8"), header_end);  // 2 + 3 + 3
  EXPECT_NE(std::find(lines.begin(), header_end, "element face 1"), header_end);
  EXPECT_NE(std::find(lines.begin(), header_end, "element edge 2"), header_end);
  const std::vector<std::string> body(header_end + 1, lines.end());
  ASSERT_EQ(body.size(), 8u + 1 + 2);
  EXPECT_EQ(body[0], "1 2 3 200 200 200");
  EXPECT_EQ(body[2], "0 0 4 128 128 0");  // normal (0, 0, -1) as colour
  EXPECT_EQ(body[7], "2 0 0 255 0 0");    // the last camera position
  EXPECT_EQ(body[8], "3 2 3 4 2 7");      // the plane's face: its three corners, its filter and plane numbers
  EXPECT_EQ(body[9], "5 6");              // the path's first step
  EXPECT_EQ(body[10], "6 7");

  std::vector<Eigen::Vector3d> read_path;
  const Map read = ReadPly(dir / "map.ply", &read_path);
  ASSERT_EQ(read.points.size(), 2u);
  EXPECT_EQ(read.points[1], map.points[1]);
  ASSERT_EQ(read.planes.size(), 1u);
  ASSERT_EQ(read.planes[0].polygon.size(), 3u);
  EXPECT_EQ(read.planes[0].polygon[2], plane.polygon[2]);
  EXPECT_LT((read.planes[0].normal - plane.normal).norm(), 0.01);
  EXPECT_EQ(read.planes[0].filter, 2);
  EXPECT_EQ(read.planes[0].plane, 7);
  ASSERT_EQ(read_path.size(), 3u);
  EXPECT_EQ(read_path[2], Eigen::Vector3d(2, 0, 0));
  // A file written before faces had their numbers reads with -1.
  std::string old = ReadFile(dir / "map.ply");
  old.erase(old.find("property int filter\nproperty int plane\n"), 39);
  old.replace(old.find("3 2 3 4 2 7"), 11, "3 2 3 4");
  WriteFileAtomically(dir / "old.ply", old);
  const Map read_old = ReadPly(dir / "old.ply", &read_path);
  ASSERT_EQ(read_old.planes.size(), 1u);
  EXPECT_EQ(read_old.planes[0].polygon[2], plane.polygon[2]);
  EXPECT_EQ(read_old.planes[0].plane, -1);
  EXPECT_EQ(read_path.size(), 3u);
}

TEST(Map, ReadsAPathOfOnePoseAndRefusesMalformedFiles) {
  const test::TempDir dir;
  Map map;
  map.points = {Eigen::Vector3d(1, 2, 3)};
  WritePly(dir / "one.ply", map, {{0.0, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(4, 5, 6))}});
  std::vector<Eigen::Vector3d> path;
  const Map read = ReadPly(dir / "one.ply", &path);
  ASSERT_EQ(read.points.size(), 1u);
  ASSERT_EQ(path.size(), 1u);
  EXPECT_EQ(path[0], Eigen::Vector3d(4, 5, 6));

  WriteFileAtomically(dir / "short.ply", ReadFile(dir / "one.ply").substr(0, ReadFile(dir / "one.ply").size() - 8));
  EXPECT_THROW(ReadPly(dir / "short.ply", &path), FormatError);
  WriteFileAtomically(dir / "text.ply", "hello\n");
  EXPECT_THROW(ReadPly(dir / "text.ply", &path), FormatError);
  EXPECT_THROW(ReadPly(dir / "missing.ply", &path), IoError);
}

// The record counts a plane once however often it is recorded, with its most points; a discarded filter's
// planes and what it kept are forgotten, an earlier filter's stay.
TEST(Map, RecordForgetsADiscardedFilter) {
  MapRecord record(4);
  PlaneTrack plane;
  for (int k = 0; k < 5; ++k) plane.members.push_back({Eigen::Vector2d(10 * k, k * k), Eigen::Vector3d::UnitZ(), {}});
  record.Record(7, plane);
  plane.moved_away = 3;
  record.Record(7, plane);
  record.KeepPlane(MapPlane{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()}, {0, 0, 1}});
  EXPECT_EQ(record.stats().planes, 1);
  EXPECT_EQ(record.stats().points_per_plane, 8);  // its members and those that moved away
  record.NewFilter();
  record.Record(7, plane);  // another filter's plane 7
  record.KeepPlane(MapPlane{});
  EXPECT_EQ(record.stats().planes, 2);
  EXPECT_EQ(record.kept().planes.size(), 2u);
  record.DiscardFilter();
  EXPECT_EQ(record.stats().planes, 1);
  EXPECT_EQ(record.kept().planes.size(), 1u);
  plane.members.resize(2);
  plane.moved_away = 1;
  record.Record(9, plane);  // 3 points: fewer than 4, not a plane
  EXPECT_EQ(record.stats().planes, 1);
}

TEST(Map, MeasurementCurveAveragesThePlanesThatReachedTheirPoints) {
  MeasurementCurve curve(3, 2);
  // Plane 1 of the keyframe at frame 0: two distinct pixels; used twice at age 0, once at age 2.
  curve.Add(0, 0, 1, {1, 1}, true);
  curve.Add(0, 0, 1, {5, 5}, true);
  curve.Add(1, 0, 1, {5, 5}, false);  // searched for, not used
  curve.Add(2, 0, 1, {5.2, 4.9}, true);
  // Plane 1 of the keyframe at frame 3 (ids start again per keyframe here): one pixel only, left out.
  curve.Add(3, 3, 1, {2, 2}, true);
  // Plane 2: two pixels; used once at age 1, and at age 5, beyond the curve.
  curve.Add(1, 0, 2, {1, 1}, true);
  curve.Add(1, 0, 2, {9, 9}, false);
  curve.Add(5, 0, 2, {1, 1}, true);
  // Plane 3: never used within the curve's frames, left out.
  curve.Add(7, 0, 3, {1, 1}, true);
  curve.Add(7, 0, 3, {2, 2}, true);
  const std::vector<double> mean = curve.Mean();
  ASSERT_EQ(mean.size(), 3u);
  EXPECT_DOUBLE_EQ(mean[0], 1.0);
  EXPECT_DOUBLE_EQ(mean[1], 0.5);
  EXPECT_DOUBLE_EQ(mean[2], 0.5);
}

}  // namespace
}  // namespace pdvo::vo
