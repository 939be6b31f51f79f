// The plane detector's time per 320x240 image on one core, stage by stage (describe, windows, pooling,
// segmentation, segments), median over the images: rendered synthetic street frames, and the Strecha images
// (reduced to the working width) when ../shared/data is beside the project. Target: at most 30 ms median for the
// whole detection.
// Usage: detector_bench [--model=PATH] [--images=N] [option=value ...]   (DetectorOptions)
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"
#include "pdvo/infer/detector.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void Report(const char* what, const pdvo::Detector& detector, const std::vector<cv::Mat>& images) {
  if (images.empty()) return;
  std::vector<double> describe, windows, pooling, segmentation, segments, total, count, points, planes;
  for (const cv::Mat& image : images) {
    const pdvo::Detections d = detector.Detect(image);
    describe.push_back(d.times.describe);
    windows.push_back(d.times.windows);
    pooling.push_back(d.times.pooling);
    segmentation.push_back(d.times.segmentation);
    segments.push_back(d.times.segments);
    total.push_back(d.times.total);
    count.push_back(static_cast<double>(d.windows.size()));
    points.push_back(static_cast<double>(d.points.size()));
    planes.push_back(static_cast<double>(
        std::count_if(d.segments.begin(), d.segments.end(), [](const pdvo::DetectedSegment& s) { return s.planar; })));
  }
  std::printf(
      "detector_bench: %zu %s images, medians (ms): describe %.1f (%.0f points), windows %.1f (%.0f windows), pooling "
      "%.1f, segmentation %.1f, segments %.1f; total %.1f (target <= 30), %.0f planes\n",
      images.size(), what, Median(describe), Median(points), Median(windows), Median(count), Median(pooling),
      Median(segmentation), Median(segments), Median(total), Median(planes));
}

}  // namespace

int main(int argc, char** argv) {
  pdvo::KeepFreedMemory();  // as pdvo does
  std::string model = PDVO_SOURCE_DIR "/models/default/model.yml";
  int count = 20;
  pdvo::DetectorOptions options;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) {
      std::fprintf(stderr,
                   "usage: detector_bench [--model=PATH] [--images=N] [option=value ...]   (DetectorOptions)\n");
      return 0;
    }
    if (std::strncmp(argv[i], "--model=", 8) == 0) {
      model = argv[i] + 8;
    } else if (std::strncmp(argv[i], "--images=", 9) == 0) {
      count = std::atoi(argv[i] + 9);
    } else {
      const std::string arg = argv[i];
      const size_t eq = arg.find('=');
      try {
        if (eq == std::string::npos) throw pdvo::InvalidArgument("expected option=value, got '" + arg + "'");
        pdvo::SetOption(options, arg.substr(0, eq), arg.substr(eq + 1));
      } catch (const std::exception& e) {
        std::fprintf(stderr, "detector_bench: %s\n", e.what());
        return 2;
      }
    }
  }
  const pdvo::Detector detector(pdvo::PlaneModel::Read(model), options);
  // Synthetic: a street the model never saw (seed 901), one frame a second.
  pdvo::sim::SynthOptions synth;
  const pdvo::sim::Street street = pdvo::sim::GenerateStreet(synth.street, 60, 901);
  synth.walk.fps = 1;
  const pdvo::Trajectory walk = pdvo::sim::WalkStreet(street, synth.walk, count, 901);
  const pdvo::sim::Renderer renderer(street, synth.MakeCamera(), synth.render, 901);
  std::vector<cv::Mat> images;
  for (size_t k = 0; k < walk.size(); ++k) {
    pdvo::sim::RenderedFrame frame;
    renderer.Render({walk[k].world_from_cam}, walk[k].timestamp, k, &frame);
    images.push_back(frame.image);
  }
  Report("synthetic street", detector, images);
  images.clear();
  for (const char* set : {"strecha_entry_p10", "strecha_herzjesu_p8"}) {
    const std::filesystem::path folder = std::filesystem::path(PDVO_SOURCE_DIR "/../shared/data") / set / "images";
    if (!std::filesystem::is_directory(folder)) continue;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      // At the working width, as the target is for 320x240 images (reducing a 3072x2048 photo adds ~10 ms).
      const cv::Mat image = cv::imread(f.string(), cv::IMREAD_COLOR);
      if (!image.empty())
        images.push_back(pdvo::ToWorkingSize(image, detector.recogniser().model().options.working_width));
    }
  }
  if (images.empty()) std::printf("detector_bench: no Strecha images under ../shared/data, skipped\n");
  Report("Strecha", detector, images);
  return 0;
}
