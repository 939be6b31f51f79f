// Scoring plane detections against reference annotations of the same image (pdvo evaluate-detection).
//
// Both are rasterised at the reference image's size (at most `max_width` wide; where shapes overlap, the later
// wins). A plane is all the plane shapes of one group_id (LabelMe's grouping: the pieces of one plane, on both
// sides of a tree, say), or one plane shape without it; its normal is its largest piece's. Only pixels the
// reference annotates (plane or non-plane) are scored:
// - pixel precision, recall and F1 of the plane label and of the non-plane label (a pixel the detection leaves
//   unlabelled counts against both recalls);
// - false plane area: the share of the detected plane area (on annotated pixels) that lies on reference
//   non-plane pixels;
// - plane recall: of the reference planes covering at least `min_plane_share` of the image, the share whose best
//   overlapping detected plane has IoU >= `match_iou` and a normal within 10, and within 30, degrees; the normal
//   errors of every reference plane so matched; detected planes that are no reference plane's match are spurious;
//   each counted reference plane that is not matched within 30 degrees is put down to one cause: its best match's
//   normal is over 30 degrees off (turned); the detected plane overlapping it most holds at least half of it but is
//   too large for IoU match_iou (merged: it runs onto other planes or non-planes); detected planes cover at least
//   half of it, but none half (fragmented); less than half of it is detected as plane (missed); a merged plane is
//   put down to where most of that detected plane's area outside it lies: on reference planes of its orientation
//   (within 30 degrees: a neighbouring facade), on reference planes at another angle (a wall round a corner, the
//   ground), on reference non-plane pixels, or on unannotated pixels;
// - segmentation over the reference's plane pixels, each reference plane a segment and each detected plane a
//   segment (pixels on no detected plane one more): Rand index, variation of information (bits), and the
//   covering of the reference by the detection (each reference segment's best IoU, weighted by its size).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo {

struct DetectionScoreOptions {
  int max_width = 640;            // px
  double min_plane_share = 0.01;  // of the image: smaller reference planes do not count for plane recall
  double match_iou = 0.5;
};

// Why counted reference planes are not matched within 30 degrees (see above); a merged one by where most of the
// detected plane's area outside it lies.
struct Unmatched {
  int turned = 0, fragmented = 0, missed = 0;
  int merged_parallel = 0, merged_angled = 0, merged_nonplane = 0, merged_unannotated = 0;
  int merged() const { return merged_parallel + merged_angled + merged_nonplane + merged_unannotated; }
  Unmatched& operator+=(const Unmatched& o);
};

struct DetectionScore {
  std::string name;
  // Pixel counts on annotated pixels: reference label x detected label (plane, non-plane, none).
  long plane_as_plane = 0, plane_as_nonplane = 0, plane_as_none = 0;
  long nonplane_as_plane = 0, nonplane_as_nonplane = 0, nonplane_as_none = 0;
  int reference_planes = 0;               // counted for plane recall
  int matched_10 = 0, matched_30 = 0;     // of them, matched with a normal within 10 / 30 degrees
  std::vector<double> normal_errors_deg;  // of the reference planes matched by IoU (any angle, any size)
  int spurious_planes = 0;                // detected planes that are no reference plane's match
  Unmatched unmatched;
  double rand_index = 1, variation_of_information = 0, covering = 1;  // 1, 0, 1 without reference planes
  long segmentation_pixels = 0;  // the reference plane pixels the segmentation figures are over
};

// Throws FormatError if the two annotations are of different image sizes.
DetectionScore ScoreDetection(const Annotation& reference, const Annotation& detection,
                              const DetectionScoreOptions& options = {});

struct DetectionSummary {
  int images = 0;
  double plane_precision = 0, plane_recall = 0, plane_f1 = 0;  // over all annotated pixels
  double nonplane_precision = 0, nonplane_recall = 0, nonplane_f1 = 0;
  double false_plane_area = 0;
  int reference_planes = 0;
  double plane_recall_10 = 0, plane_recall_30 = 0;
  double mean_normal_error_deg = 0, median_normal_error_deg = 0;  // over matched planes
  int spurious_planes = 0;
  Unmatched unmatched;
  double rand_index = 0, variation_of_information = 0, covering = 0;  // means over images with plane pixels
};
DetectionSummary Summarise(const std::vector<DetectionScore>& scores);

// {"how": ..., "summary": {...}, "images": [{...}, ...]}
nlohmann::json ToJson(const std::vector<DetectionScore>& scores, const DetectionScoreOptions& options);

}  // namespace pdvo
