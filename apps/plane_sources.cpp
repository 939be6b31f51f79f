#include "plane_sources.h"

#include <filesystem>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/errors.h"
#include "pdvo/infer/detection_drawing.h"
#include "pdvo/infer/detector.h"
#include "tool.h"

namespace pdvo::apps {

namespace fs = std::filesystem;

struct PlaneSource::Impl {
  Camera working;
  std::string description;
  std::unique_ptr<Detector> detector;                       // model
  std::map<std::string, std::vector<DetectedPlane>> files;  // folder, oracle: by image stem
  std::mutex mutex;                                         // guards names and stages
  std::vector<std::string> names;                           // by frame: image stems
  bool keep_stages = false;
  std::map<int, std::vector<unsigned char>> stages;  // by keyframe frame: JPEG

  void ReadFolder(const std::string& folder) {
    for (const std::string& path : ListAnnotationFiles({folder})) {
      const Annotation a = ReadAnnotation(path);
      const std::string stem = fs::path(a.image_path.empty() ? path : a.image_path).stem().string();
      files[stem] = DetectedPlanes(a, working.width);
    }
  }
};

PlaneSource::PlaneSource(const std::string& source, const std::string& model_path, const std::string& sequence_path,
                         const Camera& working)
    : impl_(std::make_unique<Impl>()) {
  impl_->working = working;
  if (source == "model") {
    impl_->detector = std::make_unique<Detector>(PlaneModel::Read(model_path), DetectorOptions());
    impl_->description = "the detector with " + model_path;
  } else if (source == "oracle") {
    const fs::path folder = fs::path(sequence_path) / "annotations";
    PDVO_THROW_CHECK(fs::is_directory(folder), IoError,
                     sequence_path << ": --detections oracle needs the sequence's annotations/ (pdvo synth output)");
    impl_->ReadFolder(folder.string());
    impl_->description = "the oracle (" + folder.string() + ")";
  } else {
    impl_->ReadFolder(source);
    impl_->description = "the annotations in " + source;
  }
}

PlaneSource::~PlaneSource() = default;

void PlaneSource::AddFrame(int index, const std::string& image_path) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (static_cast<int>(impl_->names.size()) <= index) impl_->names.resize(index + 1);
  impl_->names[index] = fs::path(image_path).stem().string();
}

vo::PlaneDetector PlaneSource::detector() {
  Impl* impl = impl_.get();
  if (impl->detector) {
    return [impl](const vo::KeyframeImage& k) {
      const cv::Mat& image = k.colour.empty() ? k.grey : k.colour;
      const Detections d = impl->detector->Detect(image, impl->working);
      bool keep = false;
      {
        std::lock_guard<std::mutex> lock(impl->mutex);
        keep = impl->keep_stages;
      }
      if (keep) {  // drawn without the lock: the tracking thread takes it for every frame
        std::vector<unsigned char> jpeg;
        const cv::Mat stages = DrawDetectionStages(image, d, d.ToAnnotation("", image.cols, image.rows, impl->working));
        cv::imencode(".jpg", stages, jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
        std::lock_guard<std::mutex> lock(impl->mutex);
        impl->stages[k.frame] = std::move(jpeg);
      }
      return d.Planes(image.cols, image.rows);
    };
  }
  return [impl](const vo::KeyframeImage& k) {
    std::string name;
    {
      std::lock_guard<std::mutex> lock(impl->mutex);
      if (k.frame < static_cast<int>(impl->names.size())) name = impl->names[k.frame];
    }
    const auto found = impl->files.find(name);
    return found == impl->files.end() ? std::vector<DetectedPlane>() : found->second;
  };
}

void PlaneSource::KeepStages() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->keep_stages = impl_->detector != nullptr;
}

std::map<int, std::vector<unsigned char>> PlaneSource::TakeStages() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return std::move(impl_->stages);
}

std::string PlaneSource::Describe() const { return impl_->description; }

}  // namespace pdvo::apps
