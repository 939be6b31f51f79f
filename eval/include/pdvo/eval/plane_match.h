// Comparing estimated planes (detections, or annotations made from depth) with reference annotations.
//
// Planes are matched one to one, greedily by intersection over union of their masks (highest first), above
// `min_iou`. For each match: IoU and the angle between the normals. Masks are compared at the reference
// image's size (or scaled to `max_width`). A plane is its pieces (PlanesOf: the plane shapes of one
// group_id), named by and taking the normal of its largest piece.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo {

struct PlaneMatch {
  int reference_shape = -1, estimated_shape = -1;  // each plane's largest piece
  double iou = 0;
  double normal_angle_deg = -1;  // -1 if either has no normal
};

struct PlaneComparison {
  std::string name;  // the frame, for reports
  int reference_planes = 0, estimated_planes = 0;
  std::vector<PlaneMatch> matches;
};

struct PlaneMatchOptions {
  double min_iou = 0.1;  // pairs below this are not matched
  int max_width = 640;   // masks are compared at most this wide
};

// Throws FormatError if the two annotations are of different image sizes.
PlaneComparison ComparePlanes(const Annotation& reference, const Annotation& estimate,
                              const PlaneMatchOptions& options = {});

struct PlaneComparisonSummary {
  int frames = 0, reference_planes = 0, matched = 0;
  double median_iou = 0, mean_iou = 0;  // over reference planes, 0 for unmatched ones
  double median_matched_iou = 0;        // over matched planes only
  double median_normal_angle_deg = 0, mean_normal_angle_deg = 0, p90_normal_angle_deg = 0;  // over matches
};

PlaneComparisonSummary Summarise(const std::vector<PlaneComparison>& comparisons);

// {"summary": {...}, "frames": [{"name", "reference_planes", "estimated_planes", "matches": [...]}]}
nlohmann::json ToJson(const std::vector<PlaneComparison>& comparisons);

// The purity of planes built from points (the odometry's): each point of a plane, seen in a frame, carries a
// label, e.g. the true surface it lies on. Over the (frame, plane) groups of at least `min_points`, the share of
// points that carry their group's most common label.
class PlanePurity {
 public:
  void Add(int frame, int plane, int label) { ++counts_[{frame, plane}][label]; }
  // 0 if no group is large enough; `points` (optional): how many points the share is over.
  double Share(int min_points, long* points = nullptr) const;
  // The most common label of group (frame, plane) (the smallest of equals), if it has `min_points` or more.
  std::optional<int> MainLabel(int frame, int plane, int min_points) const;

 private:
  std::map<std::pair<int, int>, std::map<int, int>> counts_;  // (frame, plane) -> label -> points
};

}  // namespace pdvo
