#include "pdvo/vo/detection_worker.h"

#include <chrono>
#include <exception>

#include "pdvo/common/errors.h"

namespace pdvo::vo {

DetectionWorker::DetectionWorker(PlaneDetector detector, DetectionSchedule schedule, int delay_frames,
                                 double timeout_seconds)
    : detector_(std::move(detector)),
      schedule_(schedule),
      delay_frames_(delay_frames),
      timeout_seconds_(timeout_seconds) {
  PDVO_THROW_CHECK(detector_, InvalidArgument, "detection worker: no detector");
  PDVO_THROW_CHECK(delay_frames >= 1 && timeout_seconds > 0, InvalidArgument,
                   "detection worker: delay_frames " << delay_frames << " and timeout_seconds " << timeout_seconds
                                                     << " must be positive");
  thread_ = std::thread([this] { Run(); });
}

DetectionWorker::~DetectionWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    job_.reset();
    waiting_.reset();
  }
  wake_.notify_all();
  thread_.join();
}

void DetectionWorker::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || job_; });
    if (stop_) return;
    Job job = std::move(*job_);
    job_.reset();
    running_ = true;
    lock.unlock();
    DetectionResult result;
    result.keyframe = job.keyframe.frame;
    result.keyframe_time = job.keyframe.time;
    result.started = job.started;
    const auto start = std::chrono::steady_clock::now();
    try {
      result.planes = detector_(job.keyframe);
    } catch (const std::exception& e) {
      result.error = e.what();
    } catch (...) {
      result.error = "unknown exception";
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    lock.lock();
    running_ = false;
    results_.emplace_back(job.serial, std::move(result));
    if (schedule_ == DetectionSchedule::kRealTime && waiting_ && !stop_) {
      StartLocked(std::move(*waiting_), frame_);
      waiting_.reset();
    }
    done_.notify_all();
  }
}

void DetectionWorker::StartLocked(KeyframeImage keyframe, int frame) {
  job_ = Job{std::move(keyframe), next_serial_++, frame};
  if (schedule_ == DetectionSchedule::kDeterministic) in_flight_ = Job{{}, job_->serial, frame};
  wake_.notify_all();
}

std::vector<DetectionResult> DetectionWorker::Collect(int frame, double* waited) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  frame_ = frame;
  std::vector<DetectionResult> out;
  if (schedule_ == DetectionSchedule::kRealTime) {
    for (auto& [serial, result] : results_) out.push_back(std::move(result));
    results_.clear();
  } else if (in_flight_ && in_flight_->started + delay_frames_ <= frame) {
    const int serial = in_flight_->serial;
    auto ready = [&] {
      std::erase_if(results_, [&](const auto& r) { return r.first < serial; });  // given up earlier
      return !results_.empty();
    };
    if (done_.wait_for(lock, std::chrono::duration<double>(timeout_seconds_), ready)) {
      out.push_back(std::move(results_.front().second));
      results_.pop_front();
    } else {
      ++timed_out_;
    }
    in_flight_.reset();
    if (waiting_) {
      StartLocked(std::move(*waiting_), frame);
      waiting_.reset();
    }
  }
  for (DetectionResult& r : out) r.delivered = frame;
  if (waited) *waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void DetectionWorker::Offer(KeyframeImage keyframe) {
  std::lock_guard<std::mutex> lock(mutex_);
  frame_ = keyframe.frame;
  const bool busy = schedule_ == DetectionSchedule::kRealTime ? running_ || job_.has_value() : in_flight_.has_value();
  if (busy) {
    skipped_ += waiting_.has_value();
    waiting_ = std::move(keyframe);
  } else {
    const int frame = keyframe.frame;
    StartLocked(std::move(keyframe), frame);
  }
}

int DetectionWorker::skipped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

int DetectionWorker::timed_out() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return timed_out_;
}

}  // namespace pdvo::vo
