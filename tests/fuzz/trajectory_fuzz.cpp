// Trajectories (pdvo ate --gt/--est, a sequence's groundtruth.txt): TUM and KITTI, and a KITTI times file.
#include "fuzz.h"
#include "pdvo/common/trajectory.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pdvo::fuzz::WriteInput(data, size, ".txt");
  using pdvo::TrajectoryFormat;
  pdvo::fuzz::ExpectOnlyPdvoErrors("ReadTrajectory tum", [&] { pdvo::ReadTrajectory(path, TrajectoryFormat::kTum); });
  pdvo::fuzz::ExpectOnlyPdvoErrors("ReadTrajectory kitti",
                                   [&] { pdvo::ReadTrajectory(path, TrajectoryFormat::kKitti); });
  pdvo::fuzz::ExpectOnlyPdvoErrors("ReadTimes", [&] { pdvo::ReadTimes(path); });
  return 0;
}
