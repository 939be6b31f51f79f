// The plane detector: pooling on hand-made windows and against the direct computation; the words' prior; an end-to-end
// detection on a rendered street whose planes are known (its largest planes found, with their orientation); the same
// image gives the same annotation bytes, from one thread or two at once; images too small or empty are refused; the
// shipped options file equals the defaults.
#include "pdvo/infer/detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <thread>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"
#include "pdvo/infer/sphere.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"

namespace pdvo {
namespace {

TEST(Detector, PoolsTheWindowsThatHoldAPoint) {
  const std::vector<cv::Point2f> points = {{10, 10}, {50, 10}, {200, 200}};
  const Eigen::Vector3d a(0, 0, -1), b = Eigen::Vector3d(1, 0, -1).normalized(), c(0, -1, 0);
  // Point 0 lies in windows 0-2, point 1 in windows 1-3 only, point 2 in none.
  const std::vector<DetectedWindow> windows = {{cv::Rect(0, 0, 40, 40), 0.9, a},
                                               {cv::Rect(0, 0, 64, 64), 0.8, a},
                                               {cv::Rect(8, 0, 64, 32), 0.2, b},
                                               {cv::Rect(40, 0, 32, 32), 0.6, c}};
  const PointPooling p = PoolWindows(points, windows, 15);
  EXPECT_DOUBLE_EQ(p.planarity[0], 0.8);       // the median of 0.9, 0.8, 0.2
  EXPECT_DOUBLE_EQ(p.planarity[1], 0.6);       // of 0.8, 0.2, 0.6
  EXPECT_DOUBLE_EQ(p.planarity[2], 0.5);       // no window: undecided
  EXPECT_LT((p.normals[0] - a).norm(), 0.05);  // the light, far normal b hardly moves the robust mean
  EXPECT_EQ(p.normals[2], Eigen::Vector3d::Zero());
}

// Windows anywhere (not on a grid), points anywhere: each point pools exactly the windows that hold its pixel, as a
// direct pooling of those windows gives.
TEST(Detector, PoolingEqualsTheDirectComputation) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> at(0, 150), side(5, 80);
  std::uniform_real_distribution<double> u(-1, 1), p(0, 1);
  std::vector<DetectedWindow> windows;
  for (int k = 0; k < 40; ++k) {
    windows.push_back(
        {cv::Rect(at(rng), at(rng), side(rng), side(rng)), p(rng), Eigen::Vector3d(u(rng), u(rng), -1).normalized()});
  }
  std::vector<cv::Point2f> points;
  for (int i = 0; i < 300; ++i) points.emplace_back(0.5f * at(rng) + 0.5f * at(rng), 0.5f * at(rng) + 0.5f * at(rng));
  const PointPooling pooled = PoolWindows(points, windows, 15);
  int held = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    std::vector<double> probabilities;
    std::vector<Eigen::Vector3d> normals;
    for (const DetectedWindow& w : windows) {
      if (!w.box.contains(NearestPixel(points[i]))) continue;
      probabilities.push_back(w.plane_probability);
      normals.push_back(w.normal);
    }
    if (probabilities.empty()) {
      EXPECT_EQ(pooled.planarity[i], 0.5) << i;
      continue;
    }
    ++held;
    std::vector<double> sorted = probabilities;
    std::sort(sorted.begin(), sorted.end());
    const size_t m = sorted.size();
    EXPECT_DOUBLE_EQ(pooled.planarity[i], m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2])) << i;
    EXPECT_EQ(pooled.normals[i], RobustMeanDirection(normals, probabilities, 15)) << i;
  }
  EXPECT_GT(held, 200);  // most points lie in some window
}

struct StreetFrame {
  cv::Mat image;
  Annotation truth;
  Camera camera;
};

// Frame `frame` of `pdvo synth -n 15 --seed SEED --set walk.fps=1 --set walk.look_deg=LOOK`.
StreetFrame RenderStreet(uint64_t seed, int frame, double look_deg = 0) {
  sim::SynthOptions options;
  options.walk.fps = 1;
  options.walk.look_deg = look_deg;
  const int frames = 15;
  const sim::Street street =
      sim::GenerateStreet(options.street, options.walk.speed * frames / options.walk.fps + 30.0, seed);
  const Trajectory walk = sim::WalkStreet(street, options.walk, frames, seed);
  StreetFrame s;
  s.camera = options.MakeCamera();
  const sim::Renderer renderer(street, s.camera, options.render, seed);
  sim::RenderedFrame rendered;
  renderer.Render({walk[frame].world_from_cam}, walk[frame].timestamp, frame, &rendered);
  s.image = rendered.image;
  s.truth = sim::AnnotateFrame(street, rendered, walk[frame].world_from_cam, s.camera, "frame.png");
  return s;
}

const Detector& DefaultDetector() {
  static const Detector detector(PlaneModel::Read(PDVO_SOURCE_DIR "/models/default/model.yml"), DetectorOptions{});
  return detector;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero(a & b), uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 0.0;
}

// On a street the model never saw (seed 951), at least half the true planes covering 10% of the frame or more are
// found: a detected plane overlaps each with IoU >= 0.4 and a normal within 30 degrees (measured 2026-12-07: 7 of 7).
TEST(Detector, FindsTheLargePlanesOfARenderedStreet) {
  int large = 0, found = 0;
  for (const int frame : {3, 9, 14}) {
    const StreetFrame s = RenderStreet(951, frame);
    const Detections d = DefaultDetector().Detect(s.image, s.camera);
    const Annotation detected = d.ToAnnotation("frame.png", s.image.cols, s.image.rows, s.camera);
    for (const ValidationIssue& issue : Validate(detected)) EXPECT_FALSE(issue.is_error) << issue.message;
    for (const AnnotationShape& truth : s.truth.shapes) {
      if (!truth.IsPlane()) continue;
      const cv::Mat t = RasteriseShape(truth, s.truth);
      if (cv::countNonZero(t) < 0.1 * s.image.total()) continue;
      ++large;
      for (const AnnotationShape& shape : detected.shapes) {
        if (!shape.IsPlane()) continue;
        const double angle = AngleDeg(*shape.normal, *truth.normal);
        if (Iou(RasteriseShape(shape, detected), t) >= 0.4 && angle <= 30) {
          ++found;
          break;
        }
      }
    }
  }
  ASSERT_GT(large, 3);
  EXPECT_GE(found, large / 2) << found << " of " << large << " large planes found";
  RecordProperty("large_planes_found", std::to_string(found) + " of " + std::to_string(large));
}

// A wide stretch of road and pavement beside a facade, which the recogniser, seeing it whole, takes for a wall 88
// degrees off (validation street 605, frame 2): the windows over its parts call it horizontal, and so does the
// detection, with the image's vertical as its normal (measured: IoU 0.69, 2.3 degrees off; 15.1 with the windows'
// mean normal).
TEST(Detector, KeepsTheGroundHorizontalWhereItsRecognitionSaysWall) {
  const StreetFrame s = RenderStreet(605, 2, 60);
  const Detections d = DefaultDetector().Detect(s.image, s.camera);
  const Annotation detected = d.ToAnnotation("frame.png", s.image.cols, s.image.rows, s.camera);
  double best = 0, angle = 180;
  for (const AnnotationShape& truth : s.truth.shapes) {
    if (!truth.IsPlane() || std::abs(truth.normal->y()) < 0.9) continue;  // the ground (y is down)
    const cv::Mat t = RasteriseShape(truth, s.truth);
    for (const AnnotationShape& shape : detected.shapes) {
      if (!shape.IsPlane() || AngleDeg(*shape.normal, *truth.normal) > 30) continue;
      const double iou = Iou(RasteriseShape(shape, detected), t);
      if (iou > best) best = iou, angle = AngleDeg(*shape.normal, *truth.normal);
    }
  }
  EXPECT_GE(best, 0.5) << "the ground's best match within 30 degrees";
  EXPECT_LE(angle, 3) << "its normal: the image's vertical";
}

// The words' prior: a point's planarity's log-odds move by the weight times its two words' log-odds, summed and
// held within 3 either way; words that say nothing change nothing.
TEST(Detector, TheWordsPriorMovesEachPointsPlanarityLogOdds) {
  const StreetFrame s = RenderStreet(952, 5);
  PlaneModel model = DefaultDetector().recogniser().model();
  const Eigen::Index words = model.gradient_words.size() + model.colour_words.size();
  DetectorOptions off;
  off.word_prior_weight = 0;
  const Detections without = Detector(model, off).Detect(s.image, s.camera);
  const auto logit = [](double p) { return std::log(p / (1 - p)); };
  const auto clamped_logit = [&](double p) { return logit(std::clamp(p, 1e-3, 1 - 1e-3)); };  // as MRF 1 clamps
  model.word_plane_log_odds = Eigen::VectorXd::Zero(words);
  const Detections nothing_said = Detector(model, DetectorOptions{}).Detect(s.image, s.camera);
  ASSERT_EQ(nothing_said.planarity.size(), without.planarity.size());
  for (size_t i = 0; i < without.planarity.size(); ++i)
    EXPECT_NEAR(logit(nothing_said.planarity[i]), clamped_logit(without.planarity[i]), 1e-9) << i;
  for (const double odds : {-0.5, 2.0}) {  // per word; a point's two words sum to -1 (kept) or 4 (held at 3)
    model.word_plane_log_odds = Eigen::VectorXd::Constant(words, odds);
    DetectorOptions half;
    half.word_prior_weight = 0.5;
    const Detections with = Detector(model, half).Detect(s.image, s.camera);
    ASSERT_EQ(with.planarity.size(), without.planarity.size());
    for (size_t i = 0; i < with.planarity.size(); ++i) {
      EXPECT_NEAR(logit(with.planarity[i]) - clamped_logit(without.planarity[i]), 0.5 * std::clamp(2 * odds, -3.0, 3.0),
                  1e-8)
          << i;
    }
  }
}

TEST(Detector, TheSameImageGivesTheSameBytesFromAnyThread) {
  const StreetFrame s = RenderStreet(952, 5);
  const Detector& detector = DefaultDetector();
  const std::string once = AnnotationToJson(detector.Detect(s.image).ToAnnotation("f.png", 320, 240));
  EXPECT_EQ(AnnotationToJson(detector.Detect(s.image).ToAnnotation("f.png", 320, 240)), once);
  std::string a, b;
  std::thread first([&] { a = AnnotationToJson(detector.Detect(s.image).ToAnnotation("f.png", 320, 240)); });
  std::thread second([&] { b = AnnotationToJson(detector.Detect(s.image).ToAnnotation("f.png", 320, 240)); });
  first.join();
  second.join();
  EXPECT_EQ(a, once);
  EXPECT_EQ(b, once);
}

TEST(Detector, RefusesImagesItCannotDetectIn) {
  const Detector& detector = DefaultDetector();
  EXPECT_THROW(detector.Detect(cv::Mat()), InvalidArgument);
  EXPECT_THROW(detector.Detect(cv::Mat(240, 320, CV_32FC3)), InvalidArgument);
  DetectorOptions large;
  large.window_sizes = {400};  // larger than a 320 x 240 image
  const Detector too_large(detector.recogniser().model(), large);
  EXPECT_THROW(too_large.Detect(cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 90, 90))), InvalidArgument);
  EXPECT_THROW(detector.Detect(cv::Mat(240, 320, CV_8UC3), Camera::Pinhole(640, 480, 500, 500, 320, 240)),
               InvalidArgument);  // a camera of another size
  DetectorOptions bad;
  bad.overlap = 1;
  EXPECT_THROW(Detector(detector.recogniser().model(), bad), InvalidArgument);
}

TEST(Detector, TheShippedOptionsAreTheDefaults) {
  EXPECT_EQ(LoadOptions<DetectorOptions>(PDVO_SOURCE_DIR "/infer/config/detector.yaml", "detector"), DetectorOptions{});
}

}  // namespace
}  // namespace pdvo
