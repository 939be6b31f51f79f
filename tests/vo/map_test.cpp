// The map as PLY: header counts, vertex order (points, plane corners, camera path), faces and path edges.
#include "pdvo/vo/map.h"

#include <gtest/gtest.h>

#include <sstream>

#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo::vo {
namespace {

TEST(Map, WritesPointsPlanesAndPathAsPly) {
  Map map;
  map.points = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-1, 0, 5)};
  MapPlane plane;
  plane.polygon = {Eigen::Vector3d(0, 0, 4), Eigen::Vector3d(1, 0, 4), Eigen::Vector3d(1, 1, 4)};
  plane.normal = Eigen::Vector3d(0, 0, -1);
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
  EXPECT_EQ(body[8], "3 2 3 4");          // the plane's face: its three corners
  EXPECT_EQ(body[9], "5 6");              // the path's first step
  EXPECT_EQ(body[10], "6 7");
}

}  // namespace
}  // namespace pdvo::vo
