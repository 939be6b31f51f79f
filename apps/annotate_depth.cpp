// pdvo annotate-depth: planes found in RGB-D depth maps, written as one annotation per frame.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pdvo/annotations/depth_planes.h"
#include "pdvo/common/dataset.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"
#include "pdvo/eval/plane_match.h"
#include "tool.h"

namespace pdvo::apps {
namespace fs = std::filesystem;

int RunAnnotateDepth(int argc, char** argv) {
  CLI::App app(
      "Finds the planes in each depth map of an RGB-D sequence (a TUM RGB-D folder or a synthetic street) "
      "and writes one annotation per frame: large planar regions as `plane` shapes with their normals, "
      "large clearly non-planar regions as `non-plane`. With --reference, compares them with reference "
      "annotations (IoU and normal angle of matched planes).",
      "pdvo annotate-depth");
  std::string sequence_path, out_dir, camera_path, config_path, reference_dir, json_path, verbosity = "info";
  std::vector<std::string> overrides;
  int every = 1;
  app.add_option("--sequence,-s", sequence_path, "RGB-D sequence folder (rgb.txt, depth.txt)")->required();
  app.add_option("--out,-o", out_dir, "Folder for the annotations (<image name>.json)")->required();
  app.add_option("--camera,-c", camera_path, "Camera YAML (default: camera.yaml in the sequence folder)");
  AddConfigFlags(app, &config_path, &overrides, "Options YAML (section annotate_depth:)", "inlier_sigmas=2.5");
  app.add_option("--every", every, "Annotate every N-th frame")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--reference", reference_dir, "Folder of reference annotations to compare with");
  app.add_option("--json", json_path, "Write the comparison report (needs --reference) as JSON");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  PDVO_THROW_CHECK(json_path.empty() || !reference_dir.empty(), InvalidArgument, "--json needs --reference");
  if (!reference_dir.empty()) CheckExists(reference_dir, "reference folder");

  const auto options = LoadToolOptions<DepthPlaneOptions>(config_path, "annotate_depth", overrides);

  SequenceOptions reading;  // depth maps, not ground truth
  reading.load_groundtruth = false;
  std::unique_ptr<Sequence> sequence = OpenSequence(sequence_path, reading);
  const Camera camera = SequenceCamera(*sequence, sequence_path, camera_path);
  const DepthPlaneFinder finder(camera, options);
  PDVO_LOG(Info) << "annotating " << sequence->Describe() << " at " << finder.working_size().width << "x"
                 << finder.working_size().height;

  StagedOutputDir out(out_dir);
  SaveOptions(out.path("annotate_depth.yaml"), options, "annotate_depth");
  std::vector<PlaneComparison> comparisons;
  size_t written = 0, without_depth = 0, shapes = 0;
  Progress progress("annotate-depth", (sequence->size() + every - 1) / every);
  Frame frame;
  for (size_t i = 0; sequence->Next(&frame); ++i) {
    if (i % every != 0) continue;
    progress.Step();
    if (frame.depth.empty()) {
      ++without_depth;
      continue;
    }
    const std::string name = fs::path(frame.image_path).stem().string() + ".json";
    const std::string image_rel = fs::relative(fs::absolute(frame.image_path), fs::absolute(out_dir)).generic_string();
    const Annotation annotation = finder.Annotate(frame.depth, image_rel);
    WriteAnnotation(out.path(name), annotation);
    ++written;
    shapes += annotation.shapes.size();
    const fs::path reference_file = fs::path(reference_dir) / name;
    if (!reference_dir.empty() && fs::exists(reference_file)) {
      const Annotation reference = ReadAnnotation(reference_file.string());
      CheckSameImageSize(reference, reference_file.string(), annotation, out.final_path(name));
      PlaneComparison c = ComparePlanes(reference, annotation);
      c.name = name;
      comparisons.push_back(std::move(c));
    }
  }
  progress.Finish();
  PDVO_THROW_CHECK(written > 0, FormatError, sequence_path << ": no frame has a depth map");
  if (without_depth > 0) PDVO_LOG(Warning) << without_depth << " frames had no depth map and were skipped";

  if (!reference_dir.empty()) {
    PDVO_THROW_CHECK(!comparisons.empty(), FormatError,
                     reference_dir << ": holds no annotation named like the frames (<image name>.json)");
    for (const PlaneComparison& c : comparisons) {
      std::string line = c.name + ": " + std::to_string(c.reference_planes) + " reference planes, " +
                         std::to_string(c.estimated_planes) + " found";
      for (const PlaneMatch& m : c.matches) {
        char buf[96];
        std::snprintf(buf, sizeof(buf), "; IoU %.3f, normal %.2f deg", m.iou, m.normal_angle_deg);
        line += buf;
      }
      PDVO_LOG(Info) << line;
    }
    const PlaneComparisonSummary s = Summarise(comparisons);
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "compared %d frames: %d of %d reference planes matched; median IoU %.3f (matched planes: %.3f); "
                  "normal angle median %.2f, mean %.2f, 90%% %.2f deg",
                  s.frames, s.matched, s.reference_planes, s.median_iou, s.median_matched_iou,
                  s.median_normal_angle_deg, s.mean_normal_angle_deg, s.p90_normal_angle_deg);
    PDVO_LOG(Info) << buf;
    if (!json_path.empty()) WriteFileAtomically(json_path, ToJson(comparisons).dump(1) + "\n");
  }
  out.Commit();
  PDVO_LOG(Info) << "wrote " << written << " annotations (" << shapes << " shapes) to " << out_dir;
  return 0;
}

}  // namespace pdvo::apps
