#include "pdvo/common/trajectory.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"

namespace pdvo {
namespace {

// Splits `content` into numeric rows, skipping blank lines and '#' comments. Every row must have `columns`
// finite numbers; line numbers are kept for errors.
struct Row {
  int line;
  std::vector<double> values;
};

std::vector<Row> ReadNumericRows(const std::string& path, size_t columns) {
  std::vector<Row> rows;
  for (const auto& [number, line] : ReadDataLines(path)) {
    std::istringstream fields(line);
    Row row{number, {}};
    std::string token;
    while (fields >> token) {
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      PDVO_THROW_CHECK(end && *end == '\0', FormatError,
                       path << ":" << number << ": '" << token << "' is not a number");
      PDVO_THROW_CHECK(std::isfinite(v), FormatError, path << ":" << number << ": value is not finite");
      row.values.push_back(v);
    }
    PDVO_THROW_CHECK(row.values.size() == columns, FormatError,
                     path << ":" << number << ": expected " << columns << " numbers, found " << row.values.size());
    rows.push_back(std::move(row));
  }
  return rows;
}

void CheckIncreasing(const std::string& path, double previous, double current, int line) {
  PDVO_THROW_CHECK(
      current > previous, FormatError,
      path << ":" << line << ": timestamp " << current << " does not increase (previous " << previous << ")");
}
}  // namespace

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  PDVO_THROW(InvalidArgument, "unknown trajectory format '" << name << "' (use tum or kitti)");
}

std::vector<double> ReadTimes(const std::string& path) {
  std::vector<double> times;
  for (const Row& row : ReadNumericRows(path, 1)) {
    if (!times.empty()) CheckIncreasing(path, times.back(), row.values[0], row.line);
    times.push_back(row.values[0]);
  }
  PDVO_THROW_CHECK(!times.empty(), FormatError, path << ": contains no times");
  return times;
}

Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format, const std::string& times_path) {
  Trajectory trajectory;
  if (format == TrajectoryFormat::kTum) {
    for (const Row& row : ReadNumericRows(path, 8)) {
      const auto& v = row.values;
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      PDVO_THROW_CHECK(q.norm() > 1e-6, FormatError, path << ":" << row.line << ": zero quaternion");
      if (!trajectory.empty()) CheckIncreasing(path, trajectory.back().timestamp, v[0], row.line);
      trajectory.push_back({v[0], Rigid3d(q, Eigen::Vector3d(v[1], v[2], v[3]))});
    }
  } else {
    for (const Row& row : ReadNumericRows(path, 12)) {
      Eigen::Matrix<double, 3, 4> m;
      for (int i = 0; i < 12; ++i) m(i / 4, i % 4) = row.values[i];
      const Eigen::Matrix3d r = m.leftCols<3>();
      PDVO_THROW_CHECK(
          (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-3 && r.determinant() > 0,
          FormatError, path << ":" << row.line << ": the 3x3 part is not a rotation");
      trajectory.push_back({static_cast<double>(trajectory.size()), Rigid3d::FromMatrix3x4(m)});
    }
    if (!times_path.empty()) {
      const std::vector<double> times = ReadTimes(times_path);
      PDVO_THROW_CHECK(
          times.size() >= trajectory.size(), FormatError,
          times_path << ": has " << times.size() << " times but " << path << " has " << trajectory.size() << " poses");
      for (size_t i = 0; i < trajectory.size(); ++i) trajectory[i].timestamp = times[i];
    }
  }
  PDVO_THROW_CHECK(!trajectory.empty(), FormatError, path << ": contains no poses");
  return trajectory;
}

void WriteTrajectory(const std::string& path, const Trajectory& trajectory, TrajectoryFormat format) {
  std::string out;
  char line[512];
  if (format == TrajectoryFormat::kTum) out = "# timestamp tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : trajectory) {
    const Eigen::Vector3d& t = p.world_from_cam.translation;
    if (format == TrajectoryFormat::kTum) {
      const Eigen::Quaterniond& q = p.world_from_cam.rotation;
      std::snprintf(line, sizeof(line), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", p.timestamp, t.x(), t.y(), t.z(),
                    q.x(), q.y(), q.z(), q.w());
    } else {
      const Eigen::Matrix<double, 3, 4> m = p.world_from_cam.ToMatrix3x4();
      int n = 0;
      for (int i = 0; i < 12; ++i) {
        n += std::snprintf(line + n, sizeof(line) - n, i ? " %.9e" : "%.9e", m(i / 4, i % 4));
      }
      std::snprintf(line + n, sizeof(line) - n, "\n");
    }
    out += line;
  }
  WriteFileAtomically(path, out);
}

double PathLength(const Trajectory& trajectory) {
  double length = 0;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory[i].world_from_cam.translation - trajectory[i - 1].world_from_cam.translation).norm();
  }
  return length;
}

}  // namespace pdvo
