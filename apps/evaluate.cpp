// pdvo evaluate --model MODEL --annotations DIR...: region recognition accuracy and normal error.
#include <filesystem>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/train/evaluate.h"
#include "tool.h"

namespace pdvo::apps {

int RunEvaluate(int argc, char** argv) {
  CLI::App app(
      "Measures a model on annotated images: regions are sampled from the annotations as in training "
      "(each polygon and sub-windows pure in its label, squares unless max_window_aspect > 1, seeded), "
      "recognised, and compared with their labels and normals. Reports accuracy, balanced accuracy, "
      "precision / recall of 'plane', ROC AUC, the confusion matrix and normal errors, overall and per "
      "image.",
      "pdvo evaluate");
  std::vector<std::string> inputs, overrides;
  std::string model_path, json_path, config_path, verbosity = "info";
  uint64_t seed = 1;
  bool per_image = false, no_fusion = false;
  app.add_option("--model,-m", model_path, "Model file (from pdvo train)")->required();
  app.add_option("--annotations,-a", inputs, "Folders (or files) of annotations")->required();
  app.add_option("--json", json_path,
                 "Write the report as JSON: overall, per image, and per region (box at the working resolution, "
                 "truth, plane probability, predicted and true normal in the camera frame)");
  AddConfigFlags(app, &config_path, &overrides, "Region sampling options (YAML, section 'regions')",
                 "windows_per_shape=4");
  app.add_option("--seed", seed, "Seed for the sub-windows")->capture_default_str()->check(NotNegative());
  app.add_flag("--per-image", per_image, "Print a row per image");
  app.add_flag("--no-fusion", no_fusion,
               "Normals from the regressors alone, not fused with the edges' vanishing direction (as if the model's "
               "recogniser.vanishing.fuse_normals were false)");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  const RegionSamplingOptions sampling = LoadToolOptions<RegionSamplingOptions>(config_path, "regions", overrides);
  PlaneModel model = PlaneModel::Read(model_path);
  if (no_fusion) model.options.vanishing.fuse_normals = false;
  const Recogniser recogniser(std::move(model));
  const std::vector<std::string> files = ListAnnotationFiles(inputs);
  const std::vector<ImageEvaluation> rows = EvaluateRecogniser(recogniser, files, sampling, seed);
  const RecognitionMetrics m = ComputeRecognitionMetrics(AllSamples(rows));
  int skipped = 0;
  nlohmann::json per_image_json = nlohmann::json::array();
  for (const ImageEvaluation& r : rows) {
    skipped += r.skipped;
    const RecognitionMetrics mi = ComputeRecognitionMetrics(r.samples);
    nlohmann::json regions = nlohmann::json::array();
    for (size_t k = 0; k < r.samples.size(); ++k) {
      const RecognitionSample& s = r.samples[k];
      const cv::Rect& b = r.boxes[k];
      nlohmann::json region = {{"box", {b.x, b.y, b.width, b.height}},
                               {"whole_shape", static_cast<bool>(r.whole_shapes[k])},
                               {"planar", s.planar},
                               {"probability", s.probability},
                               {"normal", {s.normal.x(), s.normal.y(), s.normal.z()}}};
      if (s.true_normal) region["true_normal"] = {s.true_normal->x(), s.true_normal->y(), s.true_normal->z()};
      regions.push_back(region);
    }
    per_image_json.push_back(
        {{"annotation", r.annotation_path}, {"skipped", r.skipped}, {"metrics", ToJson(mi)}, {"regions", regions}});
    if (per_image) {
      std::printf("%-40s regions %4d (skipped %3d) accuracy %.3f normal mean %5.1f deg\n",
                  std::filesystem::path(r.annotation_path).filename().c_str(), mi.regions, r.skipped, mi.accuracy,
                  mi.normal_mean);
    }
  }
  std::printf("%zu images, %d regions (%d skipped: too few salient points)\n", rows.size(), m.regions, skipped);
  std::printf("accuracy %.3f, balanced accuracy %.3f, precision %.3f, recall %.3f, ROC AUC %.3f\n", m.accuracy,
              m.balanced_accuracy, m.precision, m.recall, m.roc_auc);
  std::printf("confusion (rows truth, columns predicted; plane, non-plane): [%d %d] [%d %d]\n", m.confusion[0][0],
              m.confusion[0][1], m.confusion[1][0], m.confusion[1][1]);
  std::printf("normal error over %d planes: mean %.2f, median %.2f, 90%% %.2f deg\n", m.normals, m.normal_mean,
              m.normal_median, m.normal_p90);
  if (!json_path.empty()) {
    nlohmann::json report = {{"model", model_path},
                             {"images", rows.size()},
                             {"skipped", skipped},
                             {"overall", ToJson(m)},
                             {"per_image", per_image_json}};
    WriteFileAtomically(json_path, report.dump(1) + "\n");
  }
  return 0;
}

}  // namespace pdvo::apps
