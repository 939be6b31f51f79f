// pdvo evaluate-detection --reference DIR --estimate DIR: detections scored against reference annotations.
#include <cstdio>
#include <filesystem>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/eval/detection.h"
#include "tool.h"

namespace pdvo::apps {
namespace fs = std::filesystem;

int RunEvaluateDetection(int argc, char** argv) {
  CLI::App app(
      "Scores detections (pdvo detect output) against reference annotations of the same name, on the "
      "pixels the reference annotates: plane and non-plane pixel precision, recall and F1; false plane "
      "area (detected plane area on reference non-planes); plane recall (reference planes of at least "
      "1% of the image whose best detected plane has IoU >= 0.5, with a normal within 10 and 30 degrees) "
      "and the matched planes' normal errors; Rand index, variation of information and covering over "
      "the reference's plane pixels. A reference without a detection counts as detecting nothing. Several "
      "--reference / --estimate pairs are pooled (their pixels and planes summed).",
      "pdvo evaluate-detection");
  std::vector<std::string> reference_dirs, estimate_dirs;
  std::string json_path, verbosity = "info";
  DetectionScoreOptions options;
  app.add_option("--reference,-r", reference_dirs, "Folder of reference annotations (repeatable)")->required();
  app.add_option("--estimate,-e", estimate_dirs, "Folder of detections (annotations), one per --reference")->required();
  app.add_option("--match-iou", options.match_iou, "IoU a detected plane needs to match")->capture_default_str();
  app.add_option("--min-plane-share", options.min_plane_share,
                 "Smallest reference plane counted for plane recall, a share of the image")
      ->capture_default_str();
  app.add_option("--json", json_path, "Write the per-image report as JSON");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  if (reference_dirs.size() != estimate_dirs.size()) {
    std::cerr << "pdvo evaluate-detection: error: " << reference_dirs.size() << " --reference folders for "
              << estimate_dirs.size() << " --estimate folders (see --help)\n";
    return 1;
  }
  std::vector<DetectionScore> scores;
  size_t missing = 0;
  for (size_t pair = 0; pair < reference_dirs.size(); ++pair) {
    const std::string& estimate_dir = estimate_dirs[pair];
    CheckExists(estimate_dir, "estimate folder");
    for (const std::string& ref_path : ListAnnotationFiles({reference_dirs[pair]})) {
      const Annotation reference = ReadAnnotation(ref_path);
      const fs::path est_path = fs::path(estimate_dir) / fs::path(ref_path).filename();
      Annotation estimate;
      if (fs::exists(est_path)) {
        estimate = ReadAnnotation(est_path.string());
      } else {
        ++missing;
        estimate.image_width = reference.image_width;
        estimate.image_height = reference.image_height;
      }
      CheckSameImageSize(reference, ref_path, estimate, est_path.string());
      DetectionScore s = ScoreDetection(reference, estimate, options);
      s.name = ref_path;
      scores.push_back(std::move(s));
    }
  }
  const DetectionSummary m = Summarise(scores);
  std::printf("%d images (%zu without a detection)\n", m.images, missing);
  std::printf("  plane pixels      precision %.3f, recall %.3f, F1 %.3f; false plane area %.3f\n", m.plane_precision,
              m.plane_recall, m.plane_f1, m.false_plane_area);
  std::printf("  non-plane pixels  precision %.3f, recall %.3f, F1 %.3f\n", m.nonplane_precision, m.nonplane_recall,
              m.nonplane_f1);
  std::printf("  plane recall      %.3f within 30 deg, %.3f within 10 deg (of %d reference planes); %d spurious\n",
              m.plane_recall_30, m.plane_recall_10, m.reference_planes, m.spurious_planes);
  std::printf("  not matched       %d merged, %d fragmented, %d missed, %d turned over 30 deg\n", m.unmatched.merged(),
              m.unmatched.fragmented, m.unmatched.missed, m.unmatched.turned);
  std::printf(
      "  merged, onto     planes of its orientation %d, planes at another angle %d, non-plane %d, "
      "unannotated pixels %d\n",
      m.unmatched.merged_parallel, m.unmatched.merged_angled, m.unmatched.merged_nonplane,
      m.unmatched.merged_unannotated);
  std::printf("  normal error      mean %.1f, median %.1f deg (matched planes)\n", m.mean_normal_error_deg,
              m.median_normal_error_deg);
  std::printf("  segmentation      Rand index %.3f, variation of information %.3f bits, covering %.3f\n", m.rand_index,
              m.variation_of_information, m.covering);
  if (!json_path.empty()) WriteFileAtomically(json_path, ToJson(scores, options).dump(1) + "\n");
  return 0;
}

}  // namespace pdvo::apps
