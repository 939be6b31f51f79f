// Where `pdvo vo --mode pdvo` takes its planes from (vo/detection_worker.h's PlaneDetector):
//   model   the plane detector (infer/detector.h) with a model file, run on each keyframe's colour image;
//   FOLDER  annotation files (../ANNOTATIONS.md: detections or hand-made), one per frame, matched to frames by
//           the stem of their imagePath (000012.json with "imagePath": "../rgb/000012.png" is frame 000012.png);
//           polygons are taken as pixels of the undistorted frame, scaled to the working width;
//   oracle  the sequence's own exact annotations (pdvo synth output: its annotations/ folder): the planes a
//           perfect detector would give.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/vo/detection_worker.h"

namespace pdvo::apps {

class PlaneSource {
 public:
  // `source`: "model", "oracle" or a folder; `model_path` for "model", `sequence_path` for "oracle"; `working`:
  // the odometry's camera. Reads the model or every annotation now: throws naming the file for a missing or
  // malformed one, a folder without annotations, or a sequence without annotations/.
  PlaneSource(const std::string& source, const std::string& model_path, const std::string& sequence_path,
              const Camera& working);
  ~PlaneSource();

  // The name of frame `index`'s image (its stem is matched to annotations); call before tracking the frame.
  void AddFrame(int index, const std::string& image_path);
  // The detector for the odometry; it refers to this object, which must outlive the odometry.
  vo::PlaneDetector detector();
  // From now on, for source "model": keep a picture of the detector's stages (infer/detection_drawing.h) of
  // each keyframe it detects, JPEG-encoded, by the keyframe's frame index; TakeStages hands them over.
  void KeepStages();
  std::map<int, std::vector<unsigned char>> TakeStages();
  std::string Describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdvo::apps
