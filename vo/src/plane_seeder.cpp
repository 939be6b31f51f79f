#include "pdvo/vo/plane_seeder.h"

#include <algorithm>

#include "pdvo/vo/idpp.h"

namespace pdvo::vo {

std::vector<PlaneSeed> DensestCornersSeeder::Seed(const Keyframe& keyframe, const Camera& camera) {
  const std::vector<Corner>& corners = keyframe.corners;
  std::vector<std::pair<int, int>> density;  // (minus the corners within grow_radius, index)
  for (size_t i = 0; i < corners.size(); ++i) {
    int n = 0;
    for (const Corner& c : corners) n += (c.pixel - corners[i].pixel).norm() < o_.grow_radius;
    density.emplace_back(-n, static_cast<int>(i));
  }
  std::sort(density.begin(), density.end());
  std::vector<PlaneSeed> seeds;
  for (const auto& [minus_n, i] : density) {
    if (static_cast<int>(seeds.size()) >= o_.max_new_planes || -minus_n <= o_.min_plane_points) break;
    if (corners[i].used) continue;
    const bool apart = std::all_of(seeds.begin(), seeds.end(), [&, i = i](const PlaneSeed& s) {
      return (corners[s.corner].pixel - corners[i].pixel).norm() > 2 * o_.grow_radius;
    });
    if (!apart) continue;
    seeds.push_back({i, FrontoParallel(camera.Ray(corners[i].pixel), 1).normal, o_.plane_sigma_normal});
  }
  return seeds;
}

std::unique_ptr<PlaneSeeder> MakePlaneSeeder(PlaneMode mode, const PlaneOptions& options) {
  if (mode == PlaneMode::kIdpp) return std::make_unique<DensestCornersSeeder>(options);
  return nullptr;
}

}  // namespace pdvo::vo
