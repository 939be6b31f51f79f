// Recogniser kernels on one core (google-benchmark): describing a 320x240 synthetic street frame (salient points,
// gradient and colour descriptors, words, straight edges), its straight edges alone, the same points described by
// OpenCV's SIFT as a baseline, and recognising one 100x100 region of a described frame. Model: argv
// --model=PATH (default models/default).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pdvo/common/logging.h"
#include "pdvo/infer/recogniser.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"

namespace {

std::string g_model_path = PDVO_SOURCE_DIR "/models/default/model.yml";

cv::Mat StreetFrame() {
  const pdvo::sim::SynthOptions options;
  const pdvo::sim::Street street = pdvo::sim::GenerateStreet(options.street, 60, 1);
  const pdvo::Trajectory walk = pdvo::sim::WalkStreet(street, options.walk, 40, 1);
  const pdvo::sim::Renderer renderer(street, options.MakeCamera(), options.render, 1);
  pdvo::sim::RenderedFrame frame;
  renderer.Render({walk[30].world_from_cam}, walk[30].timestamp, 30, &frame);
  return frame.image;
}

std::unique_ptr<pdvo::Recogniser> g_recogniser;

const pdvo::Recogniser& Model() { return *g_recogniser; }

void BM_DescribeFrame(benchmark::State& state) {
  const cv::Mat image = StreetFrame();
  size_t points = 0;
  for (auto _ : state) points = Model().Describe(image).size();
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_DescribeFrame)->Unit(benchmark::kMillisecond);

void BM_DescriptorsOnly(benchmark::State& state) {
  const cv::Mat image = StreetFrame();
  for (auto _ : state) benchmark::DoNotOptimize(pdvo::ExtractFeatures(image, Model().model().options.features));
}
BENCHMARK(BM_DescriptorsOnly)->Unit(benchmark::kMillisecond);

// The straight edges and the vertical for the vanishing-direction cue (part of BM_DescribeFrame).
void BM_EdgePlanes(benchmark::State& state) {
  const cv::Mat image = StreetFrame();
  const pdvo::VanishingOptions& options = Model().model().options.vanishing;
  for (auto _ : state) benchmark::DoNotOptimize(pdvo::FindEdgePlanes(image, std::nullopt, options));
}
BENCHMARK(BM_EdgePlanes)->Unit(benchmark::kMillisecond);

// Baseline: OpenCV's SIFT descriptors at the same points (upright, one size), without our colour descriptor.
void BM_OpenCvSiftAtTheSamePoints(benchmark::State& state) {
  const cv::Mat image = StreetFrame();
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const pdvo::Features f = pdvo::ExtractFeatures(image, Model().model().options.features);
  std::vector<cv::KeyPoint> keypoints;
  for (const cv::Point2f& p : f.points) keypoints.emplace_back(p, 16.0f, 0.0f);
  const cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  for (auto _ : state) {
    std::vector<cv::KeyPoint> k = keypoints;
    cv::Mat d;
    sift->compute(grey, k, d);
    benchmark::DoNotOptimize(d);
  }
}
BENCHMARK(BM_OpenCvSiftAtTheSamePoints)->Unit(benchmark::kMillisecond);

void BM_RecogniseRegion100(benchmark::State& state) {
  const cv::Mat image = StreetFrame();
  const pdvo::ImageWords words = Model().Describe(image);
  const pdvo::Region region{cv::Rect(110, 70, 100, 100), cv::Mat()};
  int points = 0;
  for (auto _ : state) points = Model().Recognise(words, region).points;
  state.counters["points"] = points;
}
BENCHMARK(BM_RecogniseRegion100)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  pdvo::KeepFreedMemory();  // as pdvo does
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--model=", 8) == 0) g_model_path = argv[i] + 8;
  }
  try {
    g_recogniser = std::make_unique<pdvo::Recogniser>(pdvo::PlaneModel::Read(g_model_path));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "recogniser_bench: %s\n", e.what());
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
