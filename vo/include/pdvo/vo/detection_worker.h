// The plane detector beside the odometry (the paper's section V): a background thread detects planes in
// keyframes while the tracking thread goes on. When the thread is free it takes the newest keyframe; a keyframe
// made while it is busy waits, and a newer one replaces it (counted as skipped). Two schedules:
//   real time      results are handed over at the first frame after they are ready; the tracking thread never
//                  waits for the detector;
//   deterministic  a detection takes exactly `delay_frames` frames: its results are handed over at the frame
//                  `delay_frames` after it started (waiting for the thread if need be), and the thread is free
//                  again then. Which keyframes are detected, and when their planes arrive, depends only on the
//                  frames: the same input gives the same trajectory, byte for byte.
// A detector that throws gives a result with its message and no planes; in the deterministic schedule, one that
// takes longer than `timeout_seconds` is given up (its result dropped when it comes, counted in timed_out()).
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pdvo/common/detected_plane.h"

namespace pdvo::vo {

// A keyframe as the detector sees it.
struct KeyframeImage {
  int frame = -1;   // the keyframe's frame: its index in the frames given to Odometry::Track
  double time = 0;  // its timestamp (s)
  cv::Mat grey;     // the working image (CV_8UC1)
  cv::Mat colour;   // the same in colour (CV_8UC3, BGR) if Track was given it; otherwise empty
};

// Planes in a keyframe: pixels of the working image, normals in the keyframe's camera frame. May throw; it is
// called from the detector's thread, one call at a time.
using PlaneDetector = std::function<std::vector<DetectedPlane>(const KeyframeImage&)>;

enum class DetectionSchedule { kRealTime, kDeterministic };
constexpr std::array<std::pair<DetectionSchedule, const char*>, 2> OptionNames(DetectionSchedule) {
  return {{{DetectionSchedule::kRealTime, "realtime"}, {DetectionSchedule::kDeterministic, "deterministic"}}};
}

struct DetectionResult {
  int keyframe = -1;  // the keyframe's frame
  double keyframe_time = 0;
  int started = -1;    // the frame at which the detection started (real time: the newest frame known then)
  int delivered = -1;  // the frame at which the results were handed over
  double seconds = 0;  // the detector's time
  std::vector<DetectedPlane> planes;
  std::string error;  // the detector threw: its message (and no planes)
};

class DetectionWorker {
 public:
  // Throws InvalidArgument for an empty detector, delay_frames < 1 or a timeout that is not positive.
  DetectionWorker(PlaneDetector detector, DetectionSchedule schedule, int delay_frames, double timeout_seconds);
  // Waits for a detection in progress to end (it cannot be interrupted), then joins the thread.
  ~DetectionWorker();
  DetectionWorker(const DetectionWorker&) = delete;
  DetectionWorker& operator=(const DetectionWorker&) = delete;

  // The results to use at frame `frame`; once per frame, frames increasing, before that frame's Offer.
  // `waited` (optional): the seconds spent waiting for the detector (deterministic schedule).
  std::vector<DetectionResult> Collect(int frame, double* waited = nullptr);
  // A new keyframe (at frame keyframe.frame): detected at once if the detector is free, else it waits.
  void Offer(KeyframeImage keyframe);

  int skipped() const;    // keyframes replaced by a newer one while they waited
  int timed_out() const;  // deterministic detections given up after timeout_seconds

 private:
  struct Job {
    KeyframeImage keyframe;
    int serial = 0;
    int started = -1;
  };
  void Run();
  void StartLocked(KeyframeImage keyframe, int frame);  // with mutex_ held

  PlaneDetector detector_;
  DetectionSchedule schedule_;
  int delay_frames_;
  double timeout_seconds_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;  // the thread: a job or stop
  std::condition_variable done_;  // the tracking thread: a result
  std::optional<Job> job_;        // handed to the thread, not yet taken
  bool running_ = false;          // the thread is detecting
  std::optional<Job> in_flight_;  // deterministic: started and not yet handed over
  std::optional<KeyframeImage> waiting_;
  std::deque<std::pair<int, DetectionResult>> results_;  // by job serial
  int next_serial_ = 0;
  int frame_ = -1;  // the newest frame the tracking thread has reported
  int skipped_ = 0, timed_out_ = 0;
  bool stop_ = false;
  std::thread thread_;  // last: started when everything else is in place
};

}  // namespace pdvo::vo
