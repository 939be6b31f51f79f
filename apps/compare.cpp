// pdvo compare --reference DIR --estimate DIR: planes matched by IoU, with the angle between their normals.
#include <filesystem>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/eval/plane_match.h"
#include "tool.h"

namespace pdvo::apps {
namespace fs = std::filesystem;

int RunCompare(int argc, char** argv) {
  CLI::App app(
      "Matches the planes of estimated annotations (detections, or annotate-depth output) with those of "
      "reference annotations of the same name, one to one by IoU, and reports IoU and normal angle per "
      "frame and overall. A reference file without an estimate counts its planes as unmatched.",
      "pdvo compare");
  std::string reference_dir, estimate_dir, json_path, verbosity = "info";
  PlaneMatchOptions options;
  app.add_option("--reference,-r", reference_dir, "Folder of reference annotations")->required();
  app.add_option("--estimate,-e", estimate_dir, "Folder of estimated annotations")->required();
  app.add_option("--min-iou", options.min_iou, "Pairs below this IoU are not matched")
      ->capture_default_str()
      ->check(NumberIn(0, 1));
  app.add_option("--json", json_path, "Write the per-frame report as JSON");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  CheckExists(estimate_dir, "estimate folder");

  std::vector<PlaneComparison> comparisons;
  size_t missing = 0;
  for (const std::string& ref_path : ListAnnotationFiles({reference_dir})) {
    const Annotation reference = ReadAnnotation(ref_path);
    const fs::path est_path = fs::path(estimate_dir) / fs::path(ref_path).filename();
    PlaneComparison c;
    if (fs::exists(est_path)) {
      const Annotation estimate = ReadAnnotation(est_path.string());
      CheckSameImageSize(reference, ref_path, estimate, est_path.string());
      c = ComparePlanes(reference, estimate, options);
    } else {
      ++missing;
      for (const AnnotationShape& s : reference.shapes) c.reference_planes += s.IsPlane();
    }
    c.name = fs::path(ref_path).filename().string();
    comparisons.push_back(std::move(c));
  }
  const PlaneComparisonSummary s = Summarise(comparisons);
  char buf[320];
  std::snprintf(buf, sizeof(buf),
                "%d frames (%zu without an estimate): %d of %d reference planes matched; IoU median %.3f, mean "
                "%.3f (matched planes: median %.3f); normal angle median %.2f, mean %.2f, 90%% %.2f deg",
                s.frames, missing, s.matched, s.reference_planes, s.median_iou, s.mean_iou, s.median_matched_iou,
                s.median_normal_angle_deg, s.mean_normal_angle_deg, s.p90_normal_angle_deg);
  std::printf("%s\n", buf);
  if (!json_path.empty()) WriteFileAtomically(json_path, ToJson(comparisons).dump(1) + "\n");
  return 0;
}

}  // namespace pdvo::apps
