// The detector's thread: in the deterministic schedule results arrive exactly delay_frames after their
// detection starts, whatever the detector's speed, a keyframe made while the detector is busy waits and a newer
// one replaces it; in real time the tracking thread never waits and the thread stops cleanly; a detector that
// throws gives a result with its message; one slower than the timeout is given up. (Run under ThreadSanitizer
// with ./run tsan.)
#include "pdvo/vo/detection_worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>

#include "pdvo/common/errors.h"

namespace pdvo::vo {
namespace {

using std::chrono::milliseconds;

KeyframeImage Keyframe(int frame) {
  return {frame, frame / 30.0, cv::Mat(24, 32, CV_8U, cv::Scalar(frame)), cv::Mat()};
}

// A detector that returns one plane whose score is the keyframe's frame, after `sleep`.
PlaneDetector Slow(milliseconds sleep) {
  return [sleep](const KeyframeImage& k) {
    std::this_thread::sleep_for(sleep);
    DetectedPlane p;
    p.score = k.frame;
    p.normal = Eigen::Vector3d(0, 0, -1);
    return std::vector<DetectedPlane>{p};
  };
}

// Runs frames 0..last, offering keyframes at `keyframes`; returns (keyframe, started, delivered) per result.
std::vector<std::array<int, 3>> RunFrames(DetectionWorker* worker, int last, const std::vector<int>& keyframes) {
  std::vector<std::array<int, 3>> out;
  for (int frame = 0; frame <= last; ++frame) {
    for (const DetectionResult& r : worker->Collect(frame)) {
      EXPECT_TRUE(r.error.empty());
      EXPECT_EQ(r.planes.at(0).score, r.keyframe);
      out.push_back({r.keyframe, r.started, r.delivered});
    }
    if (std::find(keyframes.begin(), keyframes.end(), frame) != keyframes.end()) worker->Offer(Keyframe(frame));
  }
  return out;
}

TEST(DetectionWorker, TheDeterministicScheduleDependsOnFramesOnly) {
  const std::vector<std::array<int, 3>> expected = {{0, 0, 3}, {2, 3, 6}, {10, 10, 13}};
  for (const int sleep : {0, 5, 40}) {
    DetectionWorker worker(Slow(milliseconds(sleep)), DetectionSchedule::kDeterministic, 3, 10);
    // Keyframe 1 waits while 0 is detected and 2 replaces it; 2 starts when 0's results are handed over.
    EXPECT_EQ(RunFrames(&worker, 20, {0, 1, 2, 10}), expected) << sleep << " ms";
    EXPECT_EQ(worker.skipped(), 1);
    EXPECT_EQ(worker.timed_out(), 0);
  }
}

TEST(DetectionWorker, InRealTimeTheTrackingThreadNeverWaits) {
  std::atomic<bool> release{false};
  DetectionWorker worker(
      [&](const KeyframeImage& k) {
        while (!release) std::this_thread::sleep_for(milliseconds(1));
        return Slow(milliseconds(0))(k);
      },
      DetectionSchedule::kRealTime, 3, 10);
  worker.Offer(Keyframe(0));
  const auto start = std::chrono::steady_clock::now();
  for (int frame = 1; frame < 50; ++frame) EXPECT_TRUE(worker.Collect(frame).empty());
  worker.Offer(Keyframe(49));  // waits: the detector is busy
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(500));
  release = true;
  std::vector<DetectionResult> got;
  for (int frame = 50; got.size() < 2 && frame < 5000; ++frame) {
    for (DetectionResult& r : worker.Collect(frame)) got.push_back(std::move(r));
    std::this_thread::sleep_for(milliseconds(1));
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].keyframe, 0);
  EXPECT_EQ(got[1].keyframe, 49);
  EXPECT_GE(got[1].started, 49);  // started when the first detection ended
  EXPECT_GT(got[0].delivered, 49);
}

TEST(DetectionWorker, StopsCleanlyWithWorkInProgress) {
  for (const DetectionSchedule schedule : {DetectionSchedule::kRealTime, DetectionSchedule::kDeterministic}) {
    std::atomic<int> started{0}, ended{0};
    const auto start = std::chrono::steady_clock::now();
    {
      DetectionWorker worker(
          [&](const KeyframeImage& k) {
            ++started;
            std::vector<DetectedPlane> planes = Slow(milliseconds(50))(k);
            ++ended;
            return planes;
          },
          schedule, 2, 10);
      worker.Offer(Keyframe(0));
      worker.Offer(Keyframe(1));  // waits, and is dropped at the stop
      while (started == 0) std::this_thread::sleep_for(milliseconds(1));
    }  // the destructor waits for the detection in progress and joins
    EXPECT_EQ(started, 1);
    EXPECT_EQ(ended, 1);  // it ended before the destructor returned
    EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(50));
  }
}

TEST(DetectionWorker, ADetectorThatThrowsGivesItsMessage) {
  DetectionWorker worker([](const KeyframeImage&) -> std::vector<DetectedPlane> { throw std::runtime_error("boom"); },
                         DetectionSchedule::kDeterministic, 1, 10);
  worker.Offer(Keyframe(0));
  const std::vector<DetectionResult> r = worker.Collect(1);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].error, "boom");
  EXPECT_TRUE(r[0].planes.empty());
}

TEST(DetectionWorker, ASlowDetectorIsGivenUp) {
  // Keyframe 0 takes 300 ms, longer than the 50 ms timeout; keyframe 1 is quick.
  DetectionWorker worker([](const KeyframeImage& k) { return Slow(milliseconds(k.frame == 0 ? 300 : 0))(k); },
                         DetectionSchedule::kDeterministic, 1, 0.05);
  worker.Offer(Keyframe(0));
  worker.Offer(Keyframe(1));               // waits
  EXPECT_TRUE(worker.Collect(1).empty());  // 0 is given up; 1 starts, behind it in the thread
  EXPECT_EQ(worker.timed_out(), 1);
  std::this_thread::sleep_for(milliseconds(600));            // both end
  const std::vector<DetectionResult> r = worker.Collect(2);  // 0's late result is dropped
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].keyframe, 1);
  EXPECT_EQ(worker.timed_out(), 1);
}

TEST(DetectionWorker, RefusesBadArguments) {
  EXPECT_THROW(DetectionWorker(PlaneDetector(), DetectionSchedule::kRealTime, 3, 1), InvalidArgument);
  EXPECT_THROW(DetectionWorker(Slow(milliseconds(0)), DetectionSchedule::kRealTime, 0, 1), InvalidArgument);
  EXPECT_THROW(DetectionWorker(Slow(milliseconds(0)), DetectionSchedule::kRealTime, 3, 0), InvalidArgument);
}

}  // namespace
}  // namespace pdvo::vo
