#include "pdvo/train/evaluate.h"

#include <random>

#include "pdvo/common/logging.h"

namespace pdvo {

std::vector<ImageEvaluation> EvaluateRecogniser(const Recogniser& recogniser, const std::vector<std::string>& files,
                                                const RegionSamplingOptions& sampling, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<ImageEvaluation> rows;
  Progress progress("evaluating", files.size());
  for (const std::string& file : files) {
    const AnnotatedImage a = ReadAnnotatedImage(file, recogniser.model().options.working_width);
    const ImageWords words = recogniser.Describe(a.image, a.camera);
    ImageEvaluation row;
    row.annotation_path = file;
    for (const LabelledRegion& r : SampleRegions(a.annotation, a.image.size(), sampling, rng)) {
      const RegionPrediction p = recogniser.Recognise(words, r.region);
      if (!p.valid) {
        ++row.skipped;
        continue;
      }
      row.samples.push_back({r.planar, p.plane_probability, r.normal, p.normal});
      row.boxes.push_back(r.region.box);
      row.whole_shapes.push_back(r.whole_shape);
    }
    rows.push_back(std::move(row));
    progress.Step();
  }
  return rows;
}

std::vector<RecognitionSample> AllSamples(const std::vector<ImageEvaluation>& rows) {
  std::vector<RecognitionSample> all;
  for (const ImageEvaluation& r : rows) all.insert(all.end(), r.samples.begin(), r.samples.end());
  return all;
}

}  // namespace pdvo
