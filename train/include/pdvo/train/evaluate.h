// Evaluating a recogniser on annotated images: regions are sampled from the annotations as in training (each
// polygon and pure sub-windows, seeded), recognised, and compared with their labels and normals.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pdvo/annotations/regions.h"
#include "pdvo/eval/recognition.h"
#include "pdvo/infer/recogniser.h"

namespace pdvo {

struct ImageEvaluation {
  std::string annotation_path;
  int skipped = 0;  // regions with too few salient points
  std::vector<RecognitionSample> samples;
  std::vector<cv::Rect> boxes;     // per sample: its region's bounding box (working resolution)
  std::vector<bool> whole_shapes;  // per sample: the annotated polygon itself, not a sub-window
};

// One row per annotation file. Throws pdvo::Error naming a file that cannot be read.
std::vector<ImageEvaluation> EvaluateRecogniser(const Recogniser& recogniser,
                                                const std::vector<std::string>& annotation_files,
                                                const RegionSamplingOptions& sampling, uint64_t seed);

// All samples of all rows.
std::vector<RecognitionSample> AllSamples(const std::vector<ImageEvaluation>& rows);

}  // namespace pdvo
