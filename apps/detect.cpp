// pdvo detect: planes in single images (the windowed detector of infer/detector.h), written as annotations.
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/infer/detection_drawing.h"
#include "pdvo/infer/detector.h"
#include "tool.h"

namespace pdvo::apps {

int RunDetect(int argc, char** argv) {
  CLI::App app(
      "Finds the planes in single images with the windowed detector: windows recognised at several sizes, "
      "per-point planarity and normal, MRF segmentation, each segment recognised again. Writes one "
      "annotation (LabelMe JSON with normals and scores, ../shared/ANNOTATIONS.md) per image, named after "
      "the image. All options: infer/config/detector.yaml.",
      "pdvo detect");
  std::string model_path = "models/default/model.yml", input, out_dir, camera_path, config_path, verbosity = "info";
  std::vector<std::string> overrides;
  size_t max_frames = 0;
  bool overlay = false;
  app.add_option("--model,-m", model_path, "Plane model file")->capture_default_str();
  std::string annotations_dir;
  app.add_option("input", input, "An image, an image folder, or a sequence (video, TUM, KITTI, pdvo synth)");
  app.add_option("--annotations,-a", annotations_dir,
                 "Instead of an input: the images that these annotations are of, each with its annotation's "
                 "camera; detections are named as the annotations (for pdvo evaluate-detection)");
  app.add_option("--out,-o", out_dir, "Output folder")->required();
  app.add_option("--camera,-c", camera_path, "Camera YAML of the images (default: the sequence's own, if any)");
  app.add_option("--max-frames", max_frames, "Stop after this many images (0: all)")->check(NotNegative());
  app.add_flag("--overlay", overlay,
               "Also write <name>_stages.png per image: the windows' plane probability, each point's planarity and "
               "normal, the MRFs' labels (non-planar points white) and the final planes, side by side (the paper's "
               "Fig. 3)");
  AddConfigFlags(app, &config_path, &overrides, "Detector options (YAML, section 'detector')", "plane_smoothness=2");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  if (input.empty() == annotations_dir.empty()) {
    std::cerr << "pdvo detect: error: give an input or --annotations, one of them (see --help)\n";
    return 1;
  }
  const DetectorOptions options = LoadToolOptions<DetectorOptions>(config_path, "detector", overrides);
  const Detector detector(PlaneModel::Read(model_path), options);
  // The images: one file, or the frames of a sequence.
  std::vector<std::pair<std::string, cv::Mat>> single;
  std::unique_ptr<Sequence> sequence;
  std::optional<Camera> camera;
  if (!camera_path.empty()) camera = Camera::Read(camera_path);
  size_t total = 1;
  std::vector<std::string> annotated;
  if (!annotations_dir.empty()) {
    annotated = ListAnnotationFiles({annotations_dir});
    total = annotated.size();
  } else if (std::filesystem::is_regular_file(input) && HasImageExtension(input)) {
    single.emplace_back(input, ReadImage(input, cv::IMREAD_COLOR));
  } else {
    SequenceOptions reading;  // the images only
    reading.load_depth = reading.load_groundtruth = false;
    sequence = OpenSequence(input, reading);
    if (!camera) camera = sequence->camera();
    total = sequence->size();
    PDVO_THROW_CHECK(total > 0, FormatError, input << ": no images");
  }
  if (max_frames > 0) total = std::min(total, max_frames);
  PDVO_THROW_CHECK(!camera || !camera->HasDistortion(), InvalidArgument,
                   (camera_path.empty() ? input : camera_path)
                       << ": the camera has distortion; the detector takes undistorted images");
  StagedOutputDir out(out_dir);
  SaveOptions(out.path("detector.yaml"), options, "detector");
  Progress progress("detect", total);
  size_t done = 0, planes = 0;
  double milliseconds = 0;
  const std::filesystem::path final_dir = std::filesystem::absolute(out_dir);
  auto detect = [&](const std::string& image_path, const cv::Mat& image, const std::string& name) {
    PDVO_THROW_CHECK(!camera || (image.cols == camera->width && image.rows == camera->height), FormatError,
                     image_path << ": image is " << image.cols << "x" << image.rows << ", the camera says "
                                << camera->width << "x" << camera->height);
    const Detections d = detector.Detect(image, camera);
    const std::string relative =
        std::filesystem::relative(std::filesystem::absolute(image_path), final_dir).generic_string();
    const Annotation a = d.ToAnnotation(relative, image.cols, image.rows, camera);
    WriteAnnotation(out.path(name), a);
    if (overlay) {
      const std::string png = out.path(std::filesystem::path(name).stem().string() + "_stages.png");
      WriteImage(png, DrawDetectionStages(image, d, a));
    }
    for (const AnnotationShape& s : a.shapes) planes += s.IsPlane();
    milliseconds += d.times.total;
    ++done;
    progress.Step();
  };
  auto json_name = [](const std::string& image_path) {
    return std::filesystem::path(image_path).stem().string() + ".json";
  };
  for (const auto& [path, image] : single) detect(path, image, json_name(path));
  Frame frame;
  while (sequence && done < total && sequence->Next(&frame)) {
    PDVO_THROW_CHECK(!frame.image_path.empty(), InvalidArgument,
                     input << ": the detector needs image files, not a video");
    detect(frame.image_path, frame.image, json_name(frame.image_path));
  }
  for (size_t k = 0; k < annotated.size() && done < total; ++k) {
    const Annotation reference = ReadAnnotation(annotated[k]);
    const std::string image_path = ResolveImagePath(reference, annotated[k]);
    const cv::Mat image = ReadImage(image_path, cv::IMREAD_COLOR);
    PDVO_THROW_CHECK(image.cols == reference.image_width && image.rows == reference.image_height, FormatError,
                     image_path << ": image is " << image.cols << "x" << image.rows << ", its annotation says "
                                << reference.image_width << "x" << reference.image_height);
    camera = reference.camera;
    detect(image_path, image, std::filesystem::path(annotated[k]).filename().string());
  }
  progress.Finish();
  out.Commit();
  std::printf("%zu images, %zu planes, %.1f ms per image (one thread); wrote %s\n", done, planes,
              milliseconds / std::max<size_t>(1, done), out_dir.c_str());
  return 0;
}

}  // namespace pdvo::apps
