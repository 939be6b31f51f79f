// A sequence's frames prepared for the odometry in another way than FramePreparer's, to measure how much the
// odometry depends on half a grey level: undistorted and resized as `pdvo vo` does, except that the frames are
// converted to grey before undistortion (grey=first) and/or resized bilinearly (resize=linear). Writes a TUM
// folder that `pdvo vo` reads with working_width=0: rgb/NNNNNN.png, rgb.txt (with the frames' times) and
// camera.yaml (the working camera, without distortion).
// Usage: frame_variants SEQUENCE CAMERA_YAML OUT_DIR [grey=first|last] [resize=area|linear] [width=320]
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pdvo/common/camera.h"
#include "pdvo/common/dataset.h"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr,
                 "usage: frame_variants SEQUENCE CAMERA_YAML OUT_DIR [grey=first|last] [resize=area|linear] "
                 "[width=320]\n");
    return 2;
  }
  bool grey_first = false, linear = false;
  int width = 320;
  for (int i = 4; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "grey=first" || arg == "grey=last") {
      grey_first = arg == "grey=first";
    } else if (arg == "resize=area" || arg == "resize=linear") {
      linear = arg == "resize=linear";
    } else if (arg.rfind("width=", 0) == 0) {
      width = std::stoi(arg.substr(6));
    } else {
      std::fprintf(stderr, "frame_variants: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  try {
    const pdvo::Camera camera = pdvo::Camera::Read(argv[2]);
    const int height = static_cast<int>(std::lround(camera.height * static_cast<double>(width) / camera.width));
    const pdvo::Undistorter undistorter(camera);
    const std::filesystem::path out = argv[3];
    std::filesystem::create_directories(out / "rgb");
    camera.Undistorted().Rescaled(width, height).Write((out / "camera.yaml").string());
    std::ofstream list(out / "rgb.txt");
    pdvo::SequenceOptions options;
    options.load_depth = options.load_groundtruth = false;
    auto sequence = pdvo::OpenSequence(argv[1], options);
    pdvo::Frame frame;
    while (sequence->Next(&frame)) {
      cv::Mat image = frame.image;
      if (grey_first) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
      image = undistorter.Apply(image);
      cv::resize(image, image, cv::Size(width, height), 0, 0, linear ? cv::INTER_LINEAR : cv::INTER_AREA);
      if (!grey_first) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
      char name[32];
      std::snprintf(name, sizeof(name), "rgb/%06zu.png", frame.index);
      cv::imwrite((out / name).string(), image);
      char line[64];
      std::snprintf(line, sizeof(line), "%.6f %s\n", frame.timestamp, name);
      list << line;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "frame_variants: %s\n", e.what());
    return 1;
  }
  return 0;
}
