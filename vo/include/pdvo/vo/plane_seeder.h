// Where new planes come from. When the odometry makes a keyframe, its plane seeder picks the keyframe corners at
// which planar features start, each with a prior normal; the odometry then gives each an inverse-depth prior and
// grows it (plane_growing.h). `DensestCornersSeeder` is the IDPP system's blind seeding: where the keyframe's
// corners are densest, facing the camera. A detector's planes (the paper's PDVO) are another seeder. Pixels are
// the keyframe's (working image); normals are in the keyframe's camera frame.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/vo/plane_growing.h"
#include "pdvo/vo/tracks.h"

namespace pdvo::vo {

// points: inverse-depth points only; idpp: and planes seeded where corners are densest (DensestCornersSeeder);
// pdvo: and planes where a detector found them in keyframes (plane_priors.h), no others.
enum class PlaneMode { kPoints, kIdpp, kPdvo };
constexpr std::array<std::pair<PlaneMode, const char*>, 3> OptionNames(PlaneMode) {
  return {{{PlaneMode::kPoints, "points"}, {PlaneMode::kIdpp, "idpp"}, {PlaneMode::kPdvo, "pdvo"}}};
}

struct PlaneSeed {
  int corner = -1;            // index into the keyframe's corners
  Eigen::Vector3d normal;     // prior unit normal, keyframe camera frame, towards the camera
  double sigma_normal = 0.5;  // its prior standard deviation, per component
};

class PlaneSeeder {
 public:
  virtual ~PlaneSeeder() = default;
  // The planes to seed in a new keyframe, before its points are chosen, at distinct unused corners.
  virtual std::vector<PlaneSeed> Seed(const Keyframe& keyframe, const Camera& camera) = 0;
};

// Up to max_new_planes seeds at the corners with most other corners within grow_radius (more than
// min_plane_points of them), at least twice grow_radius apart, densest first; fronto-parallel normals (along the
// corner's ray, towards the camera) with plane_sigma_normal.
class DensestCornersSeeder : public PlaneSeeder {
 public:
  explicit DensestCornersSeeder(const PlaneOptions& options) : o_(options) {}
  std::vector<PlaneSeed> Seed(const Keyframe& keyframe, const Camera& camera) override;

 private:
  PlaneOptions o_;
};

// The seeder of a mode: DensestCornersSeeder for idpp, none for points and pdvo.
std::unique_ptr<PlaneSeeder> MakePlaneSeeder(PlaneMode mode, const PlaneOptions& options);

}  // namespace pdvo::vo
